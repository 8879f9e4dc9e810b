"""What the exposure bake leaves out: the colour of bounced light (docs/img/bounce_colour.png).

    python tools/bounce_colour.py

The bake measures each texel's dose photometrically (the luminance of the baked
irradiance, docs/bake.md) and ages it with the light group's own spectrum.  Light that
reached the texel off a coloured surface has that surface's colour: window daylight off a
green sofa is greenish.  This tool measures what that costs: each recipe's colourants
are faded by the same dose (lux·h) of window daylight, straight and after one bounce off
the ColorChecker's red, green, blue and yellow patches (colour-science's spectral
reflectances, each spectrum scaled back to 1 lux), and the visible fade (CIEDE2000 from
new) is compared.  Printed: the fade under each bounce relative to straight daylight;
plotted: the same as bars.
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from figures import pyplot, save  # noqa: E402  (tools/figures.py)

from lightfade_addon.core.colour.colorimetry import delta_E_2000, reflectance_to_Lab  # noqa: E402
from lightfade_addon.core.fading.recipes import get_recipe  # noqa: E402
from lightfade_addon.core.fading.spectra import (
    WAVELENGTHS,
    illuminance,
    light_spectrum,
    resample,
)  # noqa: E402

#: ColorChecker patches the light bounces off (names as colour-science spells them).
SURFACES = {"red": "red", "green": "green", "blue": "blue", "yellow": "yellow"}
#: Colourant mixtures per recipe (unmixed concentrations) and the dose, lux·h, at which
#: straight daylight gives a clearly visible fade.
CASES = {
    "printed-paper": ({"cyan": [0.6, 0, 0], "magenta": [0, 0.6, 0], "yellow": [0, 0, 0.6]}, 2e6),
    "dyed-fabric": ({"cyan": [0.6, 0, 0], "magenta": [0, 0.6, 0], "yellow": [0, 0, 0.6]}, 20e6),
}


def bounced(light, surface):
    """``light`` (1 lux) after one bounce off a ColorChecker patch, scaled to 1 lux."""
    import colour

    checker = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"][surface]
    r = resample(checker.wavelengths, checker.values, WAVELENGTHS, outside="edge")
    e = light * r
    return e / illuminance(e)


def fade(recipe, unmixed, spectrum, dose):
    """CIEDE2000 from new after ``dose`` lux·h of ``spectrum`` (1 lux)."""
    c = recipe.concentrations([unmixed])
    r = recipe.simulate(c, spectrum, dose)
    return float(delta_E_2000(reflectance_to_Lab(r.initial, WAVELENGTHS),
                              reflectance_to_Lab(r.reflectance, WAVELENGTHS))[0])


def table():
    """{(recipe, colourant): {surface: fade relative to straight daylight}}."""
    daylight = light_spectrum("daylight-glass")
    out = {}
    for name, (mixtures, dose) in CASES.items():
        recipe = get_recipe(name)
        for colourant, unmixed in mixtures.items():
            straight = fade(recipe, unmixed, daylight, dose)
            out[(name, colourant)] = {"straight ΔE00": straight, **{
                s: fade(recipe, unmixed, bounced(daylight, patch), dose) / straight
                for s, patch in SURFACES.items()}}
    return out


def main():
    plt = pyplot()
    rows = table()
    print("| recipe | colourant | straight daylight ΔE00 | " +
          " | ".join(f"off {s}" for s in SURFACES) + " |")
    print("|---|---|---:|" + "---:|" * len(SURFACES))
    for (name, colourant), r in rows.items():
        print(f"| {name} | {colourant} | {r['straight ΔE00']:.1f} | " +
              " | ".join(f"{r[s]:.2f}×" for s in SURFACES) + " |")
    fig, ax = plt.subplots(figsize=(9, 3.6))
    labels = [f"{n}\n{c}" for n, c in rows]
    x = np.arange(len(rows))
    width = 0.8 / len(SURFACES)
    for k, surface in enumerate(SURFACES):
        ax.bar(x + (k - (len(SURFACES) - 1) / 2) * width, [r[surface] for r in rows.values()],
               width, color=f"tab:{surface}" if surface != "yellow" else "gold", label=f"off {surface}")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xticks(x, labels, fontsize=8)
    ax.set_ylabel("fade ÷ fade under straight daylight")
    ax.set_title("Same lux·h, light bounced off a coloured surface: what luminance-only doses leave out")
    ax.legend(fontsize=8, ncol=4)
    save(fig, "bounce_colour.png")


if __name__ == "__main__":
    main()
