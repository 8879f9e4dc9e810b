"""Aged colours back into the displayable range: one rule for every path.

The model multiplies a texel's CIE XYZ by the modelled change; for saturated
colours near the edge of the sRGB gamut the product can leave it (a channel below 0
or above 1 in linear sRGB). Every path that writes aged colours (the Blender shell
through :class:`.aging.TextureAger`, the CLI, :func:`.exact.age_image_exact` and
:func:`.restore.restore`) maps them back with :func:`into_gamut`:

* the luminance ``Y`` (Rec. 709 weights, the Y row of sRGB → XYZ) is clipped to
  [0, 1];
* the colour is moved straight towards the neutral grey of that luminance, just far
  enough that every channel lies in [0, 1].

Moving towards the neutral is an additive mixture with grey: the chromaticity moves
on the line to the white point, so the dominant wavelength (the hue) is kept, and
so is the luminance whenever it was in range. Only the saturation drops, and only
as much as needed. Colours already in range are returned unchanged.
"""

from __future__ import annotations

import numpy as np

from .colorimetry import srgb_encode

__all__ = ["LUMA", "encode_in_gamut", "into_gamut", "into_gamut_planes", "out_of_gamut"]

#: Rec. 709 / sRGB luminance weights (the Y row of the linear sRGB → XYZ matrix).
LUMA = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)


def out_of_gamut(rgb):
    """Mask (...,) of colours (..., 3) with a channel outside [0, 1] or not finite."""
    rgb = np.asarray(rgb)
    with np.errstate(invalid="ignore"):
        return ~((rgb.min(axis=-1) >= 0) & (rgb.max(axis=-1) <= 1))     # NaN counts as out


def into_gamut(rgb, out=None):
    """Linear sRGB colours mapped into [0, 1] keeping hue (see the module docstring).

    Parameters
    ----------
    rgb : array_like, shape (..., 3)
        Linear sRGB, finite.
    out : ndarray, optional
        Where to write (may be ``rgb`` itself, for in-place mapping).

    Returns
    -------
    ndarray, shape (..., 3)
        In [0, 1], same dtype as ``rgb`` (float32 or float64).

    Raises
    ------
    ValueError
        If a value is NaN or infinite (there is no colour to map).

    Examples
    --------
    >>> into_gamut(np.array([1.2, 0.5, -0.1])).round(4).tolist()
    [1.0, 0.5355, 0.1373]
    """
    rgb = np.asarray(rgb)
    if not np.issubdtype(rgb.dtype, np.floating):
        rgb = rgb.astype(float)
    if out is None:
        out = rgb.copy()
    elif out is not rgb:
        out[...] = rgb
    flat = out if out.ndim == 2 else out.reshape(-1, 3)      # a view: 2-D may be strided
    if not np.shares_memory(flat, out):
        raise ValueError("out must be a 2-D array or contiguous")
    bad = np.flatnonzero(out_of_gamut(flat))
    if bad.size == 0:
        return out
    c = flat[bad].astype(float)
    if not np.all(np.isfinite(c)):
        raise ValueError("colour contains NaN or infinite values; cannot map it into [0, 1]")
    Y = np.clip(c @ LUMA.astype(float), 0.0, 1.0)[:, None]
    d = c - Y                                         # away from the grey of luminance Y
    with np.errstate(divide="ignore", invalid="ignore"):
        t_hi = np.where(c > 1.0, (1.0 - Y) / d, 1.0)
        t_lo = np.where(c < 0.0, -Y / d, 1.0)
    t = np.clip(np.minimum(t_hi, t_lo).min(axis=1, keepdims=True), 0.0, 1.0)
    flat[bad] = np.clip(Y + t * d, 0.0, 1.0)          # the clip only absorbs rounding
    return out


def into_gamut_planes(planes):
    """:func:`into_gamut` for colours stored as (3, k) planes, in place (fast path).

    The same rule, computed plane by plane in the planes' own dtype over only the
    columns outside [0, 1] (the slider's hot path: no transposes, no float64 copy).
    """
    lo = np.minimum(np.minimum(planes[0], planes[1]), planes[2])
    hi = np.maximum(np.maximum(planes[0], planes[1]), planes[2])
    with np.errstate(invalid="ignore"):
        bad = np.flatnonzero(~((lo >= 0) & (hi <= 1)))
    if bad.size == 0:
        return planes
    c = planes[:, bad]
    if not np.all(np.isfinite(c)):
        raise ValueError("colour contains NaN or infinite values; cannot map it into [0, 1]")
    luma = LUMA.astype(c.dtype)
    Y = np.clip(luma[0] * c[0] + luma[1] * c[1] + luma[2] * c[2], 0.0, 1.0)
    d = c - Y
    t = np.ones_like(Y)
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(3):
            tk = np.where(c[k] > 1.0, (1.0 - Y) / d[k], np.where(c[k] < 0.0, -Y / d[k], 1.0))
            np.minimum(t, tk, out=t)
    np.clip(t, 0.0, 1.0, out=t)
    planes[:, bad] = np.clip(Y + t * d, 0.0, 1.0)
    return planes


def encode_in_gamut(linear, encoding="linear"):
    """Linear sRGB into [0, 1] (:func:`into_gamut`, in place), then encoded.

    The last step of every path that writes aged colours.

    Parameters
    ----------
    linear : ndarray, shape (..., 3)
        Linear sRGB, finite; overwritten.
    encoding : {"linear", "srgb"}

    Returns
    -------
    ndarray, shape (..., 3)
        In [0, 1] in ``encoding``.
    """
    into_gamut(linear, out=linear)
    if encoding == "srgb":
        return srgb_encode(linear)
    return linear
