"""How a real texture fades under a recipe: the issue-25 sofa criteria on a whole texture.

    python tools/texture_fade_check.py TEXTURE [--recipe dyed-fabric] [--years 20]
        [--doses 1 3 10]

Ages every texel of TEXTURE (any image, e.g. a Poly Haven base-colour map; nothing is
written) with the core (:class:`lightfade_addon.core.aging.ager.TextureAger`, as
``age-image``) under daylight through window glass, at a uniform annual dose per run
(Mlx·h a year: a sofa's most-exposed quarter near a window gets a few), and prints for
the aged texture: near-neutral texels (C*ab < 10 when new) — median and 95th percentile
chroma gain; the others — median hue turn; the share of texels that are cyan-teal
(hue 160-250°, C*ab > 8) before and after; the median ΔL*. Issue 25's limits: neutral
gain <= 6, median turn <= 30°, at most 10 points more cyan-teal, and it lightens.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lightfade_addon.core.aging.ager import Light, TextureAger  # noqa: E402
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    linear_srgb_to_XYZ,
    srgb_decode,
)


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(rgb, float).reshape(-1, 3))))


def teal(L):
    """Texels whose hue is cyan to teal (160-250°) with visible chroma."""
    h = np.degrees(np.arctan2(L[:, 2], L[:, 1])) % 360
    return (h >= 160) & (h <= 250) & (np.hypot(L[:, 1], L[:, 2]) > 8)


def report(rgb, recipe, years, annual_mlxh):
    light = Light("daylight-glass", False, annual_mlxh * 1e6 / (8 * 365), 8.0, 365.0)
    aged = TextureAger(rgb, recipe, [light], max_years=years, encoding="srgb").age(years)
    L0, L1 = lab(rgb), lab(aged)
    C0, C1 = np.hypot(L0[:, 1], L0[:, 2]), np.hypot(L1[:, 1], L1[:, 2])
    neutral = C0 < 10
    turn = np.degrees(np.abs((np.arctan2(L1[:, 2], L1[:, 1]) - np.arctan2(L0[:, 2], L0[:, 1])
                              + np.pi) % (2 * np.pi) - np.pi))
    gain = C1 - C0
    print(f"  {annual_mlxh:g} Mlx·h a year x {years:g} y: neutral {neutral.mean():.0%} of texels,"
          f" chroma gain median {np.median(gain[neutral]) if neutral.any() else 0:+.1f}, "
          f"95th pct {np.percentile(gain[neutral], 95) if neutral.any() else 0:+.1f}; others: "
          f"median hue turn {np.median(turn[~neutral]) if (~neutral).any() else 0:.1f}°; "
          f"cyan-teal {teal(L0).mean():.1%} -> {teal(L1).mean():.1%}; "
          f"median dL* {np.median(L1[:, 0] - L0[:, 0]):+.1f}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("texture")
    p.add_argument("--recipe", default="dyed-fabric")
    p.add_argument("--years", type=float, default=20.0)
    p.add_argument("--doses", type=float, nargs="+", default=[1.0, 3.0, 10.0],
                   help="annual doses, Mlx·h a year")
    p.add_argument("--size", type=int, default=256, help="texels per side read (resampled)")
    args = p.parse_args(argv)
    from PIL import Image

    img = Image.open(args.texture).convert("RGB").resize((args.size, args.size))
    rgb = np.asarray(img, np.float32) / 255.0
    print(f"{args.texture}: {args.recipe}, daylight through glass")
    for d in args.doses:
        report(rgb, args.recipe, args.years, d)


if __name__ == "__main__":
    main()
