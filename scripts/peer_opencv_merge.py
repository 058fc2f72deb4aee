#!/usr/bin/env python3
"""Peer benchmark: OpenCV's Debevec calibration + merge on the same bracket as `scatterfit merge`.

Not part of the test suite. Needs `pip install opencv-python-headless numpy`.
Usage:
    SCATTERFIT_BENCH_BRACKET_DIR=/tmp/b24 target/release/scatterfit bench imaging   # writes the bracket
    python3 scripts/peer_opencv_merge.py /tmp/b24/exposures.csv
Prints wall times for reading (cv2.imread), CalibrateDebevec (default 70 grid samples, lambda 10) and
MergeDebevec, on all cores OpenCV uses (cv2.getNumThreads()).
"""
import csv
import os
import sys
import time

import cv2
import numpy as np


def main() -> None:
    path = sys.argv[1]
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


if __name__ == "__main__":
    main()
