"""Contact sheets: thumbnails in a row or a grid, each labelled, under a title line (Pillow).

Used by the ``age-image`` command (one row) and the demo (``scenes/demo.py``, three
columns); any script that shows a series of images can build its sheet the same way::

    tiles = [thumbnail(rgb) for rgb in images]
    contact_sheet(tiles, ["0 y", "5 y"], ["0.00 Mlx·h", "2.19 Mlx·h"], title="photo.png")
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["thumbnail", "contact_sheet"]

#: Longest side of a tile, pixels (smaller images are enlarged to at least the minimum).
TILE = 320
MIN_TILE_WIDTH = 128


def _font(size):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError, ImportError):  # Pillow < 10.1 or no FreeType
        return ImageFont.load_default()


def thumbnail(rgb, alpha=None, size=TILE):
    """An 8-bit RGB thumbnail (PIL image) of display-encoded RGB, alpha over white.

    Parameters
    ----------
    rgb : array_like, shape (H, W, 3)
        Encoded (display) values in [0, 1]; clipped.
    alpha : array_like, shape (H, W), optional
        Straight alpha; the image is composited over white.
    size : int
        Longest side, pixels: larger images are shrunk (Lanczos), images narrower than
        :data:`MIN_TILE_WIDTH` enlarged by a whole factor (nearest neighbour).
    """
    from PIL import Image

    rgb = np.clip(np.asarray(rgb, np.float32), 0.0, 1.0)
    if alpha is not None:
        alpha = np.asarray(alpha, np.float32)[..., None]
        rgb = rgb * alpha + (1.0 - alpha)
    im = Image.fromarray(np.rint(rgb * 255).astype(np.uint8), "RGB")
    w, h = im.size
    if max(w, h) > size:
        s = size / max(w, h)
        im = im.resize((max(1, round(w * s)), max(1, round(h * s))), Image.LANCZOS)
    elif w < MIN_TILE_WIDTH:
        k = math.ceil(MIN_TILE_WIDTH / w)
        im = im.resize((w * k, h * k), Image.NEAREST)
    return im


def contact_sheet(tiles, labels, sublabels, title="", columns=None):
    """Tiles in a row, or a grid of rows, each with a label and a smaller label under it.

    Parameters
    ----------
    tiles : list of PIL.Image.Image
        RGB thumbnails (see :func:`thumbnail`).
    labels, sublabels : list of str
        One each per tile.
    title : str
        A line above the tiles.
    columns : int, optional
        Tiles per row; later tiles wrap onto new rows. None puts all tiles in one row.

    Returns
    -------
    PIL.Image.Image
        An RGB image. A column is as wide as its widest tile or label; every row is as
        tall as the tallest tile plus 44 pixels of labels; 10 pixels between and around.

    Examples
    --------
    Five 150 × 100 tiles, three to a row: two rows.

    >>> tiles = [thumbnail(np.zeros((100, 150, 3)))] * 5
    >>> contact_sheet(tiles, ["0 y"] * 5, [""] * 5, columns=3).size
    (490, 318)
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

    n = len(tiles)
    columns = n if columns is None else columns
    if columns < 1:
        raise ValueError(f"columns must be at least 1, not {columns}")
    columns = min(columns, n)
    rows = math.ceil(n / columns)
    cells = [max(t.width, width(a, big), width(b, small))
             for t, a, b in zip(tiles, labels, sublabels)]
    cols = [max(cells[c::columns]) for c in range(columns)]
    lefts = [pad + sum(cols[:c]) + pad * c for c in range(columns)]
    tile_h = max(t.height for t in tiles)
    title_h = 26 if title else 0
    text_h = 44
    row_h = tile_h + text_h + pad
    W = max(sum(cols) + pad * (columns + 1), width(title, small) + 2 * pad)
    H = pad + title_h + rows * row_h
    sheet = Image.new("RGB", (W, H), (250, 250, 248))
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((pad, pad), title, fill=(40, 40, 40), font=small)
    for i, (t, a, b) in enumerate(zip(tiles, labels, sublabels)):
        r, c = divmod(i, columns)
        x, y, cw = lefts[c], pad + title_h + r * row_h, cols[c]
        sheet.paste(t, (x + (cw - t.width) // 2, y))
        cx = x + cw / 2
        draw.text((cx, y + tile_h + 6), a, fill=(20, 20, 20), font=big, anchor="mt")
        draw.text((cx, y + tile_h + 27), b, fill=(90, 90, 90), font=small, anchor="mt")
    return sheet
