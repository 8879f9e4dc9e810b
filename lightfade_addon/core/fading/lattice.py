"""The grid's axes: concentrations, doses, and the simplex lattice of light mixtures.

Paper, Section 5 ("selective interpolation"): fading is simulated at the nodes of a
lattice over the unmixed colourants' concentrations, the light's spectral
composition and the dose; these functions place the nodes and find, for a point,
the nodes around it and their weights.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

__all__ = ["DOSE_POWER", "DOSE_RUNGS_PER_OCTAVE", "concentration_axis", "dose_axis",
           "dose_index", "grid_max_dose", "mix_lattice", "simplex_interpolation"]

#: Spacing exponent of the dose axis: node ``k`` of ``T`` is at ``max (k / (T - 1))**3``.
#: The slider spans decades (shadows get a thousandth of the sun's dose, and a grid is
#: prepared for a century); cubic spacing puts a third of the nodes in the first 4 % of
#: the axis, where fading is fastest (see docs/grid.md).
DOSE_POWER = 3.0


def concentration_axis(m, power=1.6):
    """``m`` concentrations in [0, 1], ``(k / (m - 1)) ** power``, denser near 0."""
    if m < 2:
        raise ValueError(f"a concentration axis needs at least 2 points, got {m}")
    return np.linspace(0.0, 1.0, m) ** power


def dose_axis(T, max_dose):
    """``T`` doses in lux·h from 0 to ``max_dose``, spaced as ``(k / (T - 1))**DOSE_POWER``.

    Fading is fastest at first, so the early doses get the dense nodes; a dose
    ``D`` sits at fractional index :func:`dose_index`.
    """
    if T < 2:
        raise ValueError(f"a dose axis needs at least 2 points, got {T}")
    if not max_dose > 0:
        raise ValueError(f"max_dose must be > 0 lux·h, got {max_dose!r}")
    return max_dose * np.linspace(0.0, 1.0, T) ** DOSE_POWER


#: A grid's largest dose is a rung of a ladder of quarter octaves (see :func:`grid_max_dose`).
DOSE_RUNGS_PER_OCTAVE = 4


def grid_max_dose(dose):
    """The largest dose of a grid that must reach ``dose`` lux·h: the next rung up.

    The rungs are ``2**(k / DOSE_RUNGS_PER_OCTAVE)`` lux·h (at least 1 lux·h), so
    textures whose brightest texels get nearly the same dose (materials under one sun,
    a re-bake after a lamp moved a little) share one grid, built and stored once.  The
    axis reaches at most 19 % further than needed: with cubic spacing the nodes around
    a given dose are then at most 6 % further apart (``1.19**(1/3)``).

    Examples
    --------
    >>> grid_max_dose(1.0), grid_max_dose(1.1), grid_max_dose(0.2)
    (1.0, 1.189207115002721, 1.0)
    """
    rung = math.ceil(DOSE_RUNGS_PER_OCTAVE * math.log2(max(float(dose), 1.0)) - 1e-9)
    return 2.0 ** (rung / DOSE_RUNGS_PER_OCTAVE)


def dose_index(ratio, T):
    """Fractional index on a :func:`dose_axis` of ``T`` nodes of ``dose / max_dose``."""
    return np.clip(ratio, 0.0, 1.0) ** (1.0 / DOSE_POWER) * (T - 1)


def mix_lattice(S, q):
    """The simplex lattice: all weight vectors ``n / q`` with ``n`` summing to ``q``.

    Returns an (M, S) array, M = C(S - 1 + q, q); one row ``[1.0]`` when S = 1.
    Rows are ordered so that :func:`simplex_interpolation` can index them.
    """
    if S == 1:
        return np.ones((1, 1))
    rows = [n for n in itertools.product(range(q + 1), repeat=S) if sum(n) == q]
    return np.array(rows, dtype=float) / q


def _lattice_lookup(S, q):
    """Array from a composition's code ``sum(n_i (q + 1)**i)`` to its lattice row."""
    rows = [n for n in itertools.product(range(q + 1), repeat=S) if sum(n) == q]
    lookup = np.full((q + 1) ** S, -1, dtype=np.int64)
    radix = (q + 1) ** np.arange(S)
    for i, n in enumerate(rows):
        lookup[int(np.dot(n, radix))] = i
    return lookup, radix


def simplex_interpolation(w, q):
    """Lattice nodes and barycentric weights for mixture weights ``w``.

    Parameters
    ----------
    w : ndarray, shape (N, S)
        Non-negative weights summing to 1 (each texel's share of the dose from
        each light spectrum).
    q : int
        Lattice resolution.

    Returns
    -------
    nodes : ndarray of int, shape (N, S)
        Rows of :func:`mix_lattice` (S vertices of the enclosing lattice simplex).
    weights : ndarray, shape (N, S)
        Barycentric weights (non-negative, summing to 1).

    Notes
    -----
    Freudenthal's triangulation in cumulative coordinates ``y_i = q * sum(w[:i+1])``:
    the cube cell is split by sorting the fractional parts, which keeps every
    vertex a valid composition.
    """
    w = np.asarray(w, dtype=float)
    N, S = w.shape
    if S == 1:
        return np.zeros((N, 1), dtype=int), np.ones((N, 1))
    y = q * np.cumsum(w, axis=1)[:, :-1]                   # (N, S-1), non-decreasing
    y = np.clip(y, 0, q)
    base = np.minimum(np.floor(y), q - 1)
    frac = y - base
    # ties go to the later coordinate first, which keeps every vertex non-decreasing
    order = np.argsort(-(frac + 1e-9 * np.arange(S - 1)), axis=1, kind="stable")
    sorted_frac = np.take_along_axis(frac, order, axis=1)
    weights = np.empty((N, S))
    weights[:, 0] = 1.0 - sorted_frac[:, 0]
    weights[:, 1:-1] = sorted_frac[:, :-1] - sorted_frac[:, 1:]
    weights[:, -1] = sorted_frac[:, -1]
    lookup, radix = _lattice_lookup(S, q)
    nodes = np.empty((N, S), dtype=np.int64)
    vertex = base.copy()
    for k in range(S):
        if k > 0:
            np.put_along_axis(vertex, order[:, k - 1:k],
                              np.take_along_axis(vertex, order[:, k - 1:k], axis=1) + 1, axis=1)
        cum = np.concatenate([np.zeros((N, 1)), vertex, np.full((N, 1), q)], axis=1)
        parts = np.diff(cum, axis=1).round().astype(np.int64)
        nodes[:, k] = lookup[parts @ radix]
    return nodes, weights
