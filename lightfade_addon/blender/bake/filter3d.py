"""Smoothing a baked map over its neighbours on the surface, in 3D, not in the atlas.

A map's texels are places on the object (:class:`.uvmaps.TexelGeometry`).  Texels that
lie side by side in the atlas may be far apart on the object (two islands packed
together), and texels next to each other on the object may be far apart in the atlas
(the two sides of a seam, the strips a fold or a cushion is cut into).  OIDN sees only
the atlas: each island is denoised on its own, so neighbouring islands come out at
levels that differ by their own blotches, and a small island has few texels to average.
Here each texel's value is averaged with the values of the texels within a few texels
of it *in 3D*, whichever island they are in:

    E_i = Σ_j w_ij B_j / Σ_j w_ij,        w_ij = K(d_ij / r) · n(N_i · N_j) · g(i, j)

``K(x) = max(1 - x², 0)`` (Epanechnikov) on the 3D distance ``d_ij``, ``r`` a few
texels; ``n`` a ramp from 0 at ``N_i · N_j = min_dot`` to 1 at 1 (the two sides of a
curtain, a cushion against the arm it touches, do not mix); ``g`` a Gaussian in the
log2 ratio of the guide's values (``range_stops`` wide): where the denoiser saw an edge
(a shadow, the sun patch through a window), texels either side do not mix.  A fit
linear in the normal (``B ≈ a + b · ΔN``, to keep a fold's shading) measured no better
on a real sofa and curtain and cost 3.4× the time; the normal ramp keeps the mean to
texels that face nearly the same way.

The bake (:meth:`.passes.Passes.finish`) smooths the denoised maps of an object, each
guided by itself (each pass of an adaptive bake too), once its last light group (or
pass) of a round is baked: the maps share one neighbour search.  Averaging the *raw* bake instead (unbiased, many more samples) was measured
on a real sofa and curtain under annual daylight at 8 samples: a few texels of raw
samples are still grain (p95 error at polygon centres 102 % and 89 %, against 94 % and
54 % smoothing the denoised map; ``benchmarks/real_room_bake.py``).
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

#: Neighbourhood radius in texels of the object's map (a disc of ~28 texels on a flat part).
RADIUS_TEXELS = 3.0
#: Neighbours looked at per texel (the disc; other surfaces within reach take places).
NEIGHBOURS = 32
#: Normals less aligned than this do not mix.
MIN_DOT = 0.6
#: Width of the range weight, in stops (log2) of the denoised value.
RANGE_STOPS = 0.7
#: Texels per query chunk (memory: ~ NEIGHBOURS × 40 bytes each, per thread).
_CHUNK = 65536
#: Chunks filtered at once (threads).
_THREADS = min(os.cpu_count() or 1, 4)


def smooth_on_surface(raw, guide, position, normal, covered, texel,
                      radius_texels=RADIUS_TEXELS, neighbours=NEIGHBOURS, min_dot=MIN_DOT,
                      range_stops=RANGE_STOPS, floor=1e-3, tree=None):
    """``raw`` averaged over its 3D neighbours on the surface, edges from ``guide`` (the
    equation above).

    The maps of one object (one per light group) share its texels: stacked as
    ``(G, H, W)`` they share one neighbour search and one set of distance and normal
    weights ``K · n``; only the range weight ``g`` is each map's own.

    Parameters
    ----------
    raw : ndarray, shape (H, W) or (G, H, W)
        The values to average (the raw bake, or the denoised map); any unit.
    guide : ndarray, shape like ``raw``
        The map denoised (where the edges are); same unit.
    position, normal : ndarray, shape (H, W, 3)
        World position (m) and unit normal of each covered texel.
    covered : ndarray of bool, shape (H, W)
        Texels whose centre lies on the surface.
    texel : float
        World size of a texel (m); the radius is ``radius_texels × texel``.
    floor : float
        Guide values below ``floor`` × its 99th percentile count as that (dark texels
        of one shadow are alike).
    tree : scipy.spatial.cKDTree, optional
        :func:`search_tree` of these texels, when the caller has it already.

    Returns
    -------
    ndarray, shape like ``raw``, float32
        Covered texels: the weighted mean; others: ``guide``.
    """
    single = np.ndim(guide) == 2
    stack = (lambda a: np.asarray(a, dtype=np.float32)[None]) if single else (
        lambda a: np.asarray(a, dtype=np.float32))
    out = stack(guide).copy()
    cov = np.asarray(covered, bool)
    if np.count_nonzero(cov):
        out[:, cov] = _smooth(stack(raw), stack(guide), position, normal, cov, cov, texel,
                              radius_texels, neighbours, min_dot, range_stops, floor, tree)
    return out[0] if single else out


def smooth_at(raw, guide, position, normal, covered, query, texel, **options):
    """:func:`smooth_on_surface` of ``raw`` (G, H, W) at the ``query`` texels only (a bool
    (H, W) mask inside ``covered``): (G, q) float32, in the order of ``query``'s texels.
    The neighbours are all covered texels; only the queries are searched (a sample of
    a map filtered at a fraction of the cost)."""
    raw, guide = np.asarray(raw, np.float32), np.asarray(guide, np.float32)
    covered = np.asarray(covered, bool)
    if not covered.any():
        return np.zeros((raw.shape[0], 0), np.float32)
    return _smooth(raw, guide, position, normal, covered, np.asarray(query, bool) & covered,
                   texel, **options)


def search_tree(position, covered):
    """The neighbour search's k-d tree of the ``covered`` texels' positions: an object's
    filters in one :meth:`.passes.Passes.finish` share it."""
    from scipy.spatial import cKDTree

    return cKDTree(np.asarray(position, dtype=np.float64)[np.asarray(covered, bool)])


def _smooth(raw, guide, position, normal, cov, query, texel, radius_texels=RADIUS_TEXELS,
            neighbours=NEIGHBOURS, min_dot=MIN_DOT, range_stops=RANGE_STOPS, floor=1e-3,
            tree=None):
    """The equation above at the ``query`` texels of the ``cov`` texels ((H, W) masks) of
    the stacked maps ``raw``, ``guide`` (G, H, W): (G, q)."""
    m = int(np.count_nonzero(cov))
    P = np.asarray(position, dtype=np.float64)[cov]
    N = np.asarray(normal, dtype=np.float32)[cov]
    B = raw[:, cov].T                                          # (m, G)
    shared = guide.shape[0] > 1 and guide.strides[0] == 0     # one guide for every map
    g = guide[:1 if shared else None, cov].T.astype(np.float64)
    top = np.percentile(g, 99, axis=0)
    level = np.log2(np.maximum(g, np.maximum(top * floor, 1e-30))).astype(np.float32)
    at = np.flatnonzero(query[cov])                            # the queries among them
    radius = float(radius_texels) * float(texel)
    spread = np.float32(-0.5 / range_stops ** 2)
    tree = search_tree(position, cov) if tree is None else tree
    k = min(int(neighbours), m)
    result = np.empty((at.size, B.shape[1]), dtype=np.float32)

    def chunk(start):
        rows = slice(start, min(start + _CHUNK, at.size))
        own = at[rows]
        dist, idx = tree.query(P[own], k=k, distance_upper_bound=radius)
        idx = idx.reshape(-1, k)
        idx[idx >= m] = 0                            # not found: distance inf, weight 0
        near = _epanechnikov(dist.reshape(-1, k), radius)
        dot = np.einsum("ic,ijc->ij", N[own], N[idx])
        near *= np.clip((dot - min_dot) / (1.0 - min_dot), 0.0, 1.0)
        for r in range(B.shape[1]):
            if r == 0 or not shared:
                w = level[:, r][idx]                 # in place: the chunk's arrays are large
                w -= level[own, r, None]
                np.square(w, out=w)
                w *= spread
                np.exp(w, out=w)
                w *= near
                w[:, 0] = np.maximum(w[:, 0], 1e-6)  # the texel itself (distance 0) counts
                total = w.sum(axis=1)
            result[rows, r] = np.einsum("ij,ij->i", w, B[:, r][idx]) / total

    # chunks side by side: the search and numpy's loops release the GIL, rows are disjoint
    with ThreadPoolExecutor(max_workers=_THREADS) as pool:
        list(pool.map(chunk, range(0, at.size, _CHUNK)))
    return result.T


def _epanechnikov(dist, radius):
    """``K(d / r) = max(1 - (d / r)², 0)`` as float32, computed in place (``inf``, a
    neighbour not found, gives 0)."""
    w = dist.astype(np.float32)
    w *= np.float32(1.0 / radius)
    np.square(w, out=w)
    np.subtract(np.float32(1.0), w, out=w)
    return np.maximum(w, np.float32(0.0), out=w)


def extend_over_margin(values, covered, inside):
    """Texels ``inside`` the grown islands but not ``covered`` take the value of the
    nearest covered texel (the bake margin, for filtering at island borders)."""
    from scipy.ndimage import distance_transform_edt

    if not np.any(covered):
        return values
    _, (rows, cols) = distance_transform_edt(~covered, return_indices=True)
    out = values.copy()
    margin = inside & ~covered
    out[margin] = values[rows[margin], cols[margin]]
    return out
