"""A room of ten aged 1k materials under two light spectra: Age, file and render cost.

    ./run py -m benchmarks.live_room                 # 1024² textures, Cycles 240 x 135, 16 spp
    ./run py -m benchmarks.live_room --size 512 --samples 8 --eevee

The room: a floor, three walls and six boxes (ten objects, each with its own
material: a 1024² photograph-like image straight into Base Color, Printed Paper or
Dyed Fabric), lit by a sun through the open side (daylight) and a ceiling lamp
(incandescent): two spectra. Printed side by side, in one process:

* **Age vs bake** — wall time of Bake Exposure and of Age with an empty table cache
  (the tables are built) and with a warm one (found on disk), and their ratio;
* **file** — bytes of the saved file: original, after the bake, after Age; what Age
  added against what the exposure maps added;
* **render** — Cycles CPU time (process CPU seconds) of the live aged room (the frame
  images' handler taken out: what renders where LightFade is absent;
  ``benchmarks/frame_cost.py`` measures the frame images) at 25 years and
  of the same render after Reset, two of each (the smaller counts), and their
  ratio, for each *Aged Colour On* setting (the ray gate, :func:`..copies.gate_rays`),
  and at 0 years;
  with ``--eevee`` EEVEE renders before and after the aged shaders compile;
* **default bake** — with ``--default-bake``, the same room baked at the scene's
  defaults (the *Final* preset), against the cold Age above;
* **bounce error** — what the gate costs in colour: ΔE00 (p50 / p99) of 8 × 8-pixel
  means of each gated render against the ungated (``ALL``) one, beside the same
  figure for two ungated renders with different seeds (the noise floor);
* **huge years** — the 20-year render, then 1e9 years, then 20 years again: the largest
  pixel difference between the two 20-year renders.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)
import addon_utils  # noqa: E402

from benchmarks.problem import synthetic_photo  # noqa: E402

RECIPES = ("PRINTED_PAPER", "DYED_FABRIC")


def _material(name, size, seed, recipe):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    image = bpy.data.images.new(name, size, size)
    rgba = np.ones((size, size, 4), np.float32)
    photo = synthetic_photo(size, size)
    rgba[..., :3] = np.roll(photo, seed * size // 7, axis=1)[..., np.roll([0, 1, 2], seed)]
    image.pixels.foreach_set(rgba.ravel())
    image.pack()
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    mat.node_tree.links.new(tex.outputs["Color"],
                            mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    mat.lightfade.enabled = True
    mat.lightfade.recipe = recipe
    return mat


def build(size):
    """The room (ten objects, ten materials) with its lights and a camera."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    scene = bpy.context.scene
    shapes = [("plane", (0, 0, 0), 6.0, (0, 0, 0)),
              ("plane", (0, 3, 1.5), 6.0, (math.pi / 2, 0, 0)),
              ("plane", (-3, 0, 1.5), 6.0, (0, math.pi / 2, 0)),
              ("plane", (3, 0, 1.5), 6.0, (0, math.pi / 2, 0))]
    shapes += [("cube", (-1.8 + 1.2 * (k % 3), -0.8 + 1.6 * (k // 3), 0.35), 0.7, (0, 0, 0.3 * k))
               for k in range(6)]
    for k, (kind, loc, size_m, rot) in enumerate(shapes):
        if kind == "plane":
            bpy.ops.mesh.primitive_plane_add(size=size_m, location=loc, rotation=rot)
        else:
            bpy.ops.mesh.primitive_cube_add(size=size_m, location=loc, rotation=rot)
        obj = bpy.context.active_object
        obj.name = f"Item{k}"
        obj.data.materials.append(_material(f"Mat{k}", size, k, RECIPES[k % 2]))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 4.0
    sun.rotation_euler = (math.radians(50), 0, math.radians(20))
    scene.collection.objects.link(sun)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 300.0
    lamp.data.lightfade.spectrum = "INCANDESCENT"
    lamp.location = (0.0, 0.5, 2.8)
    scene.collection.objects.link(lamp)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location = (0.0, -6.5, 3.0)
    cam.rotation_euler = (math.radians(68), 0, 0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    return scene


def save_bytes(scene, folder, name):
    path = os.path.join(folder, name)
    bpy.ops.wm.save_as_mainfile(filepath=path, copy=True, compress=False)
    return os.path.getsize(path)


def render(scene, engine, samples, size, folder, name):
    """(CPU seconds, wall seconds, (H, W, 4) pixels) of one still."""
    scene.render.engine = engine
    if engine == "CYCLES":
        scene.cycles.samples = samples
        scene.cycles.device = "CPU"
        scene.cycles.use_denoising = False
    else:
        scene.eevee.taa_render_samples = samples
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    path = os.path.join(folder, name + ".exr")
    scene.render.filepath = path
    from lightfade_addon.blender.aging import frames

    live = frames.on_render_pre in bpy.app.handlers.render_pre
    if live:                                   # the live material (frame_cost.py: the frames)
        bpy.app.handlers.render_pre.remove(frames.on_render_pre)
    try:
        c0, w0 = time.process_time(), time.perf_counter()
        bpy.ops.render.render(write_still=True)
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    finally:
        if live:
            bpy.app.handlers.render_pre.append(frames.on_render_pre)
    image = bpy.data.images.load(path)
    px = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return cpu, wall, px.reshape(size[1], size[0], 4)


def block_dE(a, b, block=8):
    """ΔE00 between the ``block`` × ``block``-pixel means of two renders (noise averaged),
    both scaled by the same factor so that ``b``'s 99th percentile is white."""
    from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, delta_E_2000, linear_srgb_to_XYZ

    scale = 1.0 / max(float(np.percentile(b[..., :3], 99)), 1e-6)

    def lab(x):
        H, W = (x.shape[0] // block) * block, (x.shape[1] // block) * block
        m = scale * x[:H, :W, :3].reshape(H // block, block, W // block, block, 3).mean((1, 3))
        return XYZ_to_Lab(linear_srgb_to_XYZ(np.clip(m, 0.0, 1.0).reshape(-1, 3)))

    return delta_E_2000(lab(a), lab(b))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024, help="texture side (px)")
    parser.add_argument("--density", type=float, default=48.0, help="exposure texels per metre")
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--eevee", action="store_true", help="also first EEVEE renders")
    parser.add_argument("--default-bake", action="store_true",
                        help="also the same room's bake at the scene's defaults (Final preset)")
    args = parser.parse_args(argv)
    from lightfade_addon import api
    from lightfade_addon.core.fading import cache

    folder = tempfile.mkdtemp(prefix="lf_room_")
    cache.set_directory(os.path.join(folder, "cache"))         # an empty table cache
    scene = build(args.size)
    scene.lightfade_bake.texels_per_metre = args.density
    scene.lightfade.bake_samples = 16
    original = save_bytes(scene, folder, "original.blend")
    t0 = time.perf_counter()
    api.bake(scene, quality="CUSTOM", samples=16)
    bake = time.perf_counter() - t0
    baked = save_bytes(scene, folder, "baked.blend")
    maps = sum(len(o.lightfade.exposure_maps) for o in scene.objects if o.type == "MESH")
    t0 = time.perf_counter()
    api.age_scene(scene, years=25.0)
    age_cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    api.age_scene(scene, years=25.0)                            # tables on disk now
    age_warm = time.perf_counter() - t0
    aged_bytes = save_bytes(scene, folder, "aged.blend")
    tables = [i for i in bpy.data.images if i.name.startswith("LF_Table_")]
    print(f"room: 10 materials of {args.size}² under 2 spectra, {maps} exposure maps, "
          f"{len(tables)} colour tables ({', '.join(f'{i.size[0]}x{i.size[1]}' for i in tables)})")
    print(f"bake {bake:7.1f} s | Age {age_cold:6.1f} s with tables built "
          f"({age_cold / bake:.2f}x), {age_warm:5.1f} s with tables cached "
          f"({age_warm / bake:.2f}x); target <= 0.25x")
    print(f"file: original {original / 1e6:7.1f} MB, +{(baked - original) / 1e6:6.1f} MB by the "
          f"exposure maps, +{(aged_bytes - baked) / 1e6:6.1f} MB by Age "
          f"({(aged_bytes - baked) / max(baked - original, 1):.2f}x the maps; target <= 1x)")

    res = (240, 135)
    api.set_years(scene, 20.0)
    _c, _w, twenty = render(scene, "CYCLES", args.samples, res, folder, "twenty")
    api.set_years(scene, 1e9)
    _c, _w, huge = render(scene, "CYCLES", args.samples, res, folder, "huge")
    api.set_years(scene, 20.0)
    _c, _w, back = render(scene, "CYCLES", args.samples, res, folder, "back")
    print(f"huge years: 20 y vs 1e9 y differ by up to {np.abs(huge - twenty).max():.3f}; "
          f"20 y again vs 20 y: max difference {np.abs(back - twenty).max():.2e}")

    cpu, px = {}, {}
    for rays in ("ALL", "VISIBLE", "CAMERA"):
        scene.lightfade.aged_rays = rays
        api.age_scene(scene, years=25.0)
        runs = [render(scene, "CYCLES", args.samples, res, folder, f"{rays}{k}") for k in range(2)]
        cpu[rays], px[rays] = min(r[0] for r in runs), runs[0][2]
        if rays == "ALL":
            scene.cycles.seed = 1
            px["seed"] = render(scene, "CYCLES", args.samples, res, folder, "seed")[2]
            scene.cycles.seed = 0
            api.set_years(scene, 0.0)
            cpu["zero"] = min(render(scene, "CYCLES", args.samples, res, folder, f"zero{k}")[0]
                              for k in range(2))
            api.set_years(scene, 25.0)
    scene.lightfade.aged_rays = "VISIBLE"
    api.reset(scene)
    reset = min(render(scene, "CYCLES", args.samples, res, folder, f"reset{k}")[0]
                for k in range(2))
    print(f"Cycles {res[0]}x{res[1]}, {args.samples} spp, CPU time after Reset {reset:.2f} s; "
          f"aged at 25 years (target <= 1.15x):")
    print(f"  at 0 years (All Rays)          {cpu['zero']:6.2f} s: {cpu['zero'] / reset:.2f}x")
    for rays in ("ALL", "VISIBLE", "CAMERA"):
        print(f"  Aged Colour On {rays:8s} {cpu[rays]:6.2f} s: {cpu[rays] / reset:.2f}x")
    for name in ("VISIBLE", "CAMERA", "seed"):
        d = block_dE(px[name], px["ALL"])
        label = "ALL, another seed (noise)" if name == "seed" else name
        print(f"  bounce error {label:26s} vs ALL: dE00 of 8x8 means p50 {np.median(d):.2f}, "
              f"p99 {np.percentile(d, 99):.2f}")
    if args.eevee:
        engine = "BLENDER_EEVEE_NEXT" if bpy.app.version < (4, 2, 0) or \
            "BLENDER_EEVEE_NEXT" in {e.identifier for e in
                                     bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items} \
            else "BLENDER_EEVEE"
        _c, w_start, _p = render(scene, engine, 4, res, folder, "eevee_start")
        _c, w_reset, _p = render(scene, engine, 4, res, folder, "eevee_reset")
        api.age_scene(scene, years=25.0)
        _c, w_live, _p = render(scene, engine, 4, res, folder, "eevee_live")
        _c, w_again, _p = render(scene, engine, 4, res, folder, "eevee_again")
        print(f"EEVEE (software GL) after Reset: first render {w_start:.1f} s (engine start "
              f"and the originals' shaders), then {w_reset:.1f} s; aged: first render "
              f"{w_live:.1f} s (the aged shaders compiled), then {w_again:.1f} s: "
              f"+{(w_live - w_again) / 10:.2f} s of compile per aged material")

    if args.default_bake:
        wall, _process, what = default_bake(args.size)
        print(f"default bake ({what}): Age with tables built {age_cold:.1f} s is "
              f"{age_cold / wall:.2f}x it (target <= 0.25x)")


def default_bake(size):
    """(wall s, process s, what) of the same room, new, baked at the scene's defaults
    (what a user's bake costs)."""
    from lightfade_addon import api

    scene = build(size)
    c0, w0 = time.process_time(), time.perf_counter()
    api.bake(scene)
    wall, process = time.perf_counter() - w0, time.process_time() - c0
    what = (f"{scene.lightfade_bake.quality}, {scene.lightfade_bake.texels_per_metre:g} "
            f"texels/m: {wall:.1f} s wall, {process:.1f} s process")
    return wall, process, what


if __name__ == "__main__":
    main()
