"""Restore against aging on real photographs: times side by side, and what is lost.

    python -m benchmarks.restore

Photographs (no download): Grace Hopper's portrait (matplotlib's sample data) and
three of Blender's studio-light HDRIs (the bpy wheel's ``studiolights/world``),
exposed so that their 99th percentile is white, sRGB-encoded at 8 bits and halved.
Each is aged ``YEARS`` of the default light (printed paper, 150 lux window daylight,
8 h a day) by :class:`TextureAger`, written at 8 bits, and restored by
:func:`restore`; the grid is built once beforehand (both paths load it). Printed:
aging and restore wall times (best of two) and their ratio, the median and 95th
percentile ΔE00 of the restored photo to the original, the share of pixels that
restore worse than ΔE00 2 and the share flagged lost.
"""

from __future__ import annotations

import pathlib
import time

import numpy as np

from lightfade_addon.core.aging.ager import Light, TextureAger
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
    srgb_encode,
)
from lightfade_addon.core.aging.restore import restore

YEARS = 25.0
HDRIS = ("courtyard", "forest", "interior")


def lab(img):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(img, float).reshape(-1, 3))))


def photos():
    import matplotlib.cbook as cbook
    from PIL import Image

    yield "grace_hopper", np.asarray(Image.open(cbook.get_sample_data("grace_hopper.jpg"))
                                     .convert("RGB"), np.float32) / 255
    import bpy
    import OpenImageIO as oiio

    world = pathlib.Path(bpy.utils.system_resource("DATAFILES")) / "studiolights" / "world"
    for name in HDRIS:
        px = oiio.ImageBuf(str(world / f"{name}.exr")).get_pixels(oiio.FLOAT)[..., :3]
        px = np.clip(px / np.percentile(px.max(-1), 99), 0, 1)[::2, ::2]
        yield name, (np.rint(srgb_encode(px) * 255) / 255).astype(np.float32)


def best_of(n, fn):
    times, out = [], None
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    light = Light()
    TextureAger(np.full((2, 2, 3), 0.5, np.float32), "printed-paper", [light],
                encoding="srgb", max_years=YEARS)                 # the grid, once
    print("| photo | pixels | age s | restore s | ratio | median ΔE00 | p95 | > 2 | lost |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, img in photos():
        t_age, aged = best_of(2, lambda: TextureAger(
            img, "printed-paper", [light], encoding="srgb", max_years=YEARS).age(YEARS))
        aged = (np.rint(aged * 255) / 255).astype(np.float32)
        t_restore, back = best_of(2, lambda: restore(aged, YEARS, "printed-paper", [light],
                                                     encoding="srgb"))
        err = delta_E_2000(lab(img), lab(back.image))
        print(f"| {name} | {img.shape[0] * img.shape[1]} | {t_age:.2f} | {t_restore:.2f} | "
              f"{t_restore / t_age:.2f} | {np.median(err):.2f} | {np.percentile(err, 95):.2f} "
              f"| {np.mean(err > 2):.2%} | {back.lost_fraction:.2%} |", flush=True)


if __name__ == "__main__":
    main()
