"""Image files for the command line: PNG (8 and 16 bits), JPEG and TIFF (8 bits).

Pixels cross this module as float32 arrays in [0, 1], *as stored* (encoded sRGB
for ordinary photographs; nothing is decoded or colour-managed here):

>>> rgb, alpha, info = read_image("photo.png")          # doctest: +SKIP
>>> write_image("photo_5y.png", aged, alpha, bits=info.bits)   # doctest: +SKIP

8-bit files go through Pillow. Pillow reduces 16-bit RGB and RGBA PNGs to 8 bits
when it reads them and cannot write them at all, so 16-bit PNGs are decoded and
encoded here with :mod:`zlib` and :mod:`struct` (PNG specification, 2nd ed., W3C
2003: non-interlaced images, all five filter types). An 8- or 16-bit value ``v``
becomes ``v / (2**bits - 1)`` and goes back by rounding, so a file read and written
unchanged keeps every pixel.

This module is not part of ``core/`` (which is numpy and colour-science only).
"""

from __future__ import annotations

import os
import pathlib
import struct
import zlib
from dataclasses import dataclass

import numpy as np

__all__ = ["ImageInfo", "read_image", "write_image", "FORMATS"]

#: File extensions -> format written by :func:`write_image`.
FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG", ".tif": "TIFF", ".tiff": "TIFF"}

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: PNG colour type -> samples per pixel (0 grey, 2 RGB, 4 grey + alpha, 6 RGBA).
_PNG_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}


@dataclass(frozen=True)
class ImageInfo:
    """What :func:`read_image` found in a file.

    Attributes
    ----------
    format : str
        ``"PNG"``, ``"JPEG"``, ``"TIFF"``, ... (Pillow's name for it).
    bits : int
        Bits per sample, 8 or 16.
    mode : str
        The stored layout: ``"RGB"``, ``"RGBA"``, ``"L"`` (grey), ``"LA"``, ``"P"``
        (palette), ... Everything is returned as RGB (+ alpha).
    width, height : int
        Pixels.
    """

    format: str
    bits: int
    mode: str
    width: int
    height: int


# -- reading ---------------------------------------------------------------------------


def read_image(path):
    """Read an image file as float RGB in [0, 1] plus optional alpha.

    Parameters
    ----------
    path : str or os.PathLike
        A PNG (8 or 16 bits; grey, grey + alpha, RGB, RGBA or palette), JPEG or
        TIFF (8 bits) file.

    Returns
    -------
    rgb : ndarray, float32, shape (H, W, 3)
        Values as stored, divided by 255 or 65535. Grey is repeated into R, G, B;
        palettes are expanded.
    alpha : ndarray, float32, shape (H, W), or None
        Straight (not premultiplied) alpha, if the file has any (including a PNG
        ``tRNS`` transparent colour or palette transparency).
    info : ImageInfo

    Raises
    ------
    ValueError
        The file is missing, unreadable, or in a format or depth not supported; the
        message names the file.
    """
    path = pathlib.Path(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(33)
    except FileNotFoundError:
        raise ValueError(f"cannot read {str(path)!r}: no such file") from None
    except IsADirectoryError:
        raise ValueError(f"cannot read {str(path)!r}: it is a folder, not an image") from None
    except OSError as exc:
        raise ValueError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    if head.startswith(_PNG_SIGNATURE) and len(head) >= 33 and head[24] == 16:
        try:
            return _read_png16(path)
        except ValueError as exc:
            raise ValueError(f"cannot read {str(path)!r}: {exc}") from None
    return _read_pillow(path)


def _read_pillow(path):
    from PIL import Image, ImageOps, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            im.load()
            fmt = im.format or "unknown"
            mode = im.mode
            if fmt in ("JPEG", "MPO", "TIFF"):
                im = ImageOps.exif_transpose(im)
            if mode in ("I;16", "I;16B", "I;16L", "I", "F") or "16" in mode:
                raise ValueError(f"{fmt} with {mode} pixels is not supported; "
                                 f"save it as an 8-bit image or a 16-bit PNG")
            transparent = "transparency" in im.info or mode in ("RGBA", "LA", "PA", "La",
                                                                "RGBa")
            im = im.convert("RGBA" if transparent else "RGB")
            a = np.asarray(im)
    except UnidentifiedImageError:
        raise ValueError(f"cannot read {str(path)!r}: not an image file Pillow "
                         f"recognises (PNG, JPEG and TIFF are supported)") from None
    except ValueError as exc:
        raise ValueError(f"cannot read {str(path)!r}: {exc}") from None
    except (OSError, SyntaxError) as exc:
        # Pillow reports truncated or corrupt files as OSError or SyntaxError.
        raise ValueError(f"cannot read {str(path)!r}: damaged or unsupported image "
                         f"({exc})") from None
    if a.dtype != np.uint8:
        raise ValueError(f"cannot read {str(path)!r}: unsupported pixel type {a.dtype}")
    h, w = a.shape[:2]
    rgb = a[..., :3].astype(np.float32) / np.float32(255.0)
    alpha = a[..., 3].astype(np.float32) / np.float32(255.0) if a.shape[2] == 4 else None
    return rgb, alpha, ImageInfo(fmt, 8, mode, w, h)


def _png_chunks(data):
    """Yield (type, payload) of a PNG byte string, checking lengths and CRCs."""
    if not data.startswith(_PNG_SIGNATURE):
        raise ValueError("not a PNG file")
    pos = len(_PNG_SIGNATURE)
    while pos + 12 <= len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        end = pos + 12 + length
        if end > len(data):
            raise ValueError("truncated PNG file")
        payload = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[end - 4:end])
        if zlib.crc32(kind + payload) != crc:
            raise ValueError(f"damaged PNG file (bad CRC in the {kind.decode('latin-1')} chunk)")
        yield kind, payload
        if kind == b"IEND":
            return
        pos = end
    raise ValueError("truncated PNG file (no IEND chunk)")


def decode_png(data):
    """Decode a non-interlaced 8- or 16-bit grey/RGB PNG to integer samples.

    Returns
    -------
    samples : ndarray, uint8 or uint16, shape (H, W, C)
        C = 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA).
    transparent : ndarray of shape (C,) or None
        The ``tRNS`` colour (pixels equal to it are fully transparent), if any.
    """
    header = None
    idat = []
    transparent = None
    for kind, payload in _png_chunks(data):
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", payload)
        elif kind == b"IDAT":
            idat.append(payload)
        elif kind == b"tRNS" and header is not None and header[3] in (0, 2):
            transparent = np.frombuffer(payload, ">u2").astype(np.int64)
    if header is None:
        raise ValueError("PNG file without an IHDR header")
    width, height, depth, ctype, compression, filtering, interlace = header
    if ctype not in _PNG_CHANNELS or depth not in (8, 16):
        raise ValueError(f"PNG colour type {ctype} at {depth} bits is not supported here")
    if compression != 0 or filtering != 0:
        raise ValueError("unknown PNG compression or filter method")
    if interlace != 0:
        raise ValueError("interlaced 16-bit PNGs are not supported; save it non-interlaced")
    if width == 0 or height == 0:
        raise ValueError("empty PNG image")
    channels = _PNG_CHANNELS[ctype]
    bpp = channels * depth // 8                     # bytes per pixel
    stride = width * bpp
    try:
        raw = zlib.decompress(b"".join(idat))
    except zlib.error as exc:
        raise ValueError(f"damaged PNG image data ({exc})") from None
    if len(raw) < height * (stride + 1):
        raise ValueError("truncated PNG image data")
    rows = np.frombuffer(raw, np.uint8, count=height * (stride + 1)).reshape(height, stride + 1)
    types = rows[:, 0]
    if types.max() > 4:
        raise ValueError(f"unknown PNG filter type {int(types.max())}")
    pixels = _unfilter(rows[:, 1:].reshape(height, width, bpp), types)
    if depth == 16:
        samples = pixels.reshape(height, width * channels, 2)
        samples = (samples[..., 0].astype(np.uint16) << 8) | samples[..., 1]
        samples = samples.reshape(height, width, channels)
    else:
        samples = pixels.reshape(height, width, channels)
    return samples, transparent


def _unfilter(filtered, types):
    """Undo the PNG row filters of an (H, W, bpp) uint8 array; ``types`` per row.

    Each byte is ``filtered + predictor(a, b, c)`` (mod 256), with ``a`` the byte to
    the left (a pixel earlier), ``b`` above and ``c`` above-left: a recurrence along
    rows *and* columns. Pixels on one anti-diagonal ``y + x = d`` depend only on
    earlier diagonals, so the image is reconstructed one diagonal at a time, each a
    vector operation: H + W steps whatever the filter types. Rows filtered with
    None, Sub or Up only are done first with whole-row operations where possible.
    """
    H, W, bpp = filtered.shape
    out = np.zeros((H + 1, W + 1, bpp), dtype=np.uint8)  # a zero row and column of padding
    simple = bool(np.all(types <= 2))
    if simple:
        for y in range(H):
            t = types[y]
            f = filtered[y]
            if t == 0:
                out[y + 1, 1:] = f
            elif t == 1:
                out[y + 1, 1:] = np.cumsum(f, axis=0, dtype=np.uint64) % 256
            else:
                out[y + 1, 1:] = f + out[y, 1:]     # uint8 arithmetic wraps mod 256
        return out[1:, 1:]
    types = types.astype(np.int64)
    f16 = filtered.astype(np.int16)
    for d in range(H + W - 1):
        y = np.arange(max(0, d - W + 1), min(H - 1, d) + 1)
        x = d - y
        a = out[y + 1, x].astype(np.int16)          # left
        b = out[y, x + 1].astype(np.int16)          # above
        c = out[y, x].astype(np.int16)              # above-left
        t = types[y][:, None]
        p = a + b - c
        pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
        paeth = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
        pred = np.select([t == 1, t == 2, t == 3, t == 4],
                         [a, b, (a + b) >> 1, paeth], 0)
        out[y + 1, x + 1] = (f16[y, x] + pred) & 0xFF
    return out[1:, 1:]


def _read_png16(path):
    samples, transparent = decode_png(path.read_bytes())
    h, w, channels = samples.shape
    scale = np.float32(65535.0)
    colour = samples[..., :3] if channels >= 3 else np.repeat(samples[..., :1], 3, axis=2)
    rgb = colour.astype(np.float32) / scale
    alpha = None
    if channels in (2, 4):
        alpha = samples[..., -1].astype(np.float32) / scale
    elif transparent is not None and transparent.size == channels:
        alpha = np.where(np.all(samples == transparent, axis=-1), 0.0, 1.0).astype(np.float32)
    mode = {1: "L", 2: "LA", 3: "RGB", 4: "RGBA"}[channels]
    return rgb, alpha, ImageInfo("PNG", 16, mode, w, h)


# -- writing ---------------------------------------------------------------------------


def _quantise(values, bits):
    top = (1 << bits) - 1
    v = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise ValueError("image contains NaN or infinite values")
    return np.rint(np.clip(v, 0.0, 1.0) * top).astype(np.uint8 if bits == 8 else np.uint16)


def write_image(path, rgb, alpha=None, bits=8):
    """Write float RGB in [0, 1] (and optional alpha) to an image file.

    Parameters
    ----------
    path : str or os.PathLike
        ``.png`` (8 or 16 bits), ``.jpg``/``.jpeg`` (8 bits, no alpha: it is
        dropped) or ``.tif``/``.tiff`` (8 bits). The file is written to a
        temporary name in the same folder and renamed into place, so a failed
        write leaves no partial file.
    rgb : array_like, shape (H, W, 3)
        Values in [0, 1] (clipped), stored as ``round(v * (2**bits - 1))``.
    alpha : array_like, shape (H, W), optional
    bits : {8, 16}

    Raises
    ------
    ValueError
        Unknown extension, bad shapes, 16 bits for a format other than PNG.
    OSError
        The file cannot be written.
    """
    path = pathlib.Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ValueError(f"cannot write {str(path)!r}: unknown image type "
                         f"(use one of {', '.join(sorted(FORMATS))})")
    if bits not in (8, 16):
        raise ValueError(f"bits must be 8 or 16, got {bits!r}")
    if bits == 16 and fmt != "PNG":
        raise ValueError(f"cannot write {str(path)!r}: 16 bits are supported for PNG only")
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.shape[0] == 0 or rgb.shape[1] == 0:
        raise ValueError(f"rgb must have shape (H, W, 3), got {rgb.shape}")
    samples = _quantise(rgb, bits)
    if alpha is not None and fmt != "JPEG":
        alpha = np.asarray(alpha)
        if alpha.shape != rgb.shape[:2]:
            raise ValueError(f"alpha must have shape {rgb.shape[:2]}, got {alpha.shape}")
        samples = np.concatenate([samples, _quantise(alpha, bits)[..., None]], axis=2)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        if bits == 16:
            tmp.write_bytes(encode_png(samples))
        else:
            from PIL import Image

            Image.fromarray(samples, "RGBA" if samples.shape[2] == 4 else "RGB").save(
                tmp, format=fmt, **({"quality": 95} if fmt == "JPEG" else {}))
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _chunk(kind, payload):
    return (struct.pack(">I", len(payload)) + kind + payload
            + struct.pack(">I", zlib.crc32(kind + payload)))


def encode_png(samples, level=6, filter_type=None):
    """PNG bytes of integer samples (H, W, C), uint8 or uint16, C in 1..4.

    Each row gets the filter (0 None, 1 Sub, 2 Up, 3 Average or 4 Paeth) whose
    output has the smallest sum of absolute values as signed bytes (the heuristic
    recommended by the PNG specification, section 12.8), or ``filter_type`` for
    every row when it is given.
    """
    samples = np.asarray(samples)
    if samples.ndim != 3 or samples.shape[2] not in (1, 2, 3, 4):
        raise ValueError(f"samples must have shape (H, W, 1..4), got {samples.shape}")
    if samples.dtype == np.uint8:
        depth = 8
        raw = samples
    elif samples.dtype == np.uint16:
        depth = 16
        raw = samples.astype(">u2").view(np.uint8)
    else:
        raise ValueError(f"samples must be uint8 or uint16, got {samples.dtype}")
    H, W, C = samples.shape
    ctype = {1: 0, 2: 4, 3: 2, 4: 6}[C]
    bpp = C * depth // 8
    x = raw.reshape(H, W * bpp).astype(np.int16)
    a = np.zeros_like(x)
    a[:, bpp:] = x[:, :-bpp]
    b = np.zeros_like(x)
    b[1:] = x[:-1]
    c = np.zeros_like(x)
    c[1:, bpp:] = x[:-1, :-bpp]
    p = a + b - c
    pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
    paeth = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
    candidates = np.stack([x, x - a, x - b, x - ((a + b) >> 1), x - paeth]) & 0xFF  # (5, H, n)
    cost = np.abs(candidates.astype(np.uint8).view(np.int8).astype(np.int64)).sum(axis=2)
    best = np.argmin(cost, axis=0) if filter_type is None else np.full(H, int(filter_type))
    rows = candidates[best, np.arange(H)].astype(np.uint8)
    body = np.concatenate([best.astype(np.uint8)[:, None], rows], axis=1)
    header = struct.pack(">IIBBBBB", W, H, depth, ctype, 0, 0, 0)
    return (_PNG_SIGNATURE + _chunk(b"IHDR", header)
            + _chunk(b"IDAT", zlib.compress(body.tobytes(), level)) + _chunk(b"IEND", b""))
