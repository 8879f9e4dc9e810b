"""Figures 6 and 7 of the paper, redone with LightFade on a generated photograph.

* ``docs/img/figure7.png`` (paper, Figure 7): the photograph, faded by the reference
  path (:func:`lightfade_addon.core.aging.ager.age_image_exact`: one direct simulation per
  distinct colour, "without selective interpolation") and through the mixture grid
  (:class:`lightfade_addon.core.aging.ager.TextureAger`), side by side, with a CIEDE2000
  map of grid vs reference.
* ``docs/img/figure6.png`` (paper, Figure 6): the photograph faded over progressively
  longer times (the reference path).

No photograph is downloaded: :func:`make_photo` paints one (sky, sun, hills, a red
barn, flowers, fine grain) so the figures are reproducible anywhere. Prints the
timings of both paths and the ΔE00 statistics.

Usage::

    .venv/bin/python tools/figure7.py [--years 50] [--out docs/img]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lightfade_addon.core.aging.ager import Light, TextureAger, age_image_exact  # noqa: E402
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)

SEQUENCE = (0, 10, 25, 50, 100)
RECIPE = "printed-paper"
LIGHT = Light("daylight-glass", lux=150.0, hours_per_day=8.0, days_per_year=365.0)


def _smooth_noise(rng, h, w, cell):
    """Value noise: random values on a coarse lattice, bilinearly interpolated."""
    gh, gw = h // cell + 2, w // cell + 2
    g = rng.random((gh, gw))
    y = np.arange(h) / cell
    x = np.arange(w) / cell
    y0, x0 = y.astype(int), x.astype(int)
    fy, fx = (y - y0)[:, None], (x - x0)[None, :]
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)
    a = g[y0][:, x0] * (1 - fx) + g[y0][:, x0 + 1] * fx
    b = g[y0 + 1][:, x0] * (1 - fx) + g[y0 + 1][:, x0 + 1] * fx
    return a * (1 - fy) + b * fy


def make_photo(width=384, height=256, seed=7):
    """A colourful landscape "photograph": encoded sRGB in [0, 1], 8-bit levels.

    Sky gradient with a sun disc and glow, two ranges of hills, a red barn, a field
    of saturated flowers (magenta, red, yellow, violet, orange) and film-like grain.
    """
    rng = np.random.default_rng(seed)
    h, w = height, width
    y, x = np.mgrid[0:h, 0:w].astype(float)
    v, u = y / (h - 1), x / (w - 1)
    # sky: deep blue at the top to a warm pale horizon
    t = np.clip(v / 0.55, 0, 1)[..., None]
    img = (1 - t) * np.array([0.10, 0.32, 0.72]) + t * np.array([0.98, 0.80, 0.55])
    # sun with a glow
    r = np.hypot(x - 0.72 * w, y - 0.30 * h)
    glow = np.exp(-(r / (0.12 * h)) ** 2)[..., None]
    img = img + glow * 0.35 * np.array([1.0, 0.75, 0.35])
    img[r < 0.075 * h] = (1.0, 0.93, 0.55)
    # clouds
    clouds = _smooth_noise(rng, h, w, 24)
    c = np.clip((clouds - 0.6) * 3, 0, 1)[..., None] * (v < 0.45)[..., None]
    img = img * (1 - 0.6 * c) + 0.6 * c * np.array([0.97, 0.95, 0.96])
    # far hills (blue-green) and near hills (greens), with texture
    ridge1 = 0.50 * h + 0.06 * h * np.sin(u * 7.0 + 1.0) + 0.03 * h * np.sin(u * 17.0)
    ridge2 = 0.64 * h + 0.08 * h * np.sin(u * 4.0 + 2.5) + 0.02 * h * np.sin(u * 23.0)
    tex = _smooth_noise(rng, h, w, 6)[..., None]
    far = y > ridge1
    img[far] = (np.array([0.30, 0.48, 0.45]) * (0.85 + 0.3 * tex))[far]
    near = y > ridge2
    shade = ((y - ridge2) / (0.36 * h)).clip(0, 1)[..., None]
    greens = (1 - shade) * np.array([0.45, 0.70, 0.20]) + shade * np.array([0.12, 0.40, 0.10])
    img[near] = (greens * (0.8 + 0.4 * tex))[near]
    # a red barn with a dark roof and a white door
    bx0, bx1, by1 = int(0.16 * w), int(0.30 * w), int(0.70 * h)
    by0 = int(0.58 * h)
    img[by0:by1, bx0:bx1] = (0.72, 0.10, 0.08)
    for k in range(int(0.06 * h)):                       # roof triangle
        img[by0 - k, bx0 + k:bx1 - k] = (0.25, 0.18, 0.16)
    img[by0 + 8:by1, (bx0 + bx1) // 2 - 6:(bx0 + bx1) // 2 + 6] = (0.92, 0.90, 0.86)
    # flowers in the foreground field
    colours = np.array([(0.90, 0.10, 0.55), (0.85, 0.08, 0.10), (0.98, 0.85, 0.10),
                        (0.50, 0.20, 0.75), (1.00, 0.50, 0.05), (0.95, 0.45, 0.70)])
    for _ in range(70):
        cy = rng.uniform(0.72, 0.98) * h
        cx = rng.uniform(0.0, 1.0) * w
        size = 2.0 + 5.0 * (cy / h - 0.70) / 0.28
        col = colours[rng.integers(len(colours))]
        d = np.hypot(x - cx, y - cy)
        ang = np.arctan2(y - cy, x - cx)
        petals = d < size * (0.75 + 0.25 * np.cos(5 * ang + rng.uniform(0, 6.3)))
        img[petals] = col * rng.uniform(0.85, 1.05)
        img[d < 0.3 * size] = (0.95, 0.80, 0.15)
    # grain
    img = img + rng.normal(0, 0.012, img.shape)
    img = img + 0.03 * (_smooth_noise(rng, h, w, 3)[..., None] - 0.5)
    return (np.rint(np.clip(img, 0, 1) * 255) / 255).astype(np.float32)


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(rgb)))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--years", type=float, default=50.0, help="years for Figure 7 (default 50)")
    p.add_argument("--out", default=str(ROOT / "docs" / "img"), help="output folder")
    args = p.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    photo = make_photo()
    h, w, _ = photo.shape
    codes = np.rint(photo.reshape(-1, 3) * 255).astype(np.int64) @ [65536, 256, 1]
    n_colours = np.unique(codes).size
    simulated = np.unique(photo.reshape(-1, 3), axis=0).shape[0]    # as age_image_exact
    years = sorted(set(SEQUENCE) | {args.years})
    print(f"photograph: {w}×{h}, {n_colours} distinct colours; recipe {RECIPE}, "
          f"{LIGHT.spectrum}, {LIGHT.lux:g} lux × {LIGHT.hours_per_day:g} h/day × "
          f"{LIGHT.days_per_year:g} days/year = {LIGHT.annual_dose / 1e6:.3f} Mlx·h/year")

    t0 = time.perf_counter()
    exact = age_image_exact(photo, years, RECIPE, LIGHT, encoding="srgb")
    t_exact = time.perf_counter() - t0
    exact = dict(zip(years, exact))

    t0 = time.perf_counter()
    ager = TextureAger(photo, RECIPE, [LIGHT], max_years=max(years), encoding="srgb", cache=False)
    t_prepare = time.perf_counter() - t0
    t0 = time.perf_counter()
    grid = {y: ager.age(y) for y in years}
    t_age = (time.perf_counter() - t0) / len(years)
    g = ager.grid
    print(f"exact (reference): {t_exact:.1f} s for {len(years)} ages "
          f"({simulated} colours simulated: the core bins more than 65536 distinct "
          f"colours by dropping low bits)")
    print(f"grid: {t_prepare:.1f} s to build and prepare "
          f"({g.change.shape[2:-1]} concentrations × {g.change.shape[1]} doses), "
          f"then {t_age * 1e3:.1f} ms per image")

    stats = {}
    for y in years:
        if y == 0:
            continue
        dE = delta_E_2000(lab(grid[y]), lab(exact[y]))
        fade = delta_E_2000(lab(photo), lab(exact[y]))
        stats[y] = dE
        print(f"{y:g} y ({y * LIGHT.annual_dose / 1e6:.2f} Mlx·h): fade ΔE00 mean "
              f"{fade.mean():.2f} (max {fade.max():.2f}); grid vs exact ΔE00 mean "
              f"{dE.mean():.3f}, 99th percentile {np.percentile(dE, 99):.3f}, max {dE.max():.3f}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # -- Figure 7 ------------------------------------------------------------------
    y7 = args.years
    dE = stats[y7]
    fig, axes = plt.subplots(1, 4, figsize=(15.5, 3.4),
                             gridspec_kw=dict(width_ratios=[1, 1, 1, 1.22]))
    panels = [(photo, "original"),
              (exact[y7], f"reference (exact), {y7:g} y\n{t_exact:.1f} s"),
              (grid[y7], f"grid, {y7:g} y\n{t_prepare:.1f} s once, then {t_age * 1e3:.0f} ms")]
    for ax, (img, title) in zip(axes, panels):
        ax.imshow(np.clip(img, 0, 1), interpolation="nearest")
        ax.set_title(title, fontsize=10)
        ax.axis("off")
    vmax = max(1.0, float(np.percentile(dE, 99.9)))
    im = axes[3].imshow(dE, cmap="magma", vmin=0, vmax=vmax, interpolation="nearest")
    axes[3].set_title("ΔE00, grid vs exact", fontsize=10)
    axes[3].axis("off")
    axes[3].text(0.02, 0.03, f"max {dE.max():.2f}\n99th pct {np.percentile(dE, 99):.2f}\n"
                             f"mean {dE.mean():.3f}",
                 transform=axes[3].transAxes, color="white", fontsize=9, va="bottom",
                 bbox=dict(facecolor="black", alpha=0.5, edgecolor="none"))
    fig.colorbar(im, ax=axes[3], fraction=0.046, pad=0.03, label="ΔE00")
    fig.suptitle(f"{RECIPE}, {LIGHT.spectrum}, {LIGHT.lux:g} lux × {LIGHT.hours_per_day:g} h/day: "
                 f"{y7:g} years = {y7 * LIGHT.annual_dose / 1e6:.1f} Mlx·h "
                 f"(generated photograph, {w}×{h})", fontsize=11)
    fig.tight_layout()
    fig.savefig(out / "figure7.png", dpi=110)
    plt.close(fig)

    # -- Figure 6 ------------------------------------------------------------------
    fig, axes = plt.subplots(1, len(SEQUENCE), figsize=(3.1 * len(SEQUENCE), 2.6))
    for ax, y in zip(axes, SEQUENCE):
        ax.imshow(np.clip(exact[y], 0, 1), interpolation="nearest")
        ax.set_title(f"{y:g} y  ({y * LIGHT.annual_dose / 1e6:.1f} Mlx·h)", fontsize=10)
        ax.axis("off")
    fig.suptitle(f"reference fading, {RECIPE} under {LIGHT.spectrum} at {LIGHT.lux:g} lux, "
                 f"{LIGHT.hours_per_day:g} h/day", fontsize=11)
    fig.tight_layout()
    fig.savefig(out / "figure6.png", dpi=110)
    plt.close(fig)
    print(f"wrote {out / 'figure7.png'} and {out / 'figure6.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
