"""Run a scatterfit Blender export inside Blender (the `bpy` module) and render a slab of it with Cycles.

Used by crates/cli/tests/blender.rs; runs under the virtual environment that .ci/run makes
(`pip install bpy`, CPython 3.11). Standard library + bpy only.

    python blender_slab.py EXPORT.py [--samples N] [--res R] [--render]

What it does, printing one JSON object:
- runs EXPORT.py twice as Blender would (`blender --python EXPORT.py`: as `__main__`), recording every
  warning the script raises (Blender 5.0 deprecates `Material.use_nodes`), and reports the materials
  then in the file (running twice must not make a second material);
- reads back the Principled BSDF's inputs of the material the script's VALUES name: Base Color,
  Subsurface Radius, Scale, IOR, Subsurface IOR, Weight, the subsurface method;
- with --render: a box 400 x 400 x 200 scene units of the material, top face at z = 0, a white world of
  radiance 1, an orthographic camera along the normal (R x R px, N samples, no denoising, 64 bounces of
  each kind, no clamping, a tiny pixel filter, linear EXR output). By reciprocity a pixel is the slab's
  reflectance for light arriving along the normal, R0 + Rd (see mitsuba_slab.py); prints the mean per
  channel and its standard error (pixel-to-pixel spread / sqrt(pixels)).
"""

import argparse
import json
import math
import os
import runpy
import sys
import tempfile
import time
import warnings


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("export")
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--res", type=int, default=16)
    ap.add_argument("--render", action="store_true")
    args = ap.parse_args()

    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    export = os.path.abspath(args.export)
    caught = []
    for _ in range(2):
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            namespace = runpy.run_path(export, run_name="__main__")
        caught += [
            f"{x.category.__name__}: {x.message}" for x in w if os.path.abspath(x.filename) == export
        ]
    values = namespace["VALUES"]
    mat = bpy.data.materials[values["material"]]
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")

    def value(name):
        v = bsdf.inputs[name].default_value
        try:
            return list(v)
        except TypeError:
            return v

    result = {
        "blender": bpy.app.version_string,
        "warnings": caught,
        "materials": [m.name for m in bpy.data.materials],
        "material": mat.name,
        "values_name": values["name"],
        "method": bsdf.subsurface_method,
        "inputs": {
            name: value(name)
            for name in [
                "Base Color",
                "Subsurface Weight",
                "Subsurface Radius",
                "Subsurface Scale",
                "Subsurface IOR",
                "IOR",
                "Subsurface Anisotropy",
                "Roughness",
            ]
        },
    }

    if args.render:
        scene = bpy.context.scene
        scene.render.engine = "CYCLES"
        c = scene.cycles
        c.device, c.samples, c.use_denoising, c.use_adaptive_sampling = "CPU", args.samples, False, False
        c.seed = 7
        c.max_bounces = c.transmission_bounces = c.diffuse_bounces = c.glossy_bounces = 64
        c.sample_clamp_direct = c.sample_clamp_indirect = 0
        c.filter_width = 0.01
        scene.view_settings.view_transform = "Standard"
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, -100))
        slab = bpy.context.active_object
        slab.scale = (400, 400, 200)
        slab.data.materials.append(mat)
        scene.world = bpy.data.worlds.new("world")
        if bpy.app.version < (5, 0, 0):
            scene.world.use_nodes = True
        background = scene.world.node_tree.nodes["Background"]
        background.inputs["Color"].default_value = (1, 1, 1, 1)
        background.inputs["Strength"].default_value = 1
        cam_data = bpy.data.cameras.new("camera")
        cam_data.type = "ORTHO"
        cam_data.clip_start, cam_data.clip_end = 1, 1000
        cam_data.ortho_scale = 20
        cam = bpy.data.objects.new("camera", cam_data)
        cam.location = (0, 0, 50)
        scene.collection.objects.link(cam)
        scene.camera = cam
        scene.render.resolution_x = scene.render.resolution_y = args.res
        scene.render.resolution_percentage = 100
        out = os.path.join(tempfile.mkdtemp(prefix="blender_slab_"), "slab.exr")
        scene.render.filepath = out
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        result["seconds"] = time.perf_counter() - start
        image = bpy.data.images.load(out)
        px = list(image.pixels)
        n = image.size[0] * image.size[1]
        result["mean"], result["stderr"] = [], []
        for ch in range(3):
            v = px[ch::4]
            m = sum(v) / n
            result["mean"].append(m)
            result["stderr"].append(math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1) / n))
        result["pixels"], result["samples"] = n, args.samples
    sys.stdout.flush()
    print("SCATTERFIT-RESULT " + json.dumps(result))


if __name__ == "__main__":
    main()
