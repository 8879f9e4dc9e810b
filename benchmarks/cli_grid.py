"""``age-image`` (the grid) against ``age-image --exact`` on a photo of many colours.

    python -m benchmarks.cli_grid                 # 340² photo (77,000 colours), 4 recipes
    python -m benchmarks.cli_grid --size 128      # smaller and quicker
    python -m benchmarks.cli_grid --bits 16       # 16-bit photo and outputs: no rounding

A photo-like 8-bit PNG (:func:`benchmarks.problem.synthetic_photo`: sky, hills,
blossoms, noise) is aged by the command line under fluorescent light (150 lux, 8 h a
day, the command's defaults) for 15 years, once with the grid and once with
``--exact``, for every recipe; the written images are compared pixel by pixel
(max and 99th-percentile CIEDE2000) and each run's wall time is printed beside the
other's (ratios: timings on a shared machine are noisy).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import pathlib
import tempfile
import time

import numpy as np

from benchmarks.problem import synthetic_photo
from lightfade_addon import cli, images
from lightfade_addon.core.colour.colorimetry import (XYZ_to_Lab, delta_E_2000,
                                                     linear_srgb_to_XYZ, srgb_decode)
from lightfade_addon.core.fading.recipes import RECIPES


def lab(encoded):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(encoded, float).reshape(-1, 3))))


def age(photo, out, recipe, args):
    """Run ``age-image`` quietly; (the 15-year image, wall seconds)."""
    argv = ["age-image", str(photo), "--years", "15", "--recipe", recipe, "--out", str(out),
            *args]
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = cli.main(argv)
    wall = time.perf_counter() - t0
    if code != 0:
        raise SystemExit(f"age-image failed: {' '.join(argv)}")
    return images.read_image(out / f"{photo.stem}_15y.png")[0], wall


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=340, help="photo side, pixels")
    parser.add_argument("--light", default="fluorescent")
    parser.add_argument("--lux", default="150")
    parser.add_argument("--bits", type=int, default=8, choices=(8, 16),
                        help="of the photo and so of the outputs: 8 bits round each "
                             "output to steps of up to ΔE00 ~0.9 in near-greys")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="lightfade-cli-grid-") as d:
        folder = pathlib.Path(d)
        photo = folder / "photo.png"
        images.write_image(photo, synthetic_photo(args.size, args.size), None, args.bits)
        src = images.read_image(photo)[0]
        colours = np.unique(src.reshape(-1, 3), axis=0).shape[0]
        print(f"{args.size}² {args.bits}-bit photo, {colours} colours; {args.light}, {args.lux} lux, "
              f"8 h/day, 15 years")
        print("| recipe | max ΔE00 | p99 ΔE00 | mean fade ΔE00 | grid s | exact s |")
        for recipe in RECIPES:
            light = ["--light", args.light, "--lux", args.lux]
            grid, t_grid = age(photo, folder / f"grid-{recipe}", recipe, light)
            exact, t_exact = age(photo, folder / f"exact-{recipe}", recipe, light + ["--exact"])
            gap = delta_E_2000(lab(grid), lab(exact))
            fade = delta_E_2000(lab(src), lab(exact)).mean()
            print(f"| {recipe} | {gap.max():.2f} | {np.percentile(gap, 99):.2f} | "
                  f"{fade:.2f} | {t_grid:.1f} | {t_exact:.1f} |", flush=True)


if __name__ == "__main__":
    main()
