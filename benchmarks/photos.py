"""The grid path against the exact path on synthetic photographs, every recipe and light.

    python -m benchmarks.photos              # prints the table and writes docs/grid_photos.md
    python -m benchmarks.photos --quick      # printed paper in window daylight only (and
                                             # a smaller many-colour photo), also written

Each photograph (made here, no download) is aged by :class:`TextureAger` (the grid,
what Blender and ``age-image`` use) and by :func:`age_image_exact` (one direct
simulation per distinct colour, ``age-image --exact``) at doses spread over the
whole years slider (0.3 … 100 years of 3000 lux, 8 h a day: up to 876 Mlx·h), with
bands of exposure across each image (0.1 %, 1 %, 3 %, 10 %, 30 % and 100 % of the
full light, as shadows give inside one texture), and the written sRGB images are
compared: max and 99th-percentile CIEDE2000 per case.
Photographs: saturated primaries (a hue sweep at full saturation, magentas and
purples included), skin, foliage, greys, a landscape, and two with more distinct
colours than an aging table has keys (float values with noise, 74,000 colours; 8-bit
values with broad noise, 173,000 colours), which take the binned path, and the
landscape at 2048² (376,000 colours, three per key of the aging table; compared on
20,000 random pixels).  The grid reaches the next quarter octave of dose above the
brightest texel's 100 years (``lattice.grid_max_dose``), so no case sits on its last
node by construction.
"""

from __future__ import annotations

import argparse
import colorsys
import pathlib
import time

import numpy as np

from benchmarks.problem import synthetic_photo
from lightfade_addon.core.aging.ager import Light, TextureAger
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.exact import age_image_exact
from lightfade_addon.core.fading.gridbuild import build_grid
from lightfade_addon.core.fading.recipes import RECIPES

ROOT = pathlib.Path(__file__).resolve().parents[1]
YEARS = (0.3, 1.0, 2.5, 6.0, 15.0, 40.0, 100.0)
LUX = 3000.0


def _quantised(img):
    return (np.rint(np.clip(img, 0, 1) * 255) / 255).astype(np.float32)


def primaries(n=48):
    """Hue sweep at full saturation (x) over value 1 → 0.25 (y), and pastel rows."""
    h = np.linspace(0, 1, n, endpoint=False)
    v = np.linspace(1.0, 0.25, n // 2)
    sat = [[colorsys.hsv_to_rgb(hh, 1.0, vv) for hh in h] for vv in v]
    pastel = [[colorsys.hsv_to_rgb(hh, s, 1.0) for hh in h] for s in np.linspace(0.1, 0.9, n // 2)]
    return _quantised(np.array(sat + pastel))


def _patches(n, centres, spread, seed):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n] / n
    k = ((x * 4).astype(int) + 4 * (y * 4).astype(int)) % len(centres)
    img = np.asarray(centres)[k] + spread * (np.stack([x, y, x * y], -1) - 0.4)
    return _quantised(img + rng.normal(0, 0.015, img.shape))


def skin(n=48):
    return _patches(n, [(0.96, 0.80, 0.69), (0.88, 0.67, 0.53), (0.76, 0.53, 0.38),
                        (0.55, 0.36, 0.25), (0.36, 0.22, 0.15), (0.93, 0.73, 0.65)], 0.1, 1)


def foliage(n=48):
    return _patches(n, [(0.20, 0.45, 0.12), (0.35, 0.55, 0.15), (0.10, 0.30, 0.08),
                        (0.55, 0.65, 0.20), (0.45, 0.40, 0.10), (0.15, 0.35, 0.25)], 0.12, 2)


def greys(n=48):
    y, x = np.mgrid[0:n, 0:n] / n
    g = np.clip(0.03 + 0.95 * x + 0.01 * np.sin(20 * y), 0, 1)
    tint = 0.02 * (y - 0.5)
    return _quantised(np.stack([g + tint, g, g - tint], -1))


def landscape(n=48):
    return _quantised(synthetic_photo(n, n))


def many_colours(n=320):
    """Float values with noise: more than 65,536 distinct colours (and 8-bit codes)."""
    rng = np.random.default_rng(5)
    y, x = np.mgrid[0:n, 0:n] / n
    img = np.stack([0.5 + 0.45 * np.sin(6 * x + 2 * y), 0.5 + 0.45 * np.cos(5 * y + x),
                    0.5 + 0.45 * np.sin(3 * x * y + 4 * y)], -1)
    return np.clip(img + rng.normal(0, 0.03, img.shape), 0, 1).astype(np.float32)


def many_colours_8bit(n=420):
    """8-bit values, broad noise: more distinct colours (about 170,000) than keys."""
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:n, 0:n] / n
    img = np.stack([0.5 + 0.45 * np.sin(6 * x + 2 * y), 0.5 + 0.45 * np.cos(5 * y + x),
                    0.5 + 0.45 * np.sin(3 * x * y + 4 * y)], -1)
    return _quantised(img + rng.normal(0, 0.06, img.shape))


def landscape_2048():
    """The landscape at 2048², 8-bit: 376,000 distinct colours, about three per key
    (compared on 20,000 random pixels)."""
    return _quantised(synthetic_photo(2048, 2048))


PHOTOS = {"primaries": primaries, "skin": skin, "foliage": foliage, "greys": greys,
          "landscape": landscape}


def lab(img):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(img, float).reshape(-1, 3))))


#: Exposure levels across each photograph (columns), as shadows and bounce light give
#: inside one texture: texels at these shares of the brightest texel's dose.
EXPOSURES = np.array([1e-3, 1e-2, 0.03, 0.1, 0.3, 1.0])


def exposure_map(shape):
    """Bands of :data:`EXPOSURES` across the image, (H, W)."""
    h, w = shape[:2]
    return np.repeat(EXPOSURES, -(-w // EXPOSURES.size))[:w][None].repeat(h, 0)


def compare(photo, recipe, light, sample=None):
    """(max, p99) ΔE00 over all years and exposure bands, and the distinct colours.

    With ``sample``, the exact path runs on that many random pixels only (each pixel's
    exact result depends on its own colour and exposure alone); the grid path always
    ages the whole photo, since its keys depend on all of its colours."""
    expo = exposure_map(photo.shape)
    ager = TextureAger(photo, recipe, [light], expo, encoding="srgb", max_years=max(YEARS),
                       cache=False)
    pick = (np.arange(photo.shape[0] * photo.shape[1]) if sample is None else
            np.random.default_rng(0).choice(photo.shape[0] * photo.shape[1], sample, False))
    flat = photo.reshape(-1, 3)
    exact = age_image_exact(flat[pick][None], list(YEARS), recipe, light,
                            expo.reshape(-1)[pick][None], encoding="srgb")
    errs = np.concatenate([delta_E_2000(lab(ager.age(y).reshape(-1, 3)[pick]), lab(e))
                           for y, e in zip(YEARS, exact)])
    colours = np.unique(photo.reshape(-1, 3), axis=0).shape[0]
    return errs.max(), np.percentile(errs, 99), colours


def cases(quick):
    """Every light for printed paper; the others under their typical lights."""
    if quick:
        yield "printed-paper", "daylight-glass"
        yield "dyed-fabric", "daylight"
        return
    for spectrum in ("daylight-glass", "daylight", "incandescent", "fluorescent", "led"):
        yield "printed-paper", spectrum
    yield "dyed-fabric", "daylight-glass"
    yield "dyed-fabric", "incandescent"
    yield "painted-wood", "daylight"
    yield "bare-wood", "daylight"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    rows = []
    worst = 0.0
    header = "| photo | colours | recipe | light | max ΔE00 | p99 ΔE00 |"
    print(header)
    for recipe, spectrum in cases(args.quick):
        light = Light(spectrum, lux=LUX)
        photos = dict(PHOTOS)
        if (recipe, spectrum) == ("printed-paper", "daylight-glass"):
            photos["many-colours"] = (lambda: many_colours(272)) if args.quick else many_colours
            photos["many-colours-8bit"] = many_colours_8bit
            photos["landscape-2048"] = landscape_2048
        for pname, make in photos.items():
            mx, p99, colours = compare(make(), recipe, light,
                                       sample=20000 if pname == "landscape-2048" else None)
            worst = max(worst, mx)
            row = f"| {pname} | {colours} | {recipe} | {spectrum} | {mx:.2f} | {p99:.2f} |"
            print(row, flush=True)
            rows.append(row)
    # build and update times, side by side
    spectrum = Light("daylight-glass", lux=LUX).spectrum_1lux()[None]
    t0 = time.perf_counter()
    build_grid(RECIPES["printed-paper"], spectrum, LUX * 8 * 365 * 100)
    build = time.perf_counter() - t0
    big = srgb_decode(synthetic_photo(2048, 2048)).astype(np.float32)
    ager = TextureAger(big, "printed-paper", [Light(lux=LUX)], encoding="linear",
                       max_years=100, cache=False)
    out = np.empty((2048 * 2048, 4), np.float32)
    times = []
    for y in np.linspace(1, 99, 7):
        t0 = time.perf_counter()
        ager.age(y, out=out)
        times.append(time.perf_counter() - t0)
    update = float(np.median(times))
    summary = (f"Worst case max ΔE00 {worst:.2f}. Grid build (printed-paper, one spectrum, "
               f"100 years of {LUX:g} lux) {build:.2f} s; 2048² update (linear RGBA out, "
               f"median of 7) {update * 1e3:.0f} ms.")
    print(summary)
    text = "\n".join([
        "# The grid against the exact path on photographs",
        "",
        f"Generated by `python -m benchmarks.photos{' --quick' if args.quick else ''}` — "
        "do not edit by hand.",
        "",
        __doc__.split("\n\n", 2)[2].strip(),
        "",
        header, "|---|---:|---|---|---:|---:|", *rows, "", summary, ""])
    (ROOT / "docs" / "grid_photos.md").write_text(text)
    print("wrote docs/grid_photos.md")


if __name__ == "__main__":
    main()
