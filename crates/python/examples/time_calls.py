"""The package's calls timed from Python, beside the same library calls timed from Rust
(`crates/pipeline/examples/library_calls.rs`): what the binding costs.

    python crates/python/examples/time_calls.py SAMPLE_DIR RESULT_DIR [N]

SAMPLE_DIR is a sample folder, RESULT_DIR the folder its result files were written to. Prints the
median wall time of `measure` (over N calls, default 11; and its ratio to the library's own time
inside each call, `timings["total_s"]`) and of `fit_profile` (the same profile, η and α′ as the Rust
example), and the forward model on 10⁶ radii in one vectorised call against a Python loop over
one-radius calls (timed on 10⁴ radii, scaled).
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import scatterfit as sf


def median_s(n: int, f) -> float:
    times = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main(sample: Path, results: Path, n: int) -> None:
    result = json.loads((results / "result.json").read_text())
    t = np.genfromtxt(results / "profile.csv", delimiter=",", names=True)
    cols = lambda what: np.stack([t[f"{what}_{c}"] for c in "rgb"], axis=1)  # noqa: E731
    albedo = [result["channels"][c]["albedo_prime"]["value"] for c in "rgb"]
    args = (t["r_mm"], cols("value"), cols("stderr"))
    kwargs = dict(count=cols("count"), limit=cols("limit"), eta=result["eta"], albedo=albedo)
    sf.fit_profile(*args, **kwargs)
    fit = median_s(51, lambda: sf.fit_profile(*args, **kwargs))
    print(f"fit_profile: {fit * 1e3:.3f} ms (median of 51)")
    sf.measure(sample, progress=False)
    measure = median_s(n, lambda: sf.measure(sample, progress=False))
    print(f"measure: {measure * 1e3:.1f} ms (median of {n})")
    # The same calls against the library's own clock: `timings["total_s"]` is the wall time the
    # Rust measurement took inside the call, so the ratio is the binding's cost on that very call
    # (immune to the machine's load changing between runs).
    ratios = []
    for _ in range(n):
        t = time.perf_counter()
        m = sf.measure(sample, progress=False)
        ratios.append((time.perf_counter() - t) / m.timings["total_s"])
    ratios.sort()
    print(
        f"measure against the library's own time inside the call: median {statistics.median(ratios):.3f}×, "
        f"range {ratios[0]:.3f}–{ratios[-1]:.3f}× (of {n})"
    )

    r = np.linspace(0.01, 20.0, 1_000_000)
    sf.models.profile(r[:10], 1.0, 0.01, 1.4)
    vectorised = median_s(5, lambda: sf.models.profile(r, 1.0, 0.01, 1.4))
    few = r[:: len(r) // 10_000]
    loop = median_s(3, lambda: [sf.models.profile(x, 1.0, 0.01, 1.4) for x in few])
    loop_1e6 = loop * len(r) / len(few)
    print(
        f"models.profile, mc, 10^6 radii: {vectorised * 1e3:.1f} ms vectorised; a Python loop of "
        f"one-radius calls {loop_1e6:.1f} s (timed on {len(few)} radii) — {loop_1e6 / vectorised:.0f}×"
    )


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3]) if len(sys.argv) > 3 else 11)
