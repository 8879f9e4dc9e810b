"""The colour-cube aging table against ``age-image --exact`` on real photographs.

    ./run py -m benchmarks.colour_table                   # the default table
    ./run py -m benchmarks.colour_table --side 25 --per-decade 8 --size 160
    ./run py -m benchmarks.colour_table --photos DIR      # also every .png/.jpg in DIR
    ./run py -m benchmarks.colour_table --unmix-side 33 --substeps 1   # coarser tables

Each photograph (found on this machine: matplotlib's Grace Hopper, colour-science's
TM-30 background, Blender's bundled HDRIs tone-mapped to 8 bits, scikit-image's
astronaut, coffee and chelsea where scikit-image is installed or its ``skimage/data``
folder is given with ``--photos``, and any other pictures given so) is a Printed Paper
poster on a sunlit plane, the same dose everywhere: about 1 Mlx·h a year (300 lux,
8.9 h a day, daylight: issue 27's poster) and ten times that (3000 lux, a poster in
direct sun most of the day). It is aged by the colour table (:mod:`lightfade_addon.core.
colourtable`, what the node group and ``api.apply_aging`` evaluate) and by
:func:`age_image_exact` at 5 and 25 years; printed: ΔE00 p99 / max per photo and the
table's build time and size beside them.
"""

from __future__ import annotations

import argparse
import glob
import os
import time

import numpy as np

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
    srgb_encode,
)
from lightfade_addon.core.aging.colourtable import evaluate
from lightfade_addon.core.aging.tablebuild import TableSettings, build_table
from lightfade_addon.core.fading.exact import age_image_exact
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.fading.lights import Light
from lightfade_addon.core.fading.recipes import get_recipe

LIGHT = Light("daylight", False, 300.0, 8.9, 365.0)           # 0.97 Mlx·h a year
#: The posters' lights: issue 27's, and ten times its dose.
LIGHTS = (LIGHT, Light("daylight", False, 3000.0, 8.9, 365.0))
YEARS = (5.0, 25.0)


def _site():
    import matplotlib
    return os.path.dirname(os.path.dirname(matplotlib.__file__))


def photos(extra=None):
    """{name: path} of real photographs on this machine (and in the folder ``extra``)."""
    site = _site()
    found = {
        "grace-hopper": os.path.join(site, "matplotlib/mpl-data/sample_data/grace_hopper.jpg"),
        "tm30-background": os.path.join(site, "colour/plotting/tm3018/resources/CVG_Background.jpg"),
    }
    for hdri in ("forest", "sunset", "city"):
        hits = glob.glob(os.path.join(site, f"bpy/*/datafiles/studiolights/world/{hdri}.exr"))
        if hits:
            found[f"hdri-{hdri}"] = hits[0]
    skimage = os.path.join(site, "skimage", "data")
    for folder in (skimage, extra):
        if folder and os.path.isdir(folder):
            for name in ("astronaut", "coffee", "chelsea") if folder == skimage else ():
                found[name] = os.path.join(folder, f"{name}.png")
            if folder == extra:
                for path in sorted(glob.glob(os.path.join(folder, "*"))):
                    if path.lower().endswith((".png", ".jpg", ".jpeg")):
                        found[os.path.splitext(os.path.basename(path))[0]] = path
    return {k: v for k, v in found.items() if os.path.isfile(v)}


def load(path, size):
    """Encoded sRGB (H, W, 3) float32, 8-bit levels, the longer side ``size``."""
    from lightfade_addon.images import read_image
    rgb, _alpha, info = read_image(path)
    rgb = np.asarray(rgb, dtype=np.float32)[..., :3]
    if path.endswith(".exr"):                      # scene-referred: expose, then encode
        rgb = rgb / np.percentile(rgb.mean(-1), 97)
        rgb = srgb_encode(np.clip(rgb, 0, 1))
    step = max(1, int(np.ceil(max(rgb.shape[:2]) / size)))
    rgb = rgb[::step, ::step]
    return (np.rint(np.clip(rgb, 0, 1) * 255) / 255).astype(np.float32)


def dE(a, b):
    def lab(x):
        return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.clip(x, 0, 1).reshape(-1, 3))))
    return delta_E_2000(lab(a), lab(b))


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("--side", type=int, default=TableSettings.side)
    p.add_argument("--gamma", type=float, default=TableSettings.gamma)
    p.add_argument("--per-decade", type=int, default=TableSettings.per_decade)
    p.add_argument("--points", type=int, default=TableSettings().grid.points)
    p.add_argument("--size", type=int, default=128, help="longer side of each photo (px)")
    p.add_argument("--recipe", default="printed-paper")
    p.add_argument("--photos", help="a folder of more photographs (.png, .jpg)")
    p.add_argument("--substeps", type=int, default=TableSettings.substeps)
    p.add_argument("--unmix-side", type=int, default=TableSettings.unmix_side)
    p.add_argument("--power", type=float, default=TableSettings.power)
    a = p.parse_args(argv)
    recipe = get_recipe(a.recipe)
    settings = TableSettings(side=a.side, gamma=a.gamma, per_decade=a.per_decade,
                             grid=GridSettings(points=a.points), substeps=a.substeps,
                             unmix_side=a.unmix_side, power=a.power)
    t0 = time.perf_counter()
    table = build_table(recipe, [(LIGHT.spectrum, LIGHT.uv_filter)], settings)   # any dose
    built = time.perf_counter() - t0
    print(f"table {a.recipe}: side {table.side} (unmixing {table.unmix_side}), gamma "
          f"{table.gamma:g}, power {table.power:g}, {table.T} dose nodes "
          f"(to {table.max_dose:.3g} lux·h), {table.values.nbytes / 1e6:.2f} MB half; "
          f"built in {built:.1f} s")
    worst = 0.0, 0.0
    print(f"{'photo':18s} {'size':>9s} {'colours':>8s}  " + "  ".join(
        f"{light.annual_dose / 1e6:.2g} Mlx·h/yr, {y:g} y" for light in LIGHTS for y in YEARS))
    for name, path in photos(a.photos).items():
        enc = load(path, a.size)
        lin = srgb_decode(enc).reshape(-1, 3).astype(np.float32)
        cells = []
        for light in LIGHTS:
            rate = np.full((1, lin.shape[0]), light.annual_dose, dtype=np.float32)
            exact = age_image_exact(enc, list(YEARS), recipe, light, encoding="srgb")
            for y, ref in zip(YEARS, exact):
                ours = srgb_encode(evaluate(table, lin, rate, y))
                d = dE(ours, ref)
                p99, mx = float(np.percentile(d, 99)), float(d.max())
                worst = max(worst[0], p99), max(worst[1], mx)
                cells.append(f"{p99:6.2f} / {mx:5.2f}")
        colours = len(np.unique((enc * 255).astype(np.uint8).reshape(-1, 3), axis=0))
        print(f"{name:18s} {enc.shape[1]:4d}x{enc.shape[0]:<4d} {colours:8d}  " + "   ".join(cells))
    print(f"worst p99 {worst[0]:.2f} (target 0.6), worst max {worst[1]:.2f} (target 1.5)")


if __name__ == "__main__":
    main()
