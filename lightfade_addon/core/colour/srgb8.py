"""Linear colour to 8-bit sRGB codes through a small table, exactly as the formula.

A byte image in an sRGB colour space is given encoded floats that Blender rounds to a
code, ``floor(255 · e + 0.5)`` clamped to [0, 255] (``unit_float_to_uchar_clamp``),
with ``e`` the sRGB transfer function (IEC 61966-2-1) of the linear value in float32
(:func:`encode_srgb_f32`). A power per channel costs about as much as the aging itself;
here the code of a linear value ``x`` in [0, 1] is

    q = floor(x · K)                 (exact: K is a power of two)
    code = base[q] + (x >= next[q])

with ``base[q]`` the code at ``q / K`` and ``next[q]`` the smallest float32 whose code is
``base[q] + 1``: the thresholds between codes are at least ``1 / (255 · 12.92)`` apart
(the steepest part of the curve, its linear segment), more than a bucket ``1 / K``, so a
bucket holds at most one and the table gives the formula's code for every float32
(the thresholds are found by bisection over float32 bit patterns, the code being
non-decreasing in ``x``). Two gathers from 16 KB tables and a comparison per channel.
"""

from __future__ import annotations

import numpy as np

__all__ = ["encode_srgb_f32", "formula_codes", "srgb_codes", "srgb_code_floats"]

#: Buckets of the linear axis (a power of two: ``x · K`` is exact in float32).
K = 1 << 12


def encode_srgb_f32(linear):
    """sRGB-encoded float32 of linear values, clipped to [0, 1] (IEC 61966-2-1, in
    float32 without a copy to float64)."""
    x = np.clip(np.asarray(linear, dtype=np.float32), 0.0, 1.0)
    high = np.float32(1.055) * np.power(x, np.float32(1.0 / 2.4)) - np.float32(0.055)
    return np.where(x <= np.float32(0.0031308), np.float32(12.92) * x, high)


def formula_codes(linear):
    """The code (int) Blender stores for linear ``linear`` written encoded into a byte
    sRGB image: ``floor(255 · encode_srgb_f32(x) + 0.5)`` in float32, clamped."""
    e = encode_srgb_f32(linear)
    return np.clip(np.floor(np.float32(255.0) * e + np.float32(0.5)), 0, 255).astype(np.int32)


def _thresholds():
    """``t[c]`` (c = 0..256): the smallest float32 in [0, 1] whose code is at least
    ``c`` (``t[0] = 0``; ``t[256] = inf``): bisection over the bit patterns."""
    lo = np.zeros(255, np.int64)                                  # code < c at lo ... (or 0)
    hi = np.full(255, np.float32(1.0).view(np.int32), np.int64)   # ... code >= c at hi
    want = np.arange(1, 256)
    while np.any(hi - lo > 1):
        mid = (lo + hi) // 2
        above = formula_codes(mid.astype(np.int32).view(np.float32)) >= want
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    t = hi.astype(np.int32).view(np.float32)
    return np.concatenate([[np.float32(0.0)], t, [np.float32(np.inf)]]).astype(np.float32)


def _tables():
    t = _thresholds()
    edges = (np.arange(K + 1) / K).astype(np.float32)
    base = (np.searchsorted(t, edges, side="right") - 1).astype(np.int32)
    nxt = t[base + 1]
    # at most one threshold per bucket: the one after next lies past the bucket
    after = t[np.minimum(base + 2, 256)]
    if not np.all(after[:-1] >= edges[1:]):
        raise AssertionError("sRGB code table: a bucket holds two thresholds")
    return base.astype(np.uint8), nxt, (np.arange(256) / np.float32(255.0)).astype(np.float32)


_TABLES = []


def _get():
    if not _TABLES:
        _TABLES.append(_tables())
    return _TABLES[0]


def srgb_codes(linear, out=None):
    """uint8 sRGB codes of linear values (any shape; clipped to [0, 1], NaN as 0), equal
    to :func:`formula_codes`."""
    base, nxt, _f = _get()
    x = np.clip(np.nan_to_num(np.asarray(linear, dtype=np.float32), nan=0.0), 0.0, 1.0)
    q = (x * np.float32(K)).astype(np.int32)
    code = np.take(base, q, out=out)
    code += np.take(nxt, q) <= x
    return code


def srgb_code_floats(linear, out=None):
    """``code / 255`` (float32) of :func:`srgb_codes`: what a byte sRGB image given it
    stores as that code (``floor(255 · code / 255 + 0.5) = code``). ``out`` may be
    ``linear`` itself (in place)."""
    base, nxt, floats = _get()
    x = np.asarray(linear, dtype=np.float32)
    q = np.empty(x.shape, np.int32)
    np.multiply(np.clip(x, 0.0, 1.0), np.float32(K), out=q, casting="unsafe")
    code = np.take(base, q)
    code += np.take(nxt, q) <= x
    return np.take(floats, code, out=out)
