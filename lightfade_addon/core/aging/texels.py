"""Texel colours to colourant concentrations, with a bounded number of distinct rows.

A texture's aging table has one row per distinct *key* (at most ``max_keys``:
memory), and unmixing (a Gauss–Newton solve per colour, :mod:`.unmix`) is the
expensive step (at most :data:`UNMIX_BUDGET` solves: time):

* up to ``max_keys`` distinct colours (as given, float32): each is unmixed exactly
  and is its own key;
* more (photographs, noise, 16-bit and float textures): every distinct colour is
  unmixed exactly, as ``age-image --exact`` does, up to :data:`UNMIX_BUDGET`
  colours; beyond, the colours are gathered in 8-bit bins (or of fewer bits, as
  the budget needs), each bin's centre is unmixed exactly, and every
  colour gets its own concentrations by a linear step from its bin's solution,
  ``c = c_bin + dc/dLab · (Lab - Lab_bin)`` (:meth:`.unmix.Unmixer.slope`). The
  keys are then bins in *concentration* space (as fine as ``max_keys`` allows,
  :func:`_keys`), where the modelled change is smooth, not in colour space, where
  the unmixing is not.

``benchmarks/photos.py`` measures the error of both paths against the exact one.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import XYZ_to_Lab, linear_srgb_to_XYZ, srgb_decode

__all__ = ["MAX_KEYS", "UNMIX_BUDGET", "UNMIX_REFINE", "aging_refine", "texel_concentrations"]

#: Most keys per texture by default (:class:`.aging.TextureAger` sets its own from
#: the size of its table, :data:`.aging.TABLE_ROWS`).
MAX_KEYS = 1 << 17
#: Most colours unmixed exactly per texture (about 40 s on one core for this many);
#: more take a linear step from a bin's solution (:func:`_linearised`).
UNMIX_BUDGET = 1 << 20
#: Colours unmixed per call (bounds the solver's (n, wavelengths) temporaries).
_UNMIX_BLOCK = 1 << 16
#: Newton steps of each exact unmixing from the unmixer's table, for recipes of three
#: unmixed colourants (:attr:`.unmix.Unmixer.square`); with fewer, every colour is
#: solved to convergence, as ``age-image --exact`` does.
UNMIX_REFINE = 2
#: Side of the finest key bin, in sqrt(concentration) (:func:`_keys`).
_FINEST_BIN = 1e-3


def _codes(rgb_encoded, drop=0):
    """24-bit codes of 8-bit colours with ``drop`` low bits removed per channel."""
    code = np.zeros(rgb_encoded.shape[0], dtype=np.int32)
    for ch in range(3):
        q = np.clip(np.rint(rgb_encoded[:, ch] * 255.0), 0, 255).astype(np.int32) >> drop
        code |= q << (8 * (2 - ch))
    return code


def _decode(codes, drop=0):
    """Bin centres (encoded sRGB in [0, 1]) of :func:`_codes`."""
    scale = 1 << drop
    colours = np.stack([(codes >> 16) & 255, (codes >> 8) & 255, codes & 255], -1)
    return np.clip((colours * scale + (scale - 1) / 2.0) / 255.0, 0.0, 1.0)


def _distinct(rgb_encoded):
    """Distinct colours (float32 rows, sorted) and each texel's row: through 24-bit
    codes when every value is an 8-bit level (most textures), else by the rows' bytes."""
    rgb = np.ascontiguousarray(rgb_encoded, dtype=np.float32).reshape(-1, 3)
    codes = _codes(rgb)
    if np.array_equal(_decode(codes).astype(np.float32), rgb):
        values, inverse = np.unique(codes, return_inverse=True)
        return _decode(values).astype(np.float32), inverse.reshape(-1).astype(np.int32)
    rows, inverse = np.unique(rgb.view(np.dtype((np.void, 12))).ravel(), return_inverse=True)
    return (np.frombuffer(rows.tobytes(), np.float32).reshape(-1, 3),
            inverse.reshape(-1).astype(np.int32))


def _Lab(encoded):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(encoded)))


def _unmix(colours, unmixer, refine):
    """:meth:`.unmix.Unmixer.unmix` of encoded colours, in blocks."""
    return np.concatenate([unmixer.unmix(colours[s:s + _UNMIX_BLOCK], encoded=True,
                                         refine=refine)
                           for s in range(0, colours.shape[0], _UNMIX_BLOCK)]
                          or [np.zeros((0, unmixer.Cu))])


def _linearised(colours, unmixer, refine):
    """Concentrations of many colours from at most :data:`UNMIX_BUDGET` exact solves:
    bins of fewer bits, each colour a linear step from its bin centre's solution."""
    for drop in range(0, 8):
        bins, member = np.unique(_codes(colours, drop), return_inverse=True)
        if bins.size <= UNMIX_BUDGET:
            break
    member = member.reshape(-1)
    centres = _decode(bins, drop)
    c_bin = _unmix(centres, unmixer, refine)
    slope = unmixer.slope(c_bin)                                     # (B, Cu, 3)
    step = _Lab(colours) - _Lab(centres)[member]
    return np.clip(c_bin[member] + np.einsum("nki,ni->nk", slope[member], step), 0.0, 1.0)


def aging_refine(unmixer, refine=UNMIX_REFINE):
    """The ``refine`` of :meth:`.unmix.Unmixer.unmix` that aging unmixes ``unmixer``'s
    colours with: ``refine`` Newton steps when the unmixing is square
    (:attr:`.unmix.Unmixer.square`), else None (to convergence, as ``--exact``)."""
    return refine if unmixer.square else None


def texel_concentrations(rgb_encoded, unmixer, max_keys=None, refine=UNMIX_REFINE):
    """Concentrations per key and each texel's key.

    Parameters
    ----------
    rgb_encoded : ndarray, shape (n, 3)
        Encoded sRGB in [0, 1].
    unmixer : Unmixer
    max_keys : int, optional
        Most distinct keys; default :data:`MAX_KEYS`.
    refine : int
        Newton steps of the exact solves (Eq. U1 from the unmixer's table) when the
        unmixing is square (:attr:`.unmix.Unmixer.square`: three unmixed colourants,
        quadratic convergence). With fewer (bare wood: one), a colour off the recipe's
        curve is a least-squares solution that a few steps leave far from converged
        (sky blues at 0.2 of extractive instead of none, ΔE00 up to 12 after 15 years
        under fluorescent light), so every colour is solved to convergence there,
        as ``--exact`` does (cheap: :meth:`.unmix.Unmixer.XYZ` tabulates the curve).

    Returns
    -------
    key : ndarray of int32, shape (n,)
    c : ndarray, shape (K, Cu)
        Concentrations of the unmixed colourants per key, K <= ``max_keys``.
    """
    max_keys = MAX_KEYS if max_keys is None else int(max_keys)
    refine = aging_refine(unmixer, refine)
    if unmixer.Cu == 0:
        return np.zeros(rgb_encoded.shape[0], dtype=np.int32), np.zeros((1, 0))
    colours, inverse = _distinct(rgb_encoded)
    if colours.shape[0] <= max_keys:
        return inverse, _unmix(colours, unmixer, refine)
    c = (_unmix(colours, unmixer, refine)                # each solved as --exact does
         if colours.shape[0] <= UNMIX_BUDGET else _linearised(colours, unmixer, refine))
    which, c_key = _keys(c, max_keys)
    return which[inverse], c_key


def _keys(c, max_keys):
    """Gather solutions ``c`` (N, Cu) into at most ``max_keys`` keys: each key's
    concentrations (the mean of its members) and each solution's key.

    The bins are cubes in ``sqrt(c)`` (finer near 0, like the grid's axes), the
    finest (from a side of :data:`_FINEST_BIN`) that give at most ``max_keys``.
    """
    root = np.sqrt(c)

    def binned(width):
        levels = int(np.floor(1.0 / width)) + 1
        q = np.minimum(np.floor(root / width).astype(np.int64), levels - 1)
        return np.unique(np.ravel_multi_index(q.T, (levels,) * c.shape[1]),
                         return_inverse=True)

    # the finest side that gives at most max_keys, to a factor 1.1: doubling, then bisection
    fine, coarse = None, _FINEST_BIN
    while (found := binned(coarse))[0].size > max_keys:
        fine, coarse = coarse, 2 * coarse
    while fine is not None and coarse / fine > 1.1:
        middle = np.sqrt(fine * coarse)
        trial = binned(middle)
        if trial[0].size <= max_keys:
            coarse, found = middle, trial
        else:
            fine = middle
    keys, which = found
    which = which.reshape(-1).astype(np.int32)
    counts = np.bincount(which, minlength=keys.size)[:, None]
    c_key = np.stack([np.bincount(which, c[:, k], keys.size) for k in range(c.shape[1])], 1)
    return which, c_key / counts
