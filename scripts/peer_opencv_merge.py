#!/usr/bin/env python3
"""Peer benchmark: OpenCV's Debevec calibration + merge on the same bracket as `scatterfit merge`.

Not part of the test suite. Needs `pip install opencv-python-headless numpy`.
Usage:
    SCATTERFIT_BENCH_BRACKET_DIR=/tmp/b24 target/release/scatterfit bench imaging   # writes the bracket
    python3 scripts/peer_opencv_merge.py /tmp/b24/exposures.csv [--score]
Prints wall times for reading (cv2.imread), CalibrateDebevec (default 70 grid samples, lambda 10) and
MergeDebevec, on all cores OpenCV uses (cv2.getNumThreads()).

With `--score` it also prints the self-consistency of OpenCV's merge by the definition of
`scatterfit_imaging::self_consistency` (crates/imaging/src/consistency.rs), computed here on OpenCV's
radiance and response: the RMS, in code values, over every code 10 < z < 245 of every frame at a
pixel-channel with a finite radiance E > 0, of z less the code the response predicts for E·Δt at the
frame's stated time (g = ln of OpenCV's response made non-decreasing by a running maximum, its
inverse piecewise linear in ln X). Printed over every pixel and over the regular subsample that
`scatterfit merge` scores (every s-th pixel in raster order, s = ceil(pixels / 65536)).
"""
import csv
import os
import sys
import time

import cv2
import numpy as np


def self_consistency(images, times, response, hdr, max_pixels=None):
    """RMS of z - f(E t) over the well-exposed codes (module docstring), in code values."""
    g = np.log(np.maximum(response.reshape(256, -1).astype(np.float64), 1e-300))
    g = np.maximum.accumulate(g, axis=0)
    ch = g.shape[1]
    h, w = hdr.shape[:2]
    e = hdr.reshape(h * w, ch).astype(np.float64)
    if max_pixels is not None:
        s = max(1, -(-(h * w) // max_pixels))
        e = e[::s]
    ss, n = 0.0, 0
    for img, t in zip(images, times):
        z = img.reshape(h * w, ch)
        if max_pixels is not None:
            z = z[::s]
        for c in range(ch):
            zc = z[:, c].astype(np.float64)
            ec = e[:, c]
            ok = (zc > 10) & (zc < 245) & np.isfinite(ec) & (ec > 0)
            u = np.log(ec[ok]) + np.log(float(t))
            gc = g[:, c]
            m = np.searchsorted(gc[1:], u, side="right")  # codes 1..=255 with g <= u
            top = m >= 255
            mm = np.minimum(m, 254)
            g0, g1 = gc[mm], gc[mm + 1]
            with np.errstate(divide="ignore", invalid="ignore"):
                frac = np.where(g1 > g0, np.clip((u - g0) / (g1 - g0), 0.0, 1.0), 0.0)
            pred = np.where(top, 255.0, mm + frac)
            d = zc[ok] - pred
            ss += float(np.dot(d, d))
            n += int(d.size)
    return (ss / n) ** 0.5 if n else float("nan")


def main() -> None:
    score = "--score" in sys.argv[1:]
    path = [a for a in sys.argv[1:] if a != "--score"][0]
    folder = os.path.dirname(os.path.abspath(path))
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    files = [os.path.join(folder, r["file"]) for r in rows]
    times = np.array([eval(r["time_s"], {}, {}) if "/" in r["time_s"] else float(r["time_s"]) for r in rows],
                     dtype=np.float32)
    t0 = time.perf_counter()
    images = [cv2.imread(f, cv2.IMREAD_COLOR) for f in files]
    t1 = time.perf_counter()
    response = cv2.createCalibrateDebevec().process(images, times)
    t2 = time.perf_counter()
    hdr = cv2.createMergeDebevec().process(images, times, response)
    t3 = time.perf_counter()
    h, w = images[0].shape[:2]
    print(f"opencv {cv2.__version__}, threads {cv2.getNumThreads()}, {len(images)} frames {w}x{h}")
    print(f"read {t1 - t0:.3f} s, calibrate {t2 - t1:.3f} s, merge {t3 - t2:.3f} s, "
          f"total {t3 - t0:.3f} s; output {hdr.dtype} {hdr.shape}")
    if score:
        full = self_consistency(images, times, response, hdr)
        sampled = self_consistency(images, times, response, hdr, 65536)
        print(f"self-consistency {full:.2f} code values (every pixel), {sampled:.2f} (subsample)")


if __name__ == "__main__":
    main()
