"""Image pixels as arrays, through Blender's own image API (``foreach_get/set``: fast)."""

from __future__ import annotations

import os
import zlib

import bpy
import numpy as np

from ..core.colour.colorimetry import srgb_decode

#: Colour spaces whose stored values LightFade can read without Blender's colour
#: management: sRGB (decoded here) and linear Rec.709 / data (taken as they are).
#: Names are compared whole (lower case): Blender 5's "sRGB Encoded AP1" and "sRGB
#: Encoded P3-D65" have the sRGB transfer function but other primaries.
SRGB_SPACES = ("srgb",)
LINEAR_SPACES = ("linear rec.709", "linear", "non-color", "raw", "linear srgb")


def read_rgba(image):
    """(H, W, 4) float32 pixels of an image (grey and RGB images padded to RGBA)."""
    w, h = image.size
    c = image.channels
    buf = np.empty(w * h * c, dtype=np.float32)
    image.pixels.foreach_get(buf)
    buf = buf.reshape(h, w, c)
    if c == 4:
        return buf
    out = np.ones((h, w, 4), dtype=np.float32)
    out[..., :3] = buf[..., :3] if c >= 3 else buf[..., :1]
    return out


def write_rgba(image, rgba):
    """Write (n, 4) or (H, W, 4) float32 pixels into ``image`` and tag it for redraw."""
    image.pixels.foreach_set(np.ascontiguousarray(rgba, dtype=np.float32).ravel())
    image.update()


def readable_colourspace(image):
    """True if LightFade reads this image's colours correctly without Cycles."""
    if image.is_float:
        return True                      # float buffers hold scene-linear values
    name = image.colorspace_settings.name.lower()
    return name in SRGB_SPACES or name in LINEAR_SPACES


#: Linear value of each 8-bit sRGB code (float32), made on first use.
_SRGB_CODES = []


def decode_srgb_bytes(values):
    """Linear float32 of sRGB byte values read as floats (``code / 255``, as Blender
    hands byte pixels out), through a 256-entry table of :func:`srgb_decode`: the
    same numbers, without a power per texel."""
    if not _SRGB_CODES:
        _SRGB_CODES.append(srgb_decode(np.arange(256) / 255.0).astype(np.float32))
    codes = np.rint(np.clip(values, 0.0, 1.0) * np.float32(255.0)).astype(np.uint8)
    return _SRGB_CODES[0][codes]


def read_linear(image):
    """(H, W, 4) float32 of an image's colour in linear Rec.709 (alpha as stored).

    Byte images in an sRGB colour space are decoded (IEC 61966-2-1); float images
    already hold scene-linear values; linear and non-colour data are taken as stored.
    """
    rgba = read_rgba(image)
    if not image.is_float and image.colorspace_settings.name.lower() in SRGB_SPACES:
        rgba[..., :3] = decode_srgb_bytes(rgba[..., :3])
    return rgba


def stored_state(image):
    """What the pixels of ``image`` are, when they are what it was loaded or generated
    from: a hashable tuple (the image, its size, buffer and colour space, and its file's
    path, size and modification time, its packed data's CRC-32, or its generator's
    settings), read without its pixels; None when they may be something else — an image
    changed since it was loaded, saved or packed (``is_dirty``: painted, baked, written
    from Python), or of another source (tiles, sequence, movie) — and must be read.

    Pixels reach a clean image only from its file, its packed data or its generator, so
    two equal states hold equal pixels (a painted image packed again has new packed
    data; saved, a file with a new modification time)."""
    if image.is_dirty or image.source not in ("FILE", "GENERATED"):
        return None
    state = (image.as_pointer(), image.name_full, image.source, tuple(image.size),
             image.is_float, image.channels, image.colorspace_settings.name, image.alpha_mode)
    if image.source == "GENERATED":
        return (*state, image.generated_type, tuple(image.generated_color),
                image.use_generated_float, image.generated_width, image.generated_height)
    if image.packed_file is not None:
        data = image.packed_file.data
        return (*state, "packed", len(data), zlib.crc32(data))
    path = bpy.path.abspath(image.filepath_raw, library=image.library)
    try:
        stat = os.stat(path)
    except OSError:
        return None
    return (*state, "file", path, stat.st_size, stat.st_mtime_ns)


def resample(a, shape):
    """Bilinear resampling of an (h, w) map to ``shape`` in UV space (texel centres)."""
    h, w = a.shape
    H, W = shape
    if (h, w) == (H, W):
        return a
    y = np.clip((np.arange(H) + 0.5) * h / H - 0.5, 0, h - 1)
    x = np.clip((np.arange(W) + 0.5) * w / W - 0.5, 0, w - 1)
    y0 = np.minimum(y.astype(int), h - 2 if h > 1 else 0)
    x0 = np.minimum(x.astype(int), w - 2 if w > 1 else 0)
    fy = (y - y0)[:, None]
    fx = (x - x0)[None, :]
    y1 = np.minimum(y0 + 1, h - 1)
    x1 = np.minimum(x0 + 1, w - 1)
    top = a[y0][:, x0] * (1 - fx) + a[y0][:, x1] * fx
    bottom = a[y1][:, x0] * (1 - fx) + a[y1][:, x1] * fx
    return top * (1 - fy) + bottom * fy
