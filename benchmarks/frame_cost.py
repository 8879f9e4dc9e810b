"""What an aged frame costs: Cycles and EEVEE renders against Reset, and the rate at
which aged images are written, side by side in one process.

    ./run py -m benchmarks.frame_cost                          # ten 1k materials, two spectra
    ./run py -m benchmarks.frame_cost --blend out/room.blend   # an aged file (furnished room)
    ./run py -m benchmarks.frame_cost --blend out/room.blend --res 480 300 --samples 24 --eevee

Without ``--blend`` the room is :func:`benchmarks.live_room.build` (ten objects, ten
1k image materials, a sun and an incandescent lamp), baked at 16 samples and aged.
With ``--blend`` the file must hold aged materials (Age pressed) and a camera (the
furnished room's own view is added when it has none: ``tools/furnished_room.py``).
Printed:

* **images** — wall seconds per Mtexel of writing every aged copy's frame image
  (:func:`lightfade_addon.blender.aging.frames.write_frames`, what a render's
  ``render_pre`` does, Apply's evaluator): the first call (every band evaluated), the
  same years again, 0.1 year later, 20 % more years; and ``api.apply_aging`` once;
* **Cycles** — CPU seconds (process time: every thread, the handler included) of the
  frame at ``--years``, two renders each (the smaller counts) unless said: after Reset;
  with the aged colours as plain image textures (``api.apply_aging``: what the aged
  room costs as image textures — an aged room is lighter than the original, and
  longer light paths cost Cycles more); with the frame images (LightFade installed) —
  the same frame again, the first frame at a years value the images and bands have
  not met (20 % fewer years, then back), a time-lapse step (+0.1 year a frame); with
  the live material only (the handler taken out: what renders where LightFade is
  absent); the frame images at :data:`ORIGINAL_YEARS` (the original colours, to the
  8-bit code, through the same images: what the images cost, apart from the lighter
  colours; at 0 years the live material renders, its aging gated off); ratios against Reset
  and against the image textures; and the ΔE00 between
  the frame-image render and the live render (8 × 8-pixel means, same seed) beside the
  same figure for the live render at another seed (the noise floor);
* **EEVEE** (``--eevee``) — wall seconds of the first and second render after Reset
  and after Age (EEVEE renders the live material: no frame images for it), and the
  compile per aged material.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)

from benchmarks.live_room import block_dE, build  # noqa: E402

#: Years at which the aged colours are the originals to the 8-bit code, but the frame
#: images are written and rendered (at 0 the frame branch is off).
ORIGINAL_YEARS = 1e-4


def _render(scene, engine, samples, res, folder, name):
    """(CPU seconds, wall seconds, (H, W, 4) pixels) of one still."""
    scene.render.engine = engine
    if engine == "CYCLES":
        scene.cycles.samples = samples
        scene.cycles.device = "CPU"
        scene.cycles.use_denoising = False
    else:
        scene.eevee.taa_render_samples = 4
    scene.render.resolution_x, scene.render.resolution_y = res
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = path = os.path.join(folder, name + ".exr")
    c0, w0 = time.process_time(), time.perf_counter()
    bpy.ops.render.render(write_still=True)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    image = bpy.data.images.load(path)
    px = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return cpu, wall, px.reshape(res[1], res[0], 4)


def _live_only(fn):
    """Run ``fn()`` with the frame handler taken out (the live material renders)."""
    from lightfade_addon.blender.aging import frames

    bpy.app.handlers.render_pre.remove(frames.on_render_pre)
    try:
        return fn()
    finally:
        bpy.app.handlers.render_pre.append(frames.on_render_pre)


def _eevee():
    names = {e.identifier for e in
             bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items}
    return "BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in names else "BLENDER_EEVEE"


def _camera(scene):
    """The furnished room's own view where the file has no camera."""
    from tools.furnished_room import place_camera

    if scene.camera is None:
        place_camera(scene)


def image_rate(scene, years):
    """Seconds per Mtexel of writing the frame images: the first call (every band
    evaluated), the same years again, 0.1 year later, 20 % more years; Apply."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import frames

    out = {}
    for label, y in (("first call", years), ("same years", years), ("+0.1 year", years + 0.1),
                     ("+20 %", years * 1.2)):
        t0 = time.perf_counter()
        images = frames.write_frames(scene, y, camera=False)
        wall = time.perf_counter() - t0
        mtexel = sum(i.size[0] * i.size[1] for i in images.values()) / 1e6
        out[label] = wall / mtexel
    t0 = time.perf_counter()
    images = api.apply_aging(scene, years + 0.2)
    wall = time.perf_counter() - t0
    out["apply_aging"] = wall / (sum(i.size[0] * i.size[1] for i in images.values()) / 1e6)
    api.live_aging(scene)
    return mtexel, out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blend", help="an aged .blend (default: the ten-material room)")
    parser.add_argument("--size", type=int, default=1024, help="texture side of the room (px)")
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--res", type=int, nargs=2, default=(240, 135))
    parser.add_argument("--years", type=float, default=25.0)
    parser.add_argument("--eevee", action="store_true", help="also EEVEE renders")
    args = parser.parse_args(argv)
    import lightfade_addon
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import aged_copies

    folder = tempfile.mkdtemp(prefix="lf_frame_")
    if args.blend:
        bpy.ops.wm.open_mainfile(filepath=str(Path(args.blend).resolve()))
        lightfade_addon.register()
        scene = bpy.context.scene
        _camera(scene)
    else:
        scene = build(args.size)
        api.bake(scene, quality="CUSTOM", samples=16)
        api.age_scene(scene, years=args.years)
    copies = aged_copies(scene)
    if not copies:
        raise SystemExit("no aged materials in the scene: press Age first")
    res, Y = tuple(args.res), args.years
    mtexel, rate = image_rate(scene, Y)
    print(f"{len(copies)} aged materials, {mtexel:.1f} Mtexel of frame images")
    print("images, s per Mtexel (target <= 0.1): " + ", ".join(
        f"{k} {v:.3f}" for k, v in rate.items()))

    def pair(name, fn):
        runs = [fn(f"{name}{k}") for k in range(2)]
        return min(r[0] for r in runs), runs[0][2]

    cycles = lambda n: _render(scene, "CYCLES", args.samples, res, folder, n)   # noqa: E731
    cpu, px = {}, {}
    api.set_years(scene, ORIGINAL_YEARS)         # the original colours, in the frame images
    cpu["zero"], _px = pair("zero", cycles)
    firsts = []
    for k, y in enumerate((Y * 0.8, Y)):          # each a years value the images have not met
        api.set_years(scene, y)
        firsts.append(cycles(f"first{k}")[0])
    cpu["first"] = min(firsts)
    cpu["frames"], px["frames"] = pair("frames", cycles)
    steps = []
    for k in range(2):                           # a time-lapse: 0.1 year a frame
        api.set_years(scene, Y + 0.1 * (k + 1))
        steps.append(cycles(f"step{k}")[0])
    cpu["step"] = min(steps)
    api.set_years(scene, Y)
    cpu["live"], px["live"] = _live_only(lambda: pair("live", cycles))
    scene.cycles.seed = 1
    px["seed"] = _live_only(lambda: cycles("seed"))[2]
    scene.cycles.seed = 0
    api.apply_aging(scene, Y)                    # the aged colours as plain image textures
    cpu["applied"], _px = pair("applied", cycles)
    api.live_aging(scene)
    api.reset(scene)
    cpu["reset"], _px = pair("reset", cycles)
    r, a = cpu["reset"], cpu["applied"]
    print(f"Cycles {res[0]}x{res[1]}, {args.samples} spp, CPU s, aged at {Y:g} years; ratios "
          f"against the frame after Reset (target <= 1.15x) and against the aged colours "
          f"as image textures (Apply to Images):")
    rows = (("after Reset", "reset"),
            ("Apply to Images (image textures)", "applied"),
            ("frame images, originals (1e-4 years)", "zero"),
            ("frame images, same frame again", "frames"),
            ("frame images, first frame at new years", "first"),
            ("frame images, time-lapse step +0.1 y", "step"),
            ("live material (LightFade absent)", "live"))
    for label, key in rows:
        print(f"  {label:40s} {cpu[key]:7.2f} s: {cpu[key] / r:.2f}x Reset, "
              f"{cpu[key] / a:.2f}x Apply")
    for name, label in (("frames", "frame images vs live"), ("seed", "live, another seed (noise)")):
        d = block_dE(px[name], px["live"])
        print(f"  {label:27s}: dE00 of 8x8 means p50 {np.median(d):.2f}, "
              f"p99 {np.percentile(d, 99):.2f}, max {d.max():.2f}")
    if args.eevee:
        engine = _eevee()
        eevee = lambda n: _render(scene, engine, 4, res, folder, n)[1]   # noqa: E731
        start, after_reset = eevee("e_start"), eevee("e_reset")
        api.age_scene(scene, years=Y)
        aged, again = eevee("e_aged"), eevee("e_again")
        n = len(aged_copies(scene))
        print(f"EEVEE (wall s): after Reset first {start:.1f} (engine start), then "
              f"{after_reset:.1f}; aged first {aged:.1f}, then {again:.1f} "
              f"({again / after_reset:.2f}x Reset; target <= 1.15x): "
              f"+{max(aged - again, 0.0) / n:.2f} s of compile per aged material (target <= ~1 s)")


if __name__ == "__main__":
    main()
