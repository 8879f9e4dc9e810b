"""Each bundled recipe's swatches over the years (docs/img/recipe_swatches.png).

    python tools/recipe_swatches.py

Upholstery, paint and print colours and nine woods, aged with the core on the path
``age-image`` uses (:class:`lightfade_addon.core.aging.ager.TextureAger`) under daylight
through window glass at 2,000 lux for 8 h a day (5.84 Mlx·h a year, a bright spot near
a window); one row per colour, one column per age, each recipe with the years that show
its pace (paint takes about nine times the dose of fabric; wood changes most in its
first year). The same palettes as ``benchmarks/recipes.py``.
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from figures import pyplot, save  # noqa: E402  (tools/figures.py)

from benchmarks.recipes import CHROMATIC, LIGHT, NEUTRALS, WOODS  # noqa: E402
from lightfade_addon.core.aging.ager import TextureAger  # noqa: E402

#: Colours shown for the dyed, painted and printed recipes (a subset of the palettes).
COLOURS = ["black", "charcoal", "mid grey", "greige", "grey brown", "red", "burgundy",
           "rust", "mustard", "olive", "teal", "navy", "sky blue", "pink"]

PANELS = [
    ("dyed-fabric", "Dyed Fabric\n(Blue Wool 4, matched dyes)", (0, 1, 3, 10, 30)),
    ("painted-wood", "Painted Wood\n(Blue Wool 6, matched pigments)", (0, 10, 30, 100, 300)),
    ("printed-paper", "Printed Paper\n(yellow 3, magenta 3.5, cyan 5)", (0, 1, 3, 10, 30)),
    ("bare-wood", "Bare Wood (lignin yellows,\nextractives bleach)", (0, 0.5, 1, 3.77, 10)),
]


def aged_rows(recipe, colours, years):
    """(N, Y, 3) encoded sRGB of ``colours`` (sRGB 0..255) at each of ``years``."""
    rgb = (np.array(colours, float) / 255.0).reshape(1, -1, 3)
    ager = TextureAger(rgb, recipe, [LIGHT], max_years=max(years), encoding="srgb")
    return np.stack([ager.age(y).reshape(-1, 3) for y in years], axis=1)


def label(y):
    """``years`` over ``Mlx·h`` for a column."""
    if y == 0:
        return "new"
    when = f"{y:g} y" if y >= 1 else f"{12 * y:g} mo"
    dose = y * LIGHT.annual_dose / 1e6
    return f"{when}\n{dose:.0f}" if dose >= 1000 else f"{when}\n{dose:.3g}"


def main():
    plt = pyplot()
    palette = {**NEUTRALS, **CHROMATIC}
    fig, axes = plt.subplots(1, 4, figsize=(14.5, 6.6))
    for ax, (name, title, years) in zip(axes, PANELS):
        names = list(WOODS) if name == "bare-wood" else COLOURS
        colours = [WOODS[n] if name == "bare-wood" else palette[n] for n in names]
        img = aged_rows(name, colours, years)
        ax.imshow(np.repeat(np.repeat(img, 8, axis=0), 8, axis=1),
                  extent=(0, len(years), len(names), 0), interpolation="nearest")
        for k in range(1, len(names)):
            ax.axhline(k, color="white", lw=1.2)
        for k in range(1, len(years)):
            ax.axvline(k, color="white", lw=1.2)
        ax.set_xticks(np.arange(len(years)) + 0.5, [label(y) for y in years], fontsize=7)
        ax.set_yticks(np.arange(len(names)) + 0.5, names, fontsize=8)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("years / Mlx·h", fontsize=7)
        ax.tick_params(length=0)
        for spine in ax.spines.values():
            spine.set_visible(False)
    fig.suptitle("LightFade recipes under daylight through window glass, 2,000 lux × 8 h a "
                 "day (LightFade core, as age-image)", fontsize=10)
    save(fig, "recipe_swatches.png")


if __name__ == "__main__":
    main()
