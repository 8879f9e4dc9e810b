"""Frame images at the camera's detail against the live material: a figure.

    ./run py tools/frame_detail_figure.py docs/img/frame_detail.png
    ./run py tools/frame_detail_figure.py out/detail.png --blend out/ten.blend --samples 64

The room of :mod:`benchmarks.live_room` (ten 1k image materials, a sun and an
incandescent lamp; without ``--blend`` built, baked at 16 samples and aged at 25 years)
rendered in Cycles at 240 × 135, where one render pixel covers several texels of each
texture: the live material (the aging group, what renders without LightFade), the frame
images whole (``Frame Detail: Full``) and at the camera's detail (the default), and the
ΔE00 between the 8 × 8-pixel means of the last and the live render, beside the same
figure for two seeds of the live render (the noise). Each tile is enlarged three times.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)

from benchmarks.frame_cost import _live_only, _render  # noqa: E402
from benchmarks.live_room import block_dE, build  # noqa: E402

RES = (240, 135)
#: ΔE00 shown white in the maps.
DE_WHITE = 2.0


def aged_room(blend, years):
    import lightfade_addon
    from lightfade_addon import api

    if blend is not None:
        bpy.ops.wm.open_mainfile(filepath=str(pathlib.Path(blend).resolve()))
        lightfade_addon.register()
        scene = bpy.context.scene
    else:
        scene = build(1024)
        api.bake(scene, quality="CUSTOM", samples=16)
        api.age_scene(scene, years=years)
    api.set_years(scene, years)
    return scene


def renders(scene, samples, folder):
    """{name: ((H, W, 4) linear pixels, Mtexel of frame images)} of the four renders."""
    from lightfade_addon.blender.aging import frames

    def one(name, detail=None, seed=0, live=False):
        scene.cycles.seed = seed
        if detail is not None:
            scene.lightfade.frame_detail = detail
        if live:
            return _live_only(lambda: _render(scene, "CYCLES", samples, RES, folder, name))[2], 0.0
        px = _render(scene, "CYCLES", samples, RES, folder, name)[2]
        return px, sum(frames.texels_aged(c) for c, _m in frames.switches(scene)) / 1e6

    out = {"live": one("live", live=True), "live, seed 1": one("live1", seed=1, live=True),
           "full": one("full", "FULL"), "camera": one("camera", "CAMERA")}
    scene.cycles.seed = 0
    return out


def tile(px, scale):
    """An enlarged 8-bit sRGB tile (PIL) of linear pixels ``px`` (bottom row first)."""
    from PIL import Image

    from lightfade_addon.core.colour.srgb8 import encode_srgb_f32

    rgb = np.clip(px[::-1, :, :3] * scale, 0.0, 1.0)
    image = Image.fromarray((encode_srgb_f32(rgb) * 255 + 0.5).astype(np.uint8))
    return image.resize((image.width * 3, image.height * 3), Image.NEAREST)


def de_tile(a, b):
    """The ΔE00 of 8 × 8-pixel means (white: :data:`DE_WHITE`), as a tile; and the map."""
    from PIL import Image

    H, W = a.shape[0] // 8, a.shape[1] // 8
    de = block_dE(a, b).reshape(H, W)
    grey = (np.clip(de[::-1] / DE_WHITE, 0, 1) * 255 + 0.5).astype(np.uint8)
    image = Image.fromarray(grey).resize((W * 8 * 3, H * 8 * 3), Image.NEAREST).convert("RGB")
    return image, de


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output", type=pathlib.Path)
    ap.add_argument("--blend", type=pathlib.Path, help="the ten-material room, aged (.blend)")
    ap.add_argument("--years", type=float, default=25.0)
    ap.add_argument("--samples", type=int, default=128)
    args = ap.parse_args(argv)
    from lightfade_addon.contact_sheet import contact_sheet

    scene = aged_room(args.blend, args.years)
    with tempfile.TemporaryDirectory(prefix="lf_detail_") as folder:
        r = renders(scene, args.samples, folder)
    live = r["live"][0]
    scale = 1.0 / max(float(np.percentile(live[..., :3], 99)), 1e-6)
    diff, de = de_tile(r["camera"][0], live)
    noise, de_noise = de_tile(r["live, seed 1"][0], live)
    tiles = [tile(live, scale), tile(r["full"][0], scale), tile(r["camera"][0], scale), diff, noise]
    labels = ["live material", "frame images, whole", "frame images, camera's detail",
              "dE00: camera's detail vs live", "dE00: live, two seeds (the noise)"]
    stats = lambda d: f"8x8-pixel means p99 {np.percentile(d, 99):.2f}, max {d.max():.2f} (white {DE_WHITE:g})"  # noqa: E731
    sub = ["the aging group (no LightFade)", f"{r['full'][1]:.1f} Mtexel aged per years value",
           f"{r['camera'][1]:.1f} Mtexel aged per years value", stats(de), stats(de_noise)]
    title = (f"Ten 1k materials at {args.years:g} years, Cycles {RES[0]} x {RES[1]}, "
             f"{args.samples} spp, enlarged 3x")
    args.output.parent.mkdir(parents=True, exist_ok=True)
    contact_sheet(tiles, labels, sub, title=title, columns=3).save(args.output)
    print("wrote", args.output)


if __name__ == "__main__":
    main()
