"""``age-image``: fade a photograph or print by years of light exposure.

::

    python -m lightfade_addon age-image photo.png --years 0 5 10 25 --out aged/

writes ``aged/photo_0y.png``, ``aged/photo_5y.png``, ... in the photo's bit depth
(8 or 16), alpha kept, and a labelled contact sheet ``aged/photo_contact.png``.
The physics is :class:`..core.aging.TextureAger` (the mixture grid, paper
Section 5) or, with ``--exact``, :func:`..core.aging.age_image_exact` (one direct
simulation per distinct colour, the paper's reference "without selective
interpolation"). See ``docs/age-image.md``.
"""

from __future__ import annotations

import dataclasses
import math
import os
import pathlib
import time

import numpy as np

from ..cli import UserError, command

#: Defaults: a framed print in a living room (DESIGN.md, "Units and conventions").
DEFAULTS = dict(recipe="printed-paper", light="daylight-glass", lux=150.0,
                hours_per_day=8.0, days_per_year=365.0)
#: Rec. 709 / sRGB luminance weights, for the exposure mask.
_LUMA = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
#: Longest side of a contact-sheet tile, pixels (smaller images are enlarged).
_TILE = 320
_MIN_TILE_WIDTH = 128


@command("age-image", "fade a photograph or print by years of light exposure")
def build(parser):
    from ..core.recipes import RECIPES
    from ..core.spectra import LIGHTS

    d = DEFAULTS
    parser.add_argument("photo", metavar="PHOTO",
                        help="image to age: PNG (8 or 16 bits), JPEG or TIFF (8 bits); "
                             "its values are taken as sRGB. It is never modified.")
    parser.add_argument("--years", nargs="+", required=True, metavar="YEARS",
                        help="years of exposure, one image each (>= 0; e.g. 0 5 10 25); "
                             "file names use the numbers as written")
    parser.add_argument("--out", metavar="DIR",
                        help="output folder, created if missing (default: the photo's folder)")
    parser.add_argument("--recipe", default=d["recipe"], metavar="NAME",
                        help=f"material recipe (default: {d['recipe']}); one of: "
                             + "; ".join(f"{k} ({r.description})" for k, r in RECIPES.items()))
    parser.add_argument("--light", default=d["light"], metavar="NAME",
                        help=f"light spectrum (default: {d['light']}); one of: "
                             + "; ".join(f"{k} ({v})" for k, v in LIGHTS.items()))
    parser.add_argument("--lux", default=str(d["lux"]), metavar="LUX",
                        help="illuminance on the print, in lux (default: 150, a living room; "
                             "50 for sensitive museum objects, 10000+ in direct sun)")
    parser.add_argument("--hours-per-day", default=str(d["hours_per_day"]), metavar="H",
                        help="hours a day the light is on, in hours, 0-24 (default: 8)")
    parser.add_argument("--days-per-year", default=str(d["days_per_year"]), metavar="D",
                        help="days a year the light is on, in days, 0-366 (default: 365)")
    parser.add_argument("--uv-filter", action="store_true",
                        help="the light passes a UV filter (glazing or film cutting below "
                             "~400 nm); default: no filter")
    parser.add_argument("--exposure", metavar="MASK",
                        help="exposure mask image of the photo's size: its luminance (0-1, "
                             "as stored; white = the full --lux, black = dark) scales the "
                             "light per pixel (default: uniform)")
    parser.add_argument("--kinetics", default="first-order", choices=("first-order", "paper"),
                        help="rate law of the fading: first-order (default; each dye "
                             "molecule fades at its own rate, as in conservation practice) "
                             "or paper (equation 3 as printed, fade rate ~ concentration²)")
    parser.add_argument("--restore", metavar="YEARS",
                        help="the photo is already YEARS old under the light and schedule "
                             "given: first estimate it new (writes PHOTO_restored.png and "
                             "PHOTO_lost.png, white where fading destroyed the colour), then "
                             "age from new (--years 0 is the restored image)")
    parser.add_argument("--exact", action="store_true",
                        help="reference path: simulate every distinct colour directly "
                             "instead of interpolating the mixture grid (slower)")
    parser.set_defaults(run=run)


# -- parsing ---------------------------------------------------------------------------


def _number(text, what, unit, low=0.0, high=math.inf):
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise UserError(f"{what} must be a number in {unit}, got {text!r}") from None
    if not math.isfinite(value) or not low <= value <= high:
        bound = f"between {low:g} and {high:g}" if math.isfinite(high) else f">= {low:g}"
        raise UserError(f"{what} must be a finite number {bound} {unit}, got {text!r}")
    return value


def parse_years(texts):
    """``[(text, years)]`` from the command line's words, duplicates dropped.

    The text is kept as written: it names the output files (``2.5`` -> ``_2.5y``).
    """
    out = []
    for t in texts:
        y = _number(t, "years", "years")
        if t not in (s for s, _ in out):
            out.append((t, y))
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


# -- the contact sheet -------------------------------------------------------------------


def _font(size):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError, ImportError):  # Pillow < 10.1 or no FreeType
        return ImageFont.load_default()


def _tile(rgb, alpha):
    """An 8-bit RGB thumbnail (PIL image) of an image, alpha composited over white."""
    from PIL import Image

    rgb = np.clip(np.asarray(rgb, np.float32), 0.0, 1.0)
    if alpha is not None:
        rgb = rgb * alpha[..., None] + (1.0 - alpha[..., None])
    im = Image.fromarray(np.rint(rgb * 255).astype(np.uint8), "RGB")
    w, h = im.size
    if max(w, h) > _TILE:
        s = _TILE / max(w, h)
        im = im.resize((max(1, round(w * s)), max(1, round(h * s))), Image.LANCZOS)
    elif w < _MIN_TILE_WIDTH:
        k = math.ceil(_MIN_TILE_WIDTH / w)
        im = im.resize((w * k, h * k), Image.NEAREST)
    return im


def contact_sheet(tiles, labels, sublabels, title=""):
    """Tiles side by side, each with a label and a smaller label under it.

    Parameters
    ----------
    tiles : list of PIL.Image.Image
        RGB thumbnails (see :func:`_tile`).
    labels, sublabels : list of str
    title : str
        A line above the tiles.

    Returns
    -------
    PIL.Image.Image
    """
    from PIL import Image, ImageDraw

    pad = 10
    big, small = _font(16), _font(13)
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))

    def width(text, font):
        if not text:
            return 0
        x0, _, x1, _ = probe.textbbox((0, 0), text, font=font)
        return x1 - x0

    cols = [max(t.width, width(a, big), width(b, small)) for t, a, b in zip(tiles, labels,
                                                                           sublabels)]
    tile_h = max(t.height for t in tiles)
    title_h = 26 if title else 0
    text_h = 44
    W = max(sum(cols) + pad * (len(tiles) + 1), width(title, small) + 2 * pad)
    H = pad + title_h + tile_h + text_h + pad
    sheet = Image.new("RGB", (W, H), (250, 250, 248))
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((pad, pad), title, fill=(40, 40, 40), font=small)
    x = pad
    for t, a, b, cw in zip(tiles, labels, sublabels, cols):
        y = pad + title_h
        sheet.paste(t, (x + (cw - t.width) // 2, y))
        cx = x + cw / 2
        draw.text((cx, y + tile_h + 6), a, fill=(20, 20, 20), font=big, anchor="mt")
        draw.text((cx, y + tile_h + 27), b, fill=(90, 90, 90), font=small, anchor="mt")
        x += cw + pad
    return sheet


# -- the command ---------------------------------------------------------------------------


def _restore(rgb, alpha, info, years, recipe, light, exposure, base):
    """Restore an already-old photo; write ``<base>_restored.png`` and ``<base>_lost.png``."""
    from .. import imageio
    from ..core.restore import restore
    from ..progress import ProgressBar

    with ProgressBar("restore") as bar:
        try:
            result = restore(rgb, years, recipe, [light], exposure, encoding="srgb",
                             progress=bar)
        except ValueError as exc:
            raise UserError(str(exc)) from None
    restored, lost = base.with_name(base.name + "_restored.png"), \
        base.with_name(base.name + "_lost.png")
    try:
        imageio.write_image(restored, result.image, alpha, bits=info.bits)
        imageio.write_image(lost, np.repeat(result.lost[..., None], 3, -1).astype(np.float32))
    except (OSError, ValueError) as exc:
        raise UserError(f"cannot write {str(restored)!r}: "
                        f"{getattr(exc, 'strerror', None) or exc}") from None
    share = result.lost_count / max(result.lost.size, 1)
    print(f"restored {years:g} y of {format_dose(years * light.annual_dose)} Mlx·h: wrote "
          f"{restored}; {result.lost_count} pixels ({share:.1%}) lost, shown white in {lost}")
    return result.image


def run(args):
    from .. import imageio
    from ..core.aging import Light, TextureAger, age_image_exact
    from ..core.recipes import RECIPES
    from ..core.spectra import LIGHTS
    from ..progress import ProgressBar

    t_start = time.perf_counter()
    years = parse_years(args.years)
    lux = _number(args.lux, "--lux", "lux")
    hours = _number(args.hours_per_day, "--hours-per-day", "hours", 0.0, 24.0)
    days = _number(args.days_per_year, "--days-per-year", "days", 0.0, 366.0)
    if args.recipe not in RECIPES:
        raise UserError(f"unknown recipe {args.recipe!r}; valid recipes: {', '.join(RECIPES)}")
    if args.light not in LIGHTS:
        raise UserError(f"unknown light {args.light!r}; valid lights: {', '.join(LIGHTS)}")
    try:
        light = Light(args.light, args.uv_filter, lux, hours, days)
    except ValueError as exc:
        raise UserError(str(exc)) from None

    photo = pathlib.Path(args.photo)
    try:
        rgb, alpha, info = imageio.read_image(photo)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    recipe = dataclasses.replace(RECIPES[args.recipe], kinetics=args.kinetics)
    prior_years = None if args.restore is None else _number(args.restore, "--restore", "years")

    out_dir = pathlib.Path(args.out) if args.out else photo.parent
    if out_dir.exists() and not out_dir.is_dir():
        raise UserError(f"output folder {str(out_dir)!r} is a file, not a folder")
    stem = photo.stem
    outputs = [out_dir / f"{stem}_{text}y.png" for text, _ in years]
    sheet_path = out_dir / f"{stem}_contact.png"
    protected = [photo] + ([pathlib.Path(args.exposure)] if args.exposure else [])
    for p in outputs + [sheet_path]:
        for q in protected:
            if _same_file(p, q):
                raise UserError(f"refusing to write {str(p)!r}: it is an input file; "
                                f"choose another --out folder or rename the input")

    exposure = None
    if args.exposure:
        try:
            mask, _, minfo = imageio.read_image(args.exposure)
        except ValueError as exc:
            raise UserError(str(exc)) from None
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

    if prior_years is not None:
        rgb = _restore(rgb, alpha, info, prior_years, recipe, light, exposure, out_dir / stem)

    schedule = f"{lux:g} lux × {hours:g} h/day × {days:g} days/year"
    print(f"{photo.name}: {info.width}×{info.height}, {info.bits}-bit {info.format} "
          f"{info.mode}; recipe {args.recipe}, light {args.light}"
          f"{' behind a UV filter' if args.uv_filter else ''}"
          f"{', exact reference path' if args.exact else ''}")
    for text, y in years:
        print(f"{text} y = {format_dose(y * light.annual_dose)} Mlx·h ({schedule})")
    if exposure is not None:
        print(f"doses at full exposure; the mask scales them by {exposure.min():.2f}-"
              f"{exposure.max():.2f} (mean {exposure.mean():.2f})")

    values = [y for _, y in years]
    if max(values) == 0:
        aged = [rgb] * len(values)
    elif args.exact:
        with ProgressBar("exact") as bar:
            try:
                aged = age_image_exact(rgb, values, recipe, light, exposure,
                                       encoding="srgb", progress=bar)
            except ValueError as exc:
                raise UserError(str(exc)) from None
    else:
        with ProgressBar("grid") as bar:
            try:
                ager = TextureAger(rgb, recipe, [light], exposure, max_years=max(values),
                                   encoding="srgb", progress=bar)
            except ValueError as exc:
                raise UserError(str(exc)) from None
        aged = (ager.age(y) for y in values)

    tiles = []
    for (text, y), path, img in zip(years, outputs, aged):
        if y == 0:
            img = rgb                       # bit-exact: the stored values themselves
        try:
            imageio.write_image(path, img, alpha, bits=info.bits)
        except (OSError, ValueError) as exc:
            raise UserError(f"cannot write {str(path)!r}: "
                            f"{getattr(exc, 'strerror', None) or exc}") from None
        print(f"wrote {path}")
        tiles.append(_tile(img, alpha))

    sheet = contact_sheet(tiles, [f"{t} y" for t, _ in years],
                          [f"{format_dose(y * light.annual_dose)} Mlx·h" for _, y in years],
                          title=f"{photo.name}: {args.recipe}, {args.light}"
                                f"{' + UV filter' if args.uv_filter else ''}, "
                                f"{lux:g} lux, {hours:g} h/day, {days:g} days/year"
                                f"{' (exact)' if args.exact else ''}")
    try:
        imageio.write_image(sheet_path, np.asarray(sheet, np.float32) / 255.0)
    except OSError as exc:
        raise UserError(f"cannot write {str(sheet_path)!r}: {exc.strerror or exc}") from None
    print(f"wrote {sheet_path}")
    print(f"done in {time.perf_counter() - t_start:.1f} s")
    return 0
