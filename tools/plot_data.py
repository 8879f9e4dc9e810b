"""Plot LightFade's bundled spectral data for docs/data.md.

Run from the repository root::

    .venv/bin/python tools/plot_data.py

Writes docs/img/data_colourants.png (K and S of every bundled colourant),
docs/img/data_substrates.png (substrate reflectances) and docs/img/data_lights.png
(the 1-lux light presets, with and without the UV filter).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lightfade_addon.core.fading.colourants import available, load_colourant, load_substrate  # noqa: E402
from lightfade_addon.core.fading.spectra import LIGHTS, light_spectrum  # noqa: E402

OUT = ROOT / "docs" / "img"
COLOURS = {
    "cyan": "#00a0c8", "magenta": "#c8007a", "yellow": "#d8b400",
    "lignin": "#7a6a50", "quinone": "#b06010",
    "paper": "#888888", "fabric": "#b09060", "wood": "#a0682a", "white-ground": "#303030",
    "daylight": "#3060c0", "daylight-glass": "#30a0a0", "incandescent": "#d04010",
    "fluorescent": "#60a030", "led": "#a040c0",
}


def shade_uv(ax):
    ax.axvspan(300, 380, color="#ece6f6", zorder=0)
    ax.text(302, 0.97, "UV", transform=ax.get_xaxis_transform(), va="top", fontsize=8,
            color="#6a5a8a")


def plot_colourants(path):
    fig, (ax_dye, ax_yel, ax_s) = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
    for name in available("colourant"):
        c = load_colourant(name, wavelengths=None)
        ax = ax_dye if name in ("cyan", "magenta", "yellow") else ax_yel
        ax.plot(c.wavelengths, c.K, color=COLOURS.get(name), label=name)
        ax_s.plot(c.wavelengths, c.S, color=COLOURS.get(name), label=name)
    ax_dye.set_title("Absorption K: printing dyes")
    ax_yel.set_title("Absorption K: yellowing (lignin -> quinone)")
    ax_yel.set_yscale("log")
    ax_yel.set_ylim(1e-3, 50)
    ax_s.set_title("Scattering S (all colourants)")
    for ax in (ax_dye, ax_yel, ax_s):
        shade_uv(ax)
        ax.set_xlim(300, 780)
        ax.set_xlabel("wavelength (nm)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    ax_dye.set_ylabel("per unit thickness, concentration 1")
    fig.suptitle("Bundled colourants (parametric, not measured; tools/fit_colourants.py)",
                 fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_substrates(path):
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    for name in available("substrate"):
        s = load_substrate(name, wavelengths=None)
        ax.plot(s.wavelengths, s.reflectance, color=COLOURS.get(name), label=name)
    shade_uv(ax)
    ax.set_xlim(300, 780)
    ax.set_ylim(0, 1)
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("diffuse reflectance")
    ax.set_title("Bundled substrates (parametric, not measured)", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_lights(path):
    lam = np.arange(300.0, 781.0)
    fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    for name in LIGHTS:
        E = light_spectrum(name, lam)
        ax.plot(lam, E * 1e6, color=COLOURS[name], lw=1.2, label=name)
    E = light_spectrum("daylight", lam, uv_filter=True)
    ax.plot(lam, E * 1e6, color=COLOURS["daylight"], ls="--", lw=1.0,
            label="daylight + UV filter")
    shade_uv(ax)
    ax.set_xlim(300, 780)
    ax.set_ylim(0, None)
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("spectral irradiance at 1 lux (µW m⁻² nm⁻¹)")
    ax.set_title("Light presets normalised to 1 lux (1 nm resolution)", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    plot_colourants(OUT / "data_colourants.png")
    plot_substrates(OUT / "data_substrates.png")
    plot_lights(OUT / "data_lights.png")
    print(f"wrote data_colourants.png, data_substrates.png, data_lights.png to {OUT}")


if __name__ == "__main__":
    main()
