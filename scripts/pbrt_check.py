"""Render scatterfit's pbrt-v4 export with a real pbrt-v4 and print the slab's brightness.

Not part of the test suite (pbrt-v4 takes ~20 minutes to build, beyond CI's budget); BENCHMARKS.md
("exports") reports its output. Needs a pbrt-v4 executable (`--pbrt PATH` or $PBRT; build it from the
pbrt-v4 sources as their README says, outside this repository) and the standard library only.

    python3 scripts/pbrt_check.py EXPORT.pbrt --route ROUTE [--light uniform|point|distant]
        [--width W] [--thickness T] [--spp N] [--res R] [--maxdepth D] [--seed S] [--pbrt PATH]

ROUTE is one of the export's three (see its header):
- subsurface:   NamedMaterial "<id>" (pbrt's BSSRDF from the measured reflectance and mfp),
- coefficients: NamedMaterial "<id>-coefficients" (the BSSRDF from sigma_a, sigma_s),
- medium:       MediumInterface "<id>-medium" "" + NamedMaterial "<id>-boundary" (exact transport with
                the volpath integrator; per wavelength when the result has its measured spectrum);
- medium-rgb:   the same with "<id>-medium-rgb", the RGB medium (written beside the spectral one).

The scene (as crates/cli/tests/mitsuba_slab.py's): the export is `Include`d after WorldBegin, as its header
says; a closed box W wide and T thick (scene units), its top face at z = 0, gets the route's material;
an orthographic camera 1 unit above looks straight down at a square W/500 wide at the middle, box pixel
filter, independent sampler, `volpath` integrator with the maxdepth the export's header names (or
--maxdepth). Lights:
- uniform: an `infinite` light of radiance 1 (rgb 1 1 1). By reciprocity a pixel is the slab's
  reflectance for light arriving along the normal: R0 = ((eta - 1)/(eta + 1))^2 plus Rd.
- point:   a point light 5 W/1000 above the middle; distant: a `distant` light along the normal.
  (Delta lights: the medium route must render black, the subsurface routes must not.)

Prints one JSON object: per channel (R, G, B) the mean over pixels and its standard error
(pixel-to-pixel spread / sqrt(pixels)), pixels, spp, maxdepth, seconds, and pbrt's version line.
"""

import argparse
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time


def box_mesh(w, t):
    """A closed box [-w/2, w/2]^2 x [-t, 0] as a pbrt trianglemesh with outward normals."""
    h = w / 2
    p = [
        (-h, -h, -t), (h, -h, -t), (h, h, -t), (-h, h, -t),  # bottom 0-3
        (-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0),  # top 4-7
    ]
    # Counter-clockwise seen from outside: the geometric normal (p1 - p0) x (p2 - p0) points out.
    quads = [
        (4, 5, 6, 7),  # top, +z
        (0, 3, 2, 1),  # bottom, -z
        (0, 1, 5, 4),  # -y
        (2, 3, 7, 6),  # +y
        (1, 2, 6, 5),  # +x
        (3, 0, 4, 7),  # -x
    ]
    idx = []
    for a, b, c, d in quads:
        idx += [a, b, c, a, c, d]
    pts = " ".join(f"{x:g} {y:g} {z:g}" for x, y, z in p)
    return f'Shape "trianglemesh" "integer indices" [ {" ".join(map(str, idx))} ] "point3 P" [ {pts} ]'


def read_pfm(path):
    with open(path, "rb") as f:
        data = f.read()
    # Header: "PF\n<w> <h>\n<scale>\n", then float32 RGB rows bottom to top.
    parts = data.split(b"\n", 3)
    if parts[0].strip() != b"PF":
        sys.exit(f"{path}: not an RGB PFM")
    w, h = map(int, parts[1].split())
    scale = float(parts[2])
    fmt = "<" if scale < 0 else ">"
    values = struct.unpack(f"{fmt}{w * h * 3}f", parts[3][: w * h * 12])
    return w, h, values


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("export")
    ap.add_argument(
        "--route",
        choices=["subsurface", "coefficients", "medium", "medium-rgb"],
        required=True,
    )
    ap.add_argument("--light", choices=["uniform", "point", "distant"], default="uniform")
    ap.add_argument("--width", type=float, default=2000.0)
    ap.add_argument("--thickness", type=float, default=400.0)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--res", type=int, default=16)
    ap.add_argument("--maxdepth", type=int, default=None, help="default: the export header's")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--pbrt", default=os.environ.get("PBRT", "pbrt"))
    args = ap.parse_args()

    text = open(args.export, encoding="utf-8").read()
    first = re.search(r'^MakeNamedMaterial "([^"]+)"', text, re.M)
    if not first:
        sys.exit(f"{args.export}: no MakeNamedMaterial")
    mid = first.group(1)
    depth = args.maxdepth
    if depth is None:
        m = re.search(r'Integrator "volpath" "integer maxdepth" \[ (\d+) \]', text)
        depth = int(m.group(1)) if m else 5

    w, t = args.width, args.thickness
    s = w / 1000
    if args.route.startswith("medium"):
        material = f'MediumInterface "{mid}-{args.route}" ""\n    NamedMaterial "{mid}-boundary"'
    elif args.route == "coefficients":
        material = f'NamedMaterial "{mid}-coefficients"'
    else:
        material = f'NamedMaterial "{mid}"'
    if args.light == "uniform":
        light = 'LightSource "infinite" "rgb L" [ 1 1 1 ]'
    elif args.light == "point":
        light = f'LightSource "point" "rgb I" [ 1 1 1 ] "point3 from" [ 0 0 {5 * s:g} ]'
    else:
        light = 'LightSource "distant" "rgb L" [ 1 1 1 ] "point3 from" [ 0 0 1 ] "point3 to" [ 0 0 0 ]'

    work = tempfile.mkdtemp(prefix="pbrt_check_")
    try:
        shutil.copy(args.export, os.path.join(work, "export.pbrt"))
        scene = f"""LookAt 0 0 1  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [ {-s / 2:g} {s / 2:g} {-s / 2:g} {s / 2:g} ]
Film "rgb" "integer xresolution" [ {args.res} ] "integer yresolution" [ {args.res} ]
    "string filename" [ "out.pfm" ]
PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]
Sampler "independent" "integer pixelsamples" [ {args.spp} ] "integer seed" [ {args.seed} ]
Integrator "volpath" "integer maxdepth" [ {depth} ]
WorldBegin
Include "export.pbrt"
{light}
AttributeBegin
    {material}
    {box_mesh(w, t)}
AttributeEnd
"""
        with open(os.path.join(work, "scene.pbrt"), "w", encoding="utf-8") as f:
            f.write(scene)
        start = time.perf_counter()
        run = subprocess.run(
            [args.pbrt, "--quiet", "scene.pbrt"], cwd=work, capture_output=True, text=True
        )
        seconds = time.perf_counter() - start
        if run.returncode != 0:
            sys.exit(f"pbrt failed ({run.returncode}):\n{run.stdout}\n{run.stderr}")
        wpx, hpx, values = read_pfm(os.path.join(work, "out.pfm"))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    n = wpx * hpx
    mean, stderr = [], []
    for c in range(3):
        v = values[c::3]
        m = sum(v) / n
        mean.append(m)
        stderr.append(math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1) / n))
    print(
        json.dumps(
            {
                "mean": mean,
                "stderr": stderr,
                "pixels": n,
                "spp": args.spp,
                "maxdepth": depth,
                "seconds": seconds,
                "route": args.route,
                "light": args.light,
            }
        )
    )


if __name__ == "__main__":
    main()
