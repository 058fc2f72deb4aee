"""Render a slab of an exported scatterfit material with Mitsuba 3 and print its mean brightness.

Used by crates/cli/tests/mitsuba.rs (and its ignored high-quality benchmark); runs under the virtual
environment that .ci/run makes (`pip install mitsuba`). Standard library + mitsuba only.

    python mitsuba_slab.py FRAGMENT.xml --width W --thickness T [--backing] [--spp N] [--res R] [--seed S]
        [--light constant|directional] [--extra FRAGMENT2.xml] [--variant scalar_rgb|scalar_spectral]

The scene: FRAGMENT.xml (what `scatterfit export --to mitsuba` writes) is <include>d; a box W wide and
T thick, its top face at z = 0, gets the fragment's dielectric BSDF as its boundary and its medium as its
interior. A constant environment of radiance 1 lights it from every direction, and an orthographic
camera 1 scene unit above the top face looks straight down at its middle (a square W/500 wide: Mitsuba
offsets rays it spawns at a surface by about 1e-4 (1 + |p|) scene units, which shifts the first
scattering deeper and, with coordinates of 100 mean free paths, lowers Rd by ~1 % at low albedo; near
the origin the shift is negligible, and the slab is uniform, so any patch of it will do), volpath integrator with
unbounded depth and Russian roulette only after ln(1e-3)/ln(albedo) scatterings, box pixel filter so
that pixels are independent estimates.
With --backing, a black plane T/10 below the box (10 W wide) hides the lower hemisphere (Mitsuba offsets
spawned rays by about 1e-4 (1 + |p|) scene units, so the gap and the slab must be much thicker than that).

What a pixel measures: L = integral of f(wi -> wo) L_env cos(wi) dwi over the directions wi, which by
reciprocity is the reflectance of the slab for light arriving along the camera direction, here the
normal: the specular Fresnel reflectance R0 = ((eta - 1)/(eta + 1))^2 plus the diffuse reflectance Rd
for collimated normal incidence (MCML's Rd), plus, without --backing, the transmittance of light from
below (zero for a thick slab).

--light directional replaces the environment by a `directional` emitter shining straight down (a
delta light: the medium behind its dielectric boundary must render black, as the export's header says).
--extra includes a second exported fragment in the same scene and gives its materials to a second box
beside the first, out of view (two materials' ids in one scene must not clash, and each shape must get
its own material). --variant picks Mitsuba's variant (scalar_rgb by default; scalar_spectral uplifts
the RGB coefficients to spectra; a fragment exported with `--mitsuba-variant spectral` has a medium
per wavelength for them).

Prints one JSON object: per channel (R, G, B) the mean over pixels and its standard error (pixel-to-pixel
spread / sqrt(pixels)), the pixel count, spp, seconds, and the Mitsuba version.
"""

import argparse
import re
import json
import math
import os
import sys
import time
import xml.etree.ElementTree as ET


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fragment")
    ap.add_argument("--width", type=float, required=True, help="slab width, scene units")
    ap.add_argument("--thickness", type=float, required=True, help="slab thickness, scene units")
    ap.add_argument("--backing", action="store_true", help="black plane below the slab")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--res", type=int, default=16)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--light", choices=["constant", "directional"], default="constant")
    ap.add_argument("--extra", help="a second fragment, given to a box out of view")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument(
        "--integrator",
        help="the integrator type (default: the one the fragment's header recommends, else volpath)",
    )
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant(args.variant)

    suffix = "_medium"

    def ids(path):
        root = ET.parse(path).getroot()
        bsdf = [e for e in root if e.tag == "bsdf"]
        medium = [e for e in root if e.tag == "medium" and e.get("id", "").endswith(suffix)]
        if len(bsdf) != 1 or len(medium) != 1:
            sys.exit(f"{path}: expected one <bsdf> and one <medium> with an id ending {suffix}")
        return bsdf[0].get("id"), medium[0].get("id"), medium[0]

    fragment = os.path.abspath(args.fragment)
    bsdf_id, medium_id, medium = ids(fragment)
    # The integrator the fragment's header recommends: the test renders at the export's own advice.
    with open(fragment, encoding="utf-8") as f:
        advised = re.search(r'<integrator type=\\?"(\w+)\\?"', f.read())
    integrator = args.integrator or (advised.group(1) if advised else "volpath")
    albedo = [e for e in medium if e.tag in ("rgb", "spectrum") and e.get("name") == "albedo"]
    # "a, b, c" (rgb) or "λ:a, λ:b, …" (spectrum): the largest value.
    alpha = (
        max(float(x.split(":")[-1]) for x in albedo[0].get("value").split(",")) if albedo else 0.99
    )
    # Russian roulette only once every channel's throughput is below 1e-3: Mitsuba's volpath
    # survives a roulette with q = min(max throughput, 0.95), so at albedos above 0.95 early
    # roulette leaves the long paths that carry much of Rd (α' = 0.999: hundreds of scatterings)
    # to rare samples with huge weights, and finite renders come out low.
    rr_depth = max(5, math.ceil(math.log(1e-3) / math.log(alpha))) if alpha < 1 else 100000

    w, t = args.width, args.thickness
    extra = ""
    if args.extra:
        extra_path = os.path.abspath(args.extra)
        if os.path.dirname(extra_path) != os.path.dirname(fragment):
            sys.exit("--extra must be in the same folder as the fragment")
        extra_bsdf, extra_medium, _ = ids(extra_path)
        extra = f"""
    <include filename="{os.path.basename(extra_path)}"/>
    <shape type="cube">
        <transform name="to_world">
            <scale x="{w / 2}" y="{w / 2}" z="{t / 2}"/>
            <translate x="{2 * w}" z="{-t / 2}"/>
        </transform>
        <ref id="{extra_bsdf}"/>
        <ref name="interior" id="{extra_medium}"/>
    </shape>"""
    if args.light == "constant":
        light = """<emitter type="constant">
        <rgb name="radiance" value="1, 1, 1"/>
    </emitter>"""
    else:
        light = """<emitter type="directional">
        <vector name="direction" x="0" y="0" z="-1"/>
        <rgb name="irradiance" value="1, 1, 1"/>
    </emitter>"""
    backing = ""
    if args.backing:
        backing = f"""
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="{5 * w}"/>
            <translate z="{-t * 1.1}"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>
    </shape>"""
    scene_xml = f"""<scene version="3.0.0">
    <include filename="{os.path.basename(fragment)}"/>
    <integrator type="{integrator}">
        <integer name="max_depth" value="-1"/>
        <integer name="rr_depth" value="{rr_depth}"/>
    </integrator>
    <sensor type="orthographic">
        <transform name="to_world">
            <scale x="{w / 1000}" y="{w / 1000}" z="1"/>
            <lookat origin="0, 0, 1" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="{args.res}"/>
            <integer name="height" value="{args.res}"/>
            <rfilter type="box"/>
        </film>
        <sampler type="independent">
            <integer name="sample_count" value="{args.spp}"/>
        </sampler>
    </sensor>
    {light}
    <shape type="cube">
        <transform name="to_world">
            <scale x="{w / 2}" y="{w / 2}" z="{t / 2}"/>
            <translate z="{-t / 2}"/>
        </transform>
        <ref id="{bsdf_id}"/>
        <ref name="interior" id="{medium_id}"/>
    </shape>{backing}{extra}
</scene>
"""
    scene_path = os.path.join(os.path.dirname(fragment), "mitsuba_slab_scene.xml")
    with open(scene_path, "w", encoding="utf-8") as f:
        f.write(scene_xml)

    start = time.perf_counter()
    scene = mi.load_file(scene_path)
    image = mi.render(scene, seed=args.seed)
    seconds = time.perf_counter() - start

    values = list(image.array)
    n = len(values) // 3
    mean, stderr = [], []
    for c in range(3):
        v = values[c::3]
        m = sum(v) / n
        var = sum((x - m) ** 2 for x in v) / (n - 1)
        mean.append(m)
        stderr.append(math.sqrt(var / n))
    print(
        json.dumps(
            {
                "mean": mean,
                "stderr": stderr,
                "pixels": n,
                "spp": args.spp,
                "seconds": seconds,
                "rr_depth": rr_depth,
                "max": [max(values[c::3]) for c in range(3)],
                "variant": args.variant,
                "mitsuba": mi.__version__,
            }
        )
    )


if __name__ == "__main__":
    main()
