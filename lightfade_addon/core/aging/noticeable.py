"""Years until a just-noticeable fade, per texel: the CCI Light Damage Calculator's
question (how long until a visible change?) answered for every texel of a texture.

A texel's colour moves away from its original as its dose grows; by reciprocity its
dose is its annual rate times the years, so the answer is one number per texel: the
first number of years at which the CIEDE2000 difference between the aged and the
original colour reaches a threshold (1 by default: a just-noticeable difference).
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import XYZ_to_Lab, delta_E_2000, linear_srgb_to_XYZ, srgb_decode

__all__ = ["years_to_noticeable", "JND_DELTA_E00"]

#: CIEDE2000 difference taken as just noticeable.
JND_DELTA_E00 = 1.0


def _Lab(rgb, encoding):
    lin = srgb_decode(np.clip(rgb, 0.0, 1.0)) if encoding == "srgb" else rgb
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(lin, dtype=float)))


def years_to_noticeable(ager, threshold=JND_DELTA_E00, steps=64, first=1e-5):
    """Years until each texel of ``ager``'s texture is ``threshold`` ΔE00 from new.

    Parameters
    ----------
    ager : core.aging.TextureAger
        The texture, its recipe and its lights (dose rates per texel).
    threshold : float
        CIEDE2000 difference, > 0 (1: just noticeable).
    steps : int
        Years evaluated, log-spaced from ``first × max_years`` to ``ager.max_years``;
        between two of them the crossing is interpolated linearly in ΔE00.
    first : float
        The smallest years evaluated, as a fraction of ``ager.max_years``.

    Returns
    -------
    ndarray, float32, the texture's shape without the channel axis
        Years; ``inf`` where the texel stays below ``threshold`` up to
        ``ager.max_years`` (an unlit texel, a very stable colourant).

    Notes
    -----
    The years axis is a dose lookup (:meth:`.aging.TextureAger.age`), never a new
    simulation.  A fade that crosses the threshold before ``first × max_years`` is
    placed by linear interpolation from zero years.

    Examples
    --------
    >>> years = years_to_noticeable(ager)                      # doctest: +SKIP
    >>> float(np.nanmin(years))                                # the first texel to show it
    """
    threshold = float(threshold)
    if not (np.isfinite(threshold) and threshold > 0):
        raise ValueError(f"threshold must be a finite number > 0, got {threshold!r}")
    shape = ager.original.shape[:-1]
    original = ager.original.reshape(-1, 3)
    Lab0 = _Lab(original, ager.encoding)
    n = original.shape[0]
    result = np.full(n, np.inf)
    prev_years, prev_dE = 0.0, np.zeros(n)
    for years in ager.max_years * np.logspace(np.log10(first), 0.0, int(steps)):
        todo = ~np.isfinite(result)
        if not todo.any():
            break
        aged = ager.age(years).reshape(-1, 3)
        dE = np.asarray(delta_E_2000(Lab0, _Lab(aged, ager.encoding)))
        cross = todo & (dE >= threshold)
        if cross.any():
            span = np.maximum(dE[cross] - prev_dE[cross], 1e-12)
            t = np.clip((threshold - prev_dE[cross]) / span, 0.0, 1.0)
            result[cross] = prev_years + t * (years - prev_years)
        prev_years, prev_dE = years, dE
    return result.astype(np.float32).reshape(shape)
