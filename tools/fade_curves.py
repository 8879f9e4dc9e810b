"""Fade curves of a deep and a pale shade under both rate laws (docs/img/fade_curves.png).

    python tools/fade_curves.py

Magenta dye on paper (the printed-paper recipe, Blue Wool class 2), full tone (0.8)
and a pale tint (0.1), faded by window daylight to 20 Mlx·h, each law with its own
Blue Wool calibration: the colour difference from new (CIEDE2000) and the share of
dye left (mean over depth) against the dose.
"""

from __future__ import annotations

import dataclasses
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from figures import pyplot, save  # noqa: E402  (tools/figures.py)

from lightfade_addon.core.colour.colorimetry import delta_E_2000, reflectance_to_Lab  # noqa: E402
from lightfade_addon.core.fading.recipes import get_recipe  # noqa: E402
from lightfade_addon.core.fading.spectra import WAVELENGTHS, light_spectrum  # noqa: E402

SHADES = {"deep (0.8)": 0.8, "pale (0.1)": 0.1}
MAX_DOSE = 20e6


def curves(kinetics, level):
    recipe = dataclasses.replace(get_recipe("printed-paper").with_classes({"magenta": 2}),
                                 kinetics=kinetics)
    c = recipe.concentrations([[0.0, level, 0.0]])
    doses = np.linspace(MAX_DOSE / 40, MAX_DOSE, 40)
    r = recipe.simulate(c, light_spectrum("daylight-glass"), MAX_DOSE, record=doses)
    # the dye left: record again with the fractions at each dose
    left = [recipe.simulate(c, light_spectrum("daylight-glass"), d).fractions[0, :, 1].mean()
            / level for d in doses]
    Lab0 = reflectance_to_Lab(r.initial, WAVELENGTHS)
    dE = delta_E_2000(Lab0, reflectance_to_Lab(r.history[:, 0], WAVELENGTHS))
    return np.concatenate([[0], doses]), np.concatenate([[0], dE]), np.concatenate([[1], left])


def main():
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for kinetics, style in (("first-order", "-"), ("paper", "--")):
        for (name, level), colour in zip(SHADES.items(), ("tab:purple", "tab:pink")):
            d, dE, left = curves(kinetics, level)
            label = f"{name}, {kinetics}"
            axes[0].plot(d / 1e6, dE, style, color=colour, label=label)
            axes[1].plot(d / 1e6, left, style, color=colour, label=label)
    axes[0].set(xlabel="dose (Mlx·h, window daylight)", ylabel="CIEDE2000 from new",
                title="Magenta on paper: visible fade")
    axes[1].set(xlabel="dose (Mlx·h, window daylight)", ylabel="dye left (mean over depth)",
                title="Magenta on paper: dye left", ylim=(0, 1.02))
    axes[1].legend(fontsize=8)
    save(fig, "fade_curves.png")


if __name__ == "__main__":
    main()
