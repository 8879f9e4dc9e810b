"""``age-image``: fade a photograph or print by years of light exposure.

::

    python -m lightfade_addon age-image photo.png --years 0 5 10 25 --out aged/

writes ``aged/photo_0y.png``, ``aged/photo_5y.png``, ... in the photo's bit depth
(8 or 16; half or float images give OpenEXR files), alpha and colour-space metadata
kept, and a labelled contact sheet ``aged/photo_contact.png``. The physics is
:class:`..core.aging.TextureAger` (the mixture grid, paper Section 5) or, with
``--exact``, :func:`..core.aging.age_image_exact` (one direct simulation per distinct
colour, the paper's reference "without selective interpolation"). See
``docs/age-image.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import pathlib
import time

import numpy as np

from . import UserError, number

NAME = "age-image"
HELP = "fade a photograph or print by years of light exposure"

#: Defaults: a framed print in a living room (DESIGN.md, "Units and conventions").
DEFAULTS = dict(recipe="printed-paper", light="daylight-glass", lux=150.0,
                hours_per_day=8.0, days_per_year=365.0)
#: Rec. 709 / sRGB luminance weights, for the exposure mask.
_LUMA = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)


def add_arguments(parser):
    """The options, in groups: input and output, the light, the model."""
    from ..core.fading.model import KINETICS
    from ..core.fading.recipes import RECIPES
    from ..core.fading.spectra import LIGHTS

    d = DEFAULTS
    files = parser.add_argument_group("input and output")
    files.add_argument("photo", metavar="PHOTO",
                       help="image to age: PNG, TIFF, JPEG or OpenEXR (anything OpenImageIO "
                            "reads); integer values are taken as sRGB, half and float values "
                            "as linear. It is never modified.")
    files.add_argument("--years", nargs="+", required=True, metavar="YEARS", type=_years,
                       help="years of exposure, one image each (>= 0; e.g. 0 5 10 25); "
                            "file names use the numbers as written")
    files.add_argument("--out", metavar="DIR",
                       help="output folder, created if missing (default: the photo's folder)")
    files.add_argument("--exposure", metavar="MASK",
                       help="exposure mask image of the photo's size: its luminance (0-1, "
                            "as stored; white = the full --lux, black = dark) scales the "
                            "light per pixel (default: uniform)")

    light = parser.add_argument_group("the light")
    light.add_argument("--light", default=d["light"], choices=list(LIGHTS), metavar="NAME",
                       help=f"light spectrum (default: {d['light']}); one of: "
                            + "; ".join(f"{k} ({v})" for k, v in LIGHTS.items()))
    light.add_argument("--lux", default=d["lux"], type=number("lux"), metavar="LUX",
                       help="illuminance on the print, in lux (default: 150, a living room; "
                            "50 for sensitive museum objects, 10000+ in direct sun)")
    light.add_argument("--hours-per-day", default=d["hours_per_day"],
                       type=number("hours", 0, 24), metavar="H",
                       help="hours a day the light is on, in hours, 0-24 (default: 8)")
    light.add_argument("--days-per-year", default=d["days_per_year"],
                       type=number("days", 0, 366), metavar="D",
                       help="days a year the light is on, in days, 0-366 (default: 365)")
    light.add_argument("--uv-filter", action="store_true",
                       help="the light passes a UV filter (glazing or film cutting below "
                            "~400 nm); default: no filter")

    model = parser.add_argument_group("the model")
    model.add_argument("--recipe", default=d["recipe"], choices=list(RECIPES), metavar="NAME",
                       help=f"material recipe (default: {d['recipe']}); one of: "
                            + "; ".join(f"{k} ({r.description})" for k, r in RECIPES.items()))
    model.add_argument("--kinetics", default=None, choices=KINETICS,
                       help="rate law of the fading (default: the recipe's own, see "
                            "docs/recipes.md): shared (dyes in one medium fade together, "
                            "photosensitised), first-order (each dye molecule fades at its "
                            "own rate) or paper (equation 3 as printed, fade rate ~ "
                            "concentration²)")
    model.add_argument("--fastness", action="append", default=[], type=_fastness,
                       metavar="COLOURANT=CLASS",
                       help="give one colourant of the recipe another ISO Blue Wool class "
                            "(1 very fugitive - 8 very stable), e.g. --fastness yellow=2 "
                            "for a fugitive yellow dye; repeat for others (the recipe's "
                            "classes: docs/recipes.md)")
    model.add_argument("--restore", metavar="YEARS", type=number("years"),
                       help="the photo is already YEARS old under the light and schedule "
                            "given: first estimate it new (writes PHOTO_restored and "
                            "PHOTO_lost.png, white where the faded colour no longer tells "
                            "its original apart to ΔE00 2), then "
                            "age from new (--years 0 is the restored image)")
    model.add_argument("--exact", action="store_true",
                       help="reference path: simulate every distinct colour directly "
                            "instead of interpolating the mixture grid (slower)")


# -- parsing ---------------------------------------------------------------------------


def _fastness(text):
    """argparse ``type=`` of one ``--fastness`` word: ``(colourant, class)``."""
    from ..core.fading.recipes import parse_classes

    try:
        classes = parse_classes(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    if len(classes) != 1:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected one COLOURANT=CLASS per --fastness, e.g. yellow=2")
    return next(iter(classes.items()))

_non_negative_years = number("years")


def _years(text):
    """argparse ``type=`` of one ``--years`` word: ``(text, years)``, the text as written."""
    return text, _non_negative_years(text)


def parse_years(texts):
    """``[(text, years)]`` from the command line's words, duplicates dropped.

    The text is kept as written: it names the output files (``2.5`` -> ``_2.5y``).
    """
    out = []
    for t in texts:
        pair = t if isinstance(t, tuple) else _years(t)
        if pair[0] not in (s for s, _ in out):
            out.append(pair)
    return out


def format_dose(lux_hours):
    """Mlx·h with two decimals (more significant digits below 0.01 Mlx·h)."""
    m = lux_hours / 1e6
    if m == 0 or m >= 0.01:
        return f"{m:.2f}"
    return f"{m:.2g}"


def exposure_from_mask(rgb):
    """Relative exposure (H, W) in [0, 1]: the Rec. 709 luminance of the stored values."""
    return np.clip(np.asarray(rgb, np.float32) @ _LUMA, 0.0, 1.0)


def _same_file(p, q):
    try:
        if p.exists() and q.exists():
            return os.path.samefile(p, q)
    except OSError:
        pass
    return p.resolve() == q.resolve()


def _read(path):
    from ..images import read_image

    try:
        return read_image(path)
    except ValueError as exc:
        raise UserError(str(exc)) from None


def _write(path, rgb, alpha, dtype, metadata=None):
    from ..images import write_image

    try:
        write_image(path, rgb, alpha, dtype, metadata)
    except (OSError, ValueError) as exc:
        raise UserError(f"cannot write {str(path)!r}: "
                        f"{getattr(exc, 'strerror', None) or exc}") from None
    print(f"wrote {path}")


# -- the command ---------------------------------------------------------------------------


def _restore(rgb, alpha, info, years, recipe, light, exposure, base, encoding):
    """Restore an already-old photo; write ``<base>_restored`` and ``<base>_lost.png``."""
    from ..core.aging.restore import restore
    from ..progress import ProgressBar

    with ProgressBar("restore") as bar:
        try:
            # the file's own precision: half a step of its integers (8 bits for
            # half and float files, which hold no more than the camera's 8-bit steps)
            steps = {"uint16": 65535}.get(info.dtype, 255)
            result = restore(np.clip(rgb, 0.0, 1.0), years, recipe, [light], exposure,
                             encoding=encoding, progress=bar, precision=0.5 / steps)
        except ValueError as exc:
            raise UserError(str(exc)) from None
    suffix = ".exr" if info.dtype in ("half", "float") else ".png"
    restored = base.with_name(base.name + "_restored" + suffix)
    lost = base.with_name(base.name + "_lost.png")
    _write(restored, result.image, alpha, info.dtype, info.metadata)
    _write(lost, np.repeat(result.lost[..., None], 3, -1).astype(np.float32), None, "uint8")
    print(f"restored {years:g} y of {format_dose(years * light.annual_dose)} Mlx·h: "
          f"{result.lost_count} pixels ({result.lost_fraction:.1%}) lost, shown white "
          f"in {lost}")
    return result.image


def run(args):
    from ..contact_sheet import contact_sheet, thumbnail
    from ..core.aging.ager import Light, TextureAger, age_image_exact
    from ..core.colour.colorimetry import srgb_encode
    from ..core.fading.recipes import RECIPES
    from ..progress import ProgressBar

    t_start = time.perf_counter()
    years = parse_years(args.years)
    lux, hours, days = args.lux, args.hours_per_day, args.days_per_year
    light = Light(args.light, args.uv_filter, lux, hours, days)
    recipe = RECIPES[args.recipe]
    if args.kinetics is not None:
        recipe = dataclasses.replace(recipe, kinetics=args.kinetics)
    if args.fastness:
        try:
            recipe = recipe.with_classes(dict(args.fastness))
        except ValueError as exc:
            raise UserError(f"--fastness: {exc}") from None

    photo = pathlib.Path(args.photo)
    rgb, alpha, info = _read(photo)
    encoding = "linear" if info.linear else "srgb"

    out_dir = pathlib.Path(args.out) if args.out else photo.parent
    if out_dir.exists() and not out_dir.is_dir():
        raise UserError(f"output folder {str(out_dir)!r} is a file, not a folder")
    suffix = ".exr" if info.dtype in ("half", "float") else ".png"
    outputs = [out_dir / f"{photo.stem}_{text}y{suffix}" for text, _ in years]
    sheet_path = out_dir / f"{photo.stem}_contact.png"
    protected = [photo] + ([pathlib.Path(args.exposure)] if args.exposure else [])
    for p in outputs + [sheet_path]:
        for q in protected:
            if _same_file(p, q):
                raise UserError(f"refusing to write {str(p)!r}: it is an input file; "
                                f"choose another --out folder or rename the input")

    exposure = None
    if args.exposure:
        mask, _, minfo = _read(args.exposure)
        if mask.shape[:2] != rgb.shape[:2]:
            raise UserError(f"exposure mask {args.exposure!r} is {minfo.width}×{minfo.height} "
                            f"pixels but the photo is {info.width}×{info.height}; they must "
                            f"match")
        exposure = exposure_from_mask(mask)

    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create output folder {str(out_dir)!r}: "
                        f"{exc.strerror or exc}") from None

    if args.restore is not None:
        rgb = _restore(rgb, alpha, info, args.restore, recipe, light, exposure,
                       out_dir / photo.stem, encoding)

    schedule = f"{lux:g} lux × {hours:g} h/day × {days:g} days/year"
    print(f"{photo.name}: {info.width}×{info.height}, {info.bits}-bit {info.format} "
          f"{info.mode} ({encoding}); recipe {args.recipe}, light {args.light}"
          f"{' behind a UV filter' if args.uv_filter else ''}"
          f"{', exact reference path' if args.exact else ''}")
    for text, y in years:
        print(f"{text} y = {format_dose(y * light.annual_dose)} Mlx·h ({schedule})")
    if exposure is not None:
        print(f"doses at full exposure; the mask scales them by {exposure.min():.2f}-"
              f"{exposure.max():.2f} (mean {exposure.mean():.2f})")

    values = [y for _, y in years]
    albedo = np.clip(rgb, 0.0, 1.0)                 # reflectance: linear HDR values clip
    try:
        if max(values) == 0:
            aged = [rgb] * len(values)
        elif args.exact:
            with ProgressBar("exact") as bar:
                aged = age_image_exact(albedo, values, recipe, light, exposure,
                                       encoding=encoding, progress=bar)
        else:
            with ProgressBar("grid") as bar:
                ager = TextureAger(albedo, recipe, [light], exposure,
                                   max_years=max(values), encoding=encoding, progress=bar)
            aged = (ager.age(y) for y in values)
    except ValueError as exc:
        raise UserError(f"{photo.name}: {exc}") from None

    tiles = []
    for (text, y), path, img in zip(years, outputs, aged):
        if y == 0:
            img = rgb                       # bit-exact: the stored values themselves
        _write(path, img, alpha, info.dtype, info.metadata)
        shown = srgb_encode(np.clip(img, 0.0, 1.0)) if info.linear else img
        tiles.append(thumbnail(shown, alpha))

    sheet = contact_sheet(tiles, [f"{t} y" for t, _ in years],
                          [f"{format_dose(y * light.annual_dose)} Mlx·h" for _, y in years],
                          title=f"{photo.name}: {args.recipe}, {args.light}"
                                f"{' + UV filter' if args.uv_filter else ''}, "
                                f"{lux:g} lux, {hours:g} h/day, {days:g} days/year"
                                f"{' (exact)' if args.exact else ''}")
    _write(sheet_path, np.asarray(sheet, np.float32) / 255.0, None, "uint8")
    print(f"done in {time.perf_counter() - t_start:.1f} s")
    return 0
