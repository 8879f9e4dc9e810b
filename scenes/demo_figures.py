"""The demo's pictures for people: captions, labelled frames, contact sheets, the GIF and
the small images in ``docs/img/`` (Pillow)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

DOCS_IMG = Path(__file__).resolve().parents[1] / "docs" / "img"
DOCS_PNG_LIMIT = 400_000  # bytes
DOCS_GIF_LIMIT = 3_000_000
DOCS_GIF_WIDTH = 480

# ----------------------------------------------------------------------- captions


def years_label(years):
    if years == 0:
        return "0 years"
    if years < 1 / 12 - 1e-9:
        d = round(years * 365)
        return f"{d} day{'s' * (d != 1)}"
    if years < 1 - 1e-9:
        m = round(years * 12)
        return f"{m} month{'s' * (m != 1)}"
    return f"{years:g} year{'s' * (years != 1)}"


def years_slug(years):
    if years == 0 or years >= 1 - 1e-9:
        return f"{years:g}y"
    if years < 1 / 12 - 1e-9:
        return f"{round(years * 365)}d"
    return f"{round(years * 12)}mo"


def dose_label(mlxh):
    if mlxh == 0:
        return ""
    if mlxh < 10:
        return f"peak {mlxh:.2g} Mlx·h"
    return f"peak {mlxh:,.0f} Mlx·h"


# ----------------------------------------------------------------------- images (Pillow)


def _font(size):
    from PIL import ImageFont

    try:
        from matplotlib import font_manager

        return ImageFont.truetype(font_manager.findfont("DejaVu Sans"), size)
    except Exception:  # noqa: BLE001 - any font will do
        return ImageFont.load_default()


def labelled(path, label, sublabel="", bar=None):
    """The image at ``path`` with a caption bar under it."""
    from PIL import Image, ImageDraw

    im = Image.open(path).convert("RGB")
    w, h = im.size
    bar = bar or max(16, int(0.11 * h))
    out = Image.new("RGB", (w, h + bar), (24, 24, 24))
    out.paste(im, (0, 0))
    d = ImageDraw.Draw(out)
    size = max(9, int(bar * 0.55))
    font = _font(size)
    d.text((6, h + (bar - size) // 2 - 1), label, fill=(240, 240, 240), font=font)
    if sublabel:
        small = _font(max(8, int(size * 0.8)))
        tw = d.textlength(sublabel, font=small)
        d.text((w - tw - 6, h + (bar - size) // 2), sublabel, fill=(170, 170, 170), font=small)
    return out


def write_contact_sheet(frames, path, title="", columns=3):
    """Frames ``[(png, label, sublabel), ...]`` at their rendered size in a grid of
    ``columns``, labelled under each, with a title (:mod:`lightfade_addon.contact_sheet`)."""
    from PIL import Image

    from lightfade_addon.contact_sheet import contact_sheet, thumbnail

    tiles = []
    for png, _, _ in frames:
        rgb = np.asarray(Image.open(png).convert("RGB"), np.float32) / 255.0
        tiles.append(thumbnail(rgb, size=max(rgb.shape[:2])))
    sheet = contact_sheet(tiles, [f[1] for f in frames], [f[2] for f in frames], title=title,
                          columns=columns)
    sheet.save(path, optimize=True)
    return sheet


def write_gif(frames, path, width=None, ms=900, hold_ms=2200):
    """Animated GIF of labelled frames ``[(png, label, sublabel), ...]``, looping."""
    from PIL import Image

    tiles = [labelled(p, lab, sub) for p, lab, sub in frames]
    if width and tiles[0].width > width:
        h = round(tiles[0].height * width / tiles[0].width)
        tiles = [t.resize((width, h), Image.LANCZOS) for t in tiles]
    # Pillow dithers only when mapping to a given palette: make the palette, then map.
    pal = [t.quantize(palette=t.quantize(colors=255, method=Image.Quantize.MEDIANCUT),
                      dither=Image.Dither.FLOYDSTEINBERG) for t in tiles]
    durations = [ms] * len(pal)
    durations[0] = durations[-1] = hold_ms
    pal[0].save(path, save_all=True, append_images=pal[1:], duration=durations, loop=0,
                optimize=True, disposal=1)
    return path


def save_small_png(image, path, limit=DOCS_PNG_LIMIT):
    """Save ``image`` as PNG under ``limit`` bytes: full colour, scaled down to 70 % if need
    be (palette PNGs band on smooth walls), else 256 colours, else smaller still."""
    from PIL import Image

    image = image.convert("RGB")
    for scale in (1.0, 0.9, 0.8, 0.7):
        im = image if scale == 1.0 else image.resize(
            (round(image.width * scale), round(image.height * scale)), Image.LANCZOS)
        im.save(path, optimize=True)
        if os.path.getsize(path) <= limit:
            return path
    for scale in (1.0, 0.8, 0.6, 0.4):
        im = image if scale == 1.0 else image.resize(
            (round(image.width * scale), round(image.height * scale)), Image.LANCZOS)
        im.quantize(colors=256, method=Image.Quantize.FASTOCTREE,
                    dither=Image.Dither.FLOYDSTEINBERG).save(path, optimize=True)
        if os.path.getsize(path) <= limit:
            return path
    raise RuntimeError(f"could not fit {path} under {limit} bytes")


def side_by_side(frames, width=None):
    """Labelled frames ``[(png, label, sublabel), ...]`` in one row (each ``width`` px wide)."""
    from PIL import Image

    tiles = [labelled(p, lab, sub) for p, lab, sub in frames]
    if width and tiles[0].width != width:
        h = round(tiles[0].height * width / tiles[0].width)
        tiles = [t.resize((width, h), Image.LANCZOS) for t in tiles]
    gap = 4
    tw, th = tiles[0].size
    out = Image.new("RGB", (len(tiles) * tw + (len(tiles) - 1) * gap, th), (12, 12, 12))
    for i, t in enumerate(tiles):
        out.paste(t, (i * (tw + gap), 0))
    return out


# ----------------------------------------------------------------------- docs images


def write_docs(results, docs=DOCS_IMG):
    """Small images for the README: before/after/reveal strips, contact sheets, the GIF."""
    docs = Path(docs)
    docs.mkdir(parents=True, exist_ok=True)
    written = []
    r = results.get("room")
    if r:
        strip = [r["frames"][0], r["frames"][-1], *r["reveal_frames"]]
        p = docs / "demo_room_before_after.png"
        save_small_png(side_by_side(strip, width=480), p)
        written.append(p)
        p = docs / "demo_room_years.png"                # the sun's band growing, year by year
        save_small_png(side_by_side(r["frames"], width=320), p)
        written.append(p)
        dresser = r["extra"].get("Camera.Dresser", [])
        if dresser:
            p = docs / "demo_dresser.png"
            save_small_png(side_by_side(dresser, width=400), p)
            written.append(p)
        floor = r["extra"].get("Camera.Floor", [])
        if floor:
            p = docs / "demo_floor.png"
            save_small_png(side_by_side(floor, width=400), p)
            written.append(p)
        p = docs / "demo.gif"
        write_gif(r["frames"] + r["reveal_frames"], p, width=DOCS_GIF_WIDTH)
        if os.path.getsize(p) > DOCS_GIF_LIMIT:
            write_gif(r["frames"] + r["reveal_frames"], p, width=DOCS_GIF_WIDTH // 2)
        written.append(p)
    for name in ("gallery", "swatches"):
        s = results.get(name)
        if s:
            p = docs / f"demo_{name}.png"
            strip = [s["frames"][0], s["frames"][len(s["frames"]) // 2], s["frames"][-1], *s["reveal_frames"]]
            save_small_png(side_by_side(strip, width=360), p)
            written.append(p)
    return written
