"""How close Blender (Cycles) renders scatterfit's Blender export to the measured material.

Not part of the test suite (CI's Blender test is crates/cli/tests/blender.rs); BENCHMARKS.md
("exports") reports its output. Needs the `bpy` package (Blender as a Python module; `pip install
bpy==4.2.*` or `bpy==5.0.1` under Python 3.11) for the render modes; `compare` needs only the
standard library.

    python blender_cycles_check.py uniform EXPORT.py SAMPLES OUT.json
    python blender_cycles_check.py edge    EXPORT.py SAMPLES OUT.json
    python3 blender_cycles_check.py compare OUT.json MCML_PROFILES.csv ETA ALBEDO_R ALBEDO_G ALBEDO_B

Scenes (scene unit mm; a box 400 x 400 x 200 with the exported material, top face at z = 0):
- uniform: white world of radiance 1, orthographic camera along the normal, 16 x 16 px. By reciprocity a
  pixel is the reflectance for normal incidence: R0 + Rd (see crates/cli/tests/mitsuba_slab.py).
- edge: dark world; a rectangular area light 0.5 mm above the surface covering x < 0 with a 1 degree
  spread (a sharp shadow edge at x = 0); the camera sees 0 < x < 12 mm. Columns are averaged over y.
- compare: the edge scene's exact answer from a radial profile Rd(r) (MCML's, sigma_t' = 1 mm^-1):
  E(x) = integral over u > x of Lambda(u), Lambda(u) = integral over y of Rd(sqrt(u^2 + y^2)); prints both
  normalised at x = 1 mm and the mean decay rate -d ln E/dx between x = 2 and 6 mm.
"""

import json
import math
import runpy
import sys


def render(mode, export, samples, out):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    mat = runpy.run_path(export, run_name="scatterfit_export")["apply"]()
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device, c.samples, c.use_denoising, c.use_adaptive_sampling = "CPU", samples, False, False
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
        # Deprecated in Blender 5.0 (removed in 6.0): worlds always use nodes there.
        scene.world.use_nodes = True
    background = scene.world.node_tree.nodes["Background"]
    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "ORTHO"
    cam_data.clip_start, cam_data.clip_end = 1, 1000
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    if mode == "uniform":
        background.inputs["Color"].default_value = (1, 1, 1, 1)
        background.inputs["Strength"].default_value = 1
        cam.location = (0, 0, 50)
        cam_data.ortho_scale = 20
        scene.render.resolution_x = scene.render.resolution_y = 16
    else:
        background.inputs["Strength"].default_value = 0
        light = bpy.data.lights.new("half-plane", "AREA")
        light.shape, light.size, light.size_y = "RECTANGLE", 400, 800
        light.spread = math.radians(1.0)
        light.energy = 1e6
        light_obj = bpy.data.objects.new("half-plane", light)
        light_obj.location = (-200, 0, 0.5)
        scene.collection.objects.link(light_obj)
        cam.location = (6, 0, 50)
        cam_data.ortho_scale = 12
        scene.render.resolution_x, scene.render.resolution_y = 240, 16
    scene.render.resolution_percentage = 100
    scene.render.filepath = out + ".exr"
    bpy.ops.render.render(write_still=True)

    image = bpy.data.images.load(out + ".exr")
    px = list(image.pixels)
    w, h = image.size
    if mode == "uniform":
        n = w * h
        result = {"blender": bpy.app.version_string, "mean": [], "stderr": []}
        for ch in range(3):
            v = px[ch::4]
            m = sum(v) / n
            result["mean"].append(m)
            result["stderr"].append(math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1) / n))
    else:
        result = {"blender": bpy.app.version_string, "x_mm": [], "rgb": []}
        for i in range(w):
            result["x_mm"].append((i + 0.5) * 12 / w)
            result["rgb"].append(
                [sum(px[4 * (j * w + i) + ch] for j in range(h)) / h for ch in range(3)]
            )
    with open(out, "w") as f:
        json.dump(result, f)
    print(json.dumps(result)[:300])


def compare(out, profiles_csv, eta, albedos):
    rows = []
    with open(profiles_csv) as f:
        lines = [line for line in f if not line.startswith("#")]
    header = lines[0].strip().split(",")
    for line in lines[1:]:
        rows.append(dict(zip(header, map(float, line.strip().split(",")))))
    edge = json.load(open(out))
    xs = edge["x_mm"]
    probe = [1.0, 2.0, 4.0, 6.0, 8.0]
    near = {t: min(range(len(xs)), key=lambda i: abs(xs[i] - t)) for t in probe}
    for ch, albedo in enumerate(albedos):
        prof = [
            (r["r_mm"], r["rd_per_mm2"])
            for r in rows
            if abs(r["eta"] - eta) < 1e-9 and abs(r["albedo_prime"] - albedo) < 1e-9
        ][:-1]  # the last bin collects every photon beyond it
        if not prof:
            print(f"channel {ch}: no MCML profile at eta {eta}, albedo {albedo}")
            continue
        width = prof[1][0] - prof[0][0]

        def rd(r):
            k = int(r / width)
            return prof[k][1] if k < len(prof) else 0.0

        du, dy = 0.05, 0.025
        lam = [
            sum(2 * rd(math.hypot(k * du, (j + 0.5) * dy)) * dy for j in range(800))
            for k in range(400)
        ]

        def exact(x):
            return sum(lam[int(x / du):]) * du

        e1, c1 = exact(xs[near[1.0]]), edge["rgb"][near[1.0]][ch]
        print(f"channel {'RGB'[ch]}, eta {eta}, albedo {albedo}")
        for t in probe:
            i = near[t]
            print(f"  x = {xs[i]:.3f} mm: Cycles {edge['rgb'][i][ch] / c1:.4g}  exact {exact(xs[i]) / e1:.4g}")
        i2, i6 = near[2.0], near[6.0]
        dx = xs[i6] - xs[i2]
        rate_c = -math.log(edge["rgb"][i6][ch] / edge["rgb"][i2][ch]) / dx
        rate_e = -math.log(exact(xs[i6]) / exact(xs[i2])) / dx
        print(f"  decay rate 2-6 mm: Cycles {rate_c:.3f}/mm, exact {rate_e:.3f}/mm, ratio {rate_c / rate_e:.2f}")


if __name__ == "__main__":
    mode = sys.argv[1]
    if mode == "compare":
        compare(sys.argv[2], sys.argv[3], float(sys.argv[4]), [float(a) for a in sys.argv[5:8]])
    else:
        render(mode, sys.argv[2], int(sys.argv[3]), sys.argv[4])
