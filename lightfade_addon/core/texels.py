"""Texel colours to colourant concentrations, with a bounded number of distinct rows.

A texture's aging table has one row per distinct *key*; unmixing (a Gauss–Newton
solve per colour, :mod:`.unmix`) is the expensive step, so at most ``max_keys``
colours are solved exactly:

* up to ``max_keys`` distinct colours (as given, float32): each is unmixed exactly
  and is its own key;
* else up to ``max_keys`` distinct 8-bit colours: the same, on the colours rounded
  to 8 bits;
* more (photographs, noise, 16-bit and float textures): every distinct 8-bit colour
  is unmixed exactly up to :data:`UNMIX_BUDGET` colours; beyond, the colours are
  gathered in bins of fewer bits, each bin's centre is unmixed exactly, and every
  colour gets its own concentrations by a linear step from its bin's solution,
  ``c = c_bin + dc/dLab · (Lab - Lab_bin)`` (:meth:`.unmix.Unmixer.slope`). The
  keys are then bins in *concentration* space (as fine as ``max_keys`` allows),
  where the modelled change is smooth, not in colour space, where the unmixing
  is not.

``benchmarks/photos.py`` measures the error of both paths against the exact one.
"""

from __future__ import annotations

import numpy as np

from .colorimetry import XYZ_to_Lab, linear_srgb_to_XYZ, srgb_decode

__all__ = ["MAX_KEYS", "UNMIX_BUDGET", "UNMIX_REFINE", "texel_concentrations"]

#: Most colours unmixed exactly per texture (and most rows per dose interval).
MAX_KEYS = 1 << 16
#: Most colours unmixed exactly per texture; more take a linear step from a bin's
#: solution (:func:`_linearised`).
UNMIX_BUDGET = 1 << 17
#: Gauss–Newton iterations of each exact unmixing (from the unmixer's table).
UNMIX_REFINE = 2
#: Finest quantisation of a concentration axis for keys (levels over [0, 1]).
_C_LEVELS = 1024


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


def _Lab(encoded):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(encoded)))


def _linearised(colours, unmixer, refine):
    """Concentrations of many colours from at most :data:`UNMIX_BUDGET` exact solves:
    bins of fewer bits, each colour a linear step from its bin centre's solution."""
    for drop in range(1, 8):
        bins, member = np.unique(_codes(colours, drop), return_inverse=True)
        if bins.size <= UNMIX_BUDGET:
            break
    member = member.reshape(-1)
    centres = _decode(bins, drop)
    c_bin = unmixer.unmix(centres, encoded=True, refine=refine)
    slope = unmixer.slope(c_bin)                                     # (B, Cu, 3)
    step = _Lab(colours) - _Lab(centres)[member]
    return np.clip(c_bin[member] + np.einsum("nki,ni->nk", slope[member], step), 0.0, 1.0)


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
        Gauss–Newton iterations of the exact solves.

    Returns
    -------
    key : ndarray of int32, shape (n,)
    c : ndarray, shape (K, Cu)
        Concentrations of the unmixed colourants per key, K <= ``max_keys``.
    """
    max_keys = MAX_KEYS if max_keys is None else int(max_keys)
    if unmixer.Cu == 0:
        return np.zeros(rgb_encoded.shape[0], dtype=np.int32), np.zeros((1, 0))
    codes, inverse = np.unique(_codes(rgb_encoded), return_inverse=True)
    inverse = inverse.reshape(-1).astype(np.int32)
    if codes.size <= max_keys:
        exact, which = np.unique(rgb_encoded, axis=0, return_inverse=True)
        if exact.shape[0] <= max_keys:
            return which.reshape(-1).astype(np.int32), unmixer.unmix(exact, encoded=True,
                                                                     refine=refine)
        return inverse, unmixer.unmix(_decode(codes), encoded=True, refine=refine)
    colours = _decode(codes)
    if codes.size <= UNMIX_BUDGET:
        c = unmixer.unmix(colours, encoded=True, refine=refine)
    else:
        c = _linearised(colours, unmixer, refine)
    # keys: concentration bins, the finest that give at most max_keys
    levels = _C_LEVELS
    while True:
        q = np.rint(np.sqrt(c) * (levels - 1)).astype(np.int64)   # finer near 0, like the grid
        flat = np.ravel_multi_index(q.T, (levels,) * c.shape[1])
        keys, which = np.unique(flat, return_inverse=True)
        if keys.size <= max_keys or levels <= 2:
            break
        levels = int(levels / 1.25)          # merge gently: fewer keys, small bins
    which = which.reshape(-1)
    counts = np.bincount(which, minlength=keys.size)[:, None]
    c_key = np.stack([np.bincount(which, c[:, k], keys.size) for k in range(c.shape[1])], 1)
    return which[inverse].astype(np.int32), c_key / counts
