"""How often the gamut rule acts: the demo textures aged at 0, 50 and 500 years.

    python -m benchmarks.gamut

Each procedural demo texture (``scenes/textures.py``) is aged with the recipe the
demo gives it, under window daylight at 3000 lux, 8 h a day, and the share of
texels whose modelled aged colour left [0, 1] in linear sRGB (and which
:func:`lightfade_addon.core.gamut.into_gamut` maps back, keeping hue) is printed.
"""

from __future__ import annotations

import numpy as np

from lightfade_addon.core.aging import Light, TextureAger
from scenes import textures

YEARS = (0.0, 50.0, 500.0)
LIGHT = Light("daylight-glass", lux=3000)
SIZE = (256, 256)


def demo_textures():
    """(name, recipe, encoded sRGB image) of the demo scenes' textures."""
    return [
        ("floor planks", "bare-wood", textures.wood_planks(SIZE)),
        ("painted wood", "painted-wood", textures.painted_wood(SIZE, (0.55, 0.2, 0.15))),
        ("rug", "dyed-fabric", textures.rug(SIZE)),
        ("fabric", "dyed-fabric", textures.fabric(SIZE, (0.2, 0.35, 0.6))),
        ("poster", "printed-paper", textures.poster(SIZE)),
        ("colour chart", "printed-paper", textures.colour_chart(SIZE)),
    ]


def main():
    print("| texture | recipe | " + " | ".join(f"{y:g} y" for y in YEARS) + " |")
    print("|---|---|" + "---:|" * len(YEARS))
    total = np.zeros(len(YEARS))
    count = 0
    for name, recipe, img in demo_textures():
        ager = TextureAger(np.asarray(img, np.float32), recipe, [LIGHT], encoding="srgb",
                           max_years=max(YEARS))
        shares = [ager.out_of_range(y).mean() for y in YEARS]
        for y in YEARS:
            aged = ager.age(y)
            assert np.all(np.isfinite(aged)) and aged.min() >= 0 and aged.max() <= 1
        total += np.array(shares) * img[..., 0].size
        count += img[..., 0].size
        print(f"| {name} | {recipe} | " + " | ".join(f"{100 * s:.2f} %" for s in shares) + " |")
    print("| all | | " + " | ".join(f"{100 * s:.2f} %" for s in total / count) + " |")


if __name__ == "__main__":
    main()
