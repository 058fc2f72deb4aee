"""The demo's samples from Python: measure each folder, plot a profile with its fit (matplotlib),
export the material and render it with Mitsuba 3 (both optional).

    scatterfit demo --quick                  # or `cargo run -- demo --quick`: ./scatterfit-demo/
    python crates/python/examples/demo_samples.py scatterfit-demo

Writes profile-<sample>.png and render-<sample>.png beside this script's working folder.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import scatterfit as sf


def main(demo: Path) -> None:
    folders = sorted(p.parent for p in demo.glob("*/sample.toml"))
    if not folders:
        sys.exit(f"{demo}: no sample folders (run `scatterfit demo --quick` first)")
    measured, failed = sf.batch(folders)
    for f in failed:
        print(f"{f.folder}: {f.kind} error: {f.message}")
    for m in measured:
        print(f"{m.name:14s} η = {m.eta:.3f}  verdict {m.verdict}")
        for ch in m:
            print(f"  {ch.name.upper()}  σ′s = {ch.sigma_s_prime} mm⁻¹   σa = {ch.sigma_a} mm⁻¹")
    first = measured[0]
    plot(first, Path(f"profile-{first.name}.png"))
    render(first, Path(f"render-{first.name}.png"))


def plot(m: sf.Measurement, path: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no plot (pip install matplotlib)")
        return
    p = m.profile
    fig, ax = plt.subplots(figsize=(6, 4))
    r = p["r_mm"]
    for k, (ch, colour) in enumerate(zip(m, ("tab:red", "tab:green", "tab:blue"))):
        # The rings above the detection limit: those the fit used (beyond the spot).
        limit = np.nan_to_num(p["limit"][:, k], nan=0.0)
        ok = np.isfinite(p["value"][:, k]) & (p["value"][:, k] > limit) & (p["value"][:, k] > p["stderr"][:, k])
        ax.errorbar(r[ok], p["value"][ok, k], p["stderr"][ok, k], fmt=".", ms=2, color=colour, alpha=0.5)
        fit_r = r[(r >= 1.0) & ok]
        ax.plot(fit_r, m.model_profile(ch.name, fit_r), color=colour, label=f"{ch.name.upper()} fit")
    ax.set_yscale("log")
    ax.set_xlabel("r [mm]")
    ax.set_ylabel("Rd(r) [relative]")
    ax.set_title(f"{m.name}: measured profile and the {m.model} fit")
    ax.legend()
    fig.savefig(path, dpi=120, bbox_inches="tight")
    print(f"wrote {path}")


def render(m: sf.Measurement, path: Path) -> None:
    try:
        import mitsuba as mi
    except ImportError:
        print("mitsuba not installed: no render (pip install mitsuba)")
        return
    mi.set_variant("scalar_rgb")
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": sf.mitsuba_integrator(m),
            "sensor": {
                "type": "perspective",
                "fov": 30,
                "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 120], target=[0, 0, 0], up=[0, 1, 0]),
                "film": {"type": "hdrfilm", "width": 128, "height": 128},
                "sampler": {"type": "independent", "sample_count": 64},
            },
            "light": {"type": "constant", "radiance": {"type": "rgb", "value": 0.8}},
            "sun": {"type": "directional", "direction": [-1, -1, -1], "irradiance": {"type": "rgb", "value": 3.0}},
            # The material in millimetres: a sphere of 25 mm radius.
            "object": sf.mitsuba_dict(m, shape={"type": "sphere", "radius": 25.0}),
        }
    )
    mi.util.write_bitmap(str(path), mi.render(scene))
    print(f"wrote {path}")


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "scatterfit-demo"))
