#!/usr/bin/env python3
"""Peer timing for BENCHMARKS.md: SciPy's MINPACK Levenberg–Marquardt (scipy.optimize.least_squares,
method='lm', i.e. lmdif/lmder) on the same one-channel problem `scatterfit bench fit` times: the
proposed method (σa = σ′s(1/α′ − 1)) with the classical dipole (Jensen et al. 2001, eq. 4) as a point
source, log residuals weighted by the rings' relative standard errors, unknowns (ln σ′s, ln k), on the
rings of a profile CSV written by `scatterfit measure` (r ≥ 1 mm, value above the detection limit).

Usage: python3 scripts/peer_scipy_fit.py SAMPLE_DIR/profile.csv CHANNEL ETA ALBEDO [REPEATS]
Only numpy and scipy; not part of the test suite.
"""
import csv
import math
import sys
import time

import numpy as np
from scipy.optimize import least_squares


def load(path, ch):
    r, y, s, lim = [], [], [], []
    with open(path) as f:
        rows = [l for l in f if not l.startswith("#")]
    for row in csv.DictReader(rows):
        v = row.get(f"value_{ch}", "")
        if not v:
            continue
        r.append(float(row["r_mm"]))
        y.append(float(v))
        s.append(float(row[f"stderr_{ch}"] or "nan"))
        lim.append(float(row.get(f"limit_{ch}", "0") or 0))
    r, y, s, lim = map(np.array, (r, y, s, lim))
    keep = (r >= 1.0) & (y > lim) & (y > 0)
    sig = np.maximum(np.where(np.isfinite(s), s / y, 0.05), 5e-3)
    return r[keep], y[keep], sig[keep]


def dipole(r, sp, sa, eta):
    st = sp + sa
    ap = sp / st
    tr = math.sqrt(3 * sa * st)
    fdr = -1.440 / eta**2 + 0.710 / eta + 0.668 + 0.0636 * eta
    a = (1 + fdr) / (1 - fdr)
    zr = 1 / st
    zv = zr * (1 + 4 * a / 3)
    dr = np.sqrt(r * r + zr * zr)
    dv = np.sqrt(r * r + zv * zv)
    return ap / (4 * math.pi) * (zr * (tr * dr + 1) * np.exp(-tr * dr) / dr**3
                                 + zv * (tr * dv + 1) * np.exp(-tr * dv) / dv**3)


def main():
    path, ch, eta, alpha = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
    reps = int(sys.argv[5]) if len(sys.argv) > 5 else 200
    r, y, sig = load(path, ch)
    ly, w = np.log(y), 1 / sig
    c = 1 / alpha - 1

    def res(x):
        sp = math.exp(x[0])
        return w * (x[1] + np.log(dipole(r, sp, c * sp, eta)) - ly)

    x0 = np.array([math.log(1.0), 0.0])
    x0[1] = np.average(ly - np.log(dipole(r, 1.0, c, eta)), weights=w * w)
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        sol = least_squares(res, x0, method="lm", xtol=1e-10, ftol=1e-10)
        times.append(time.perf_counter() - t)
    times.sort()
    print(f"rings {len(r)}  sigma_s' {math.exp(sol.x[0]):.6f}  nfev {sol.nfev}  "
          f"median {times[len(times) // 2] * 1e6:.1f} us  (start sigma_s' = 1, finite-difference Jacobian)")


if __name__ == "__main__":
    main()
