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

The bake (:meth:`.exposure.ExposureBake._finish_maps`) smooths the denoised maps of an
object, each guided by itself, once its last light group is baked: the maps share one
neighbour search.  Averaging the *raw* bake instead (unbiased, many more samples) was measured
on a real sofa and curtain under annual daylight at 8 samples: a few texels of raw
samples are still grain (p95 error at polygon centres 102 % and 89 %, against 94 % and
54 % smoothing the denoised map; ``benchmarks/real_room_bake.py``).
"""

from __future__ import annotations

import numpy as np

#: Neighbourhood radius in texels of the object's map (a disc of 25 texels on a flat part).
RADIUS_TEXELS = 3.0
#: Normals less aligned than this do not mix.
MIN_DOT = 0.6
#: Width of the range weight, in stops (log2) of the denoised value.
RANGE_STOPS = 0.7
#: Texels whose pairs are found in one batch (memory: ~13 pairs × 40 bytes each).
_CHUNK = 1 << 18


def smooth_on_surface(raw, guide, position, normal, covered, texel,
                      radius_texels=RADIUS_TEXELS, min_dot=MIN_DOT,
                      range_stops=RANGE_STOPS, floor=1e-3):
    """``raw`` averaged over its 3D neighbours on the surface, edges from ``guide`` (the
    equation above).

    Every pair of texels closer than the radius is found once (:func:`_close_pairs`;
    about twice as fast as asking each texel for its nearest ones); ``w_ij`` is
    symmetric in its three factors, so each pair adds to both texels.
    The maps of one object (one per light group) share its texels: stacked as
    ``(G, H, W)`` they share the one pair search and the distance and normal weights
    ``K · n``; only the range weight ``g`` is each map's own.

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
    m = int(np.count_nonzero(cov))
    if m == 0:
        return out[0] if single else out
    P = np.asarray(position, dtype=np.float64)[cov]
    N = np.asarray(normal, dtype=np.float32)[cov]
    B = stack(raw)[:, cov]                                     # (G, m)
    g = out[:, cov].astype(np.float64)
    top = np.percentile(g, 99, axis=1, keepdims=True)
    level = np.log2(np.maximum(g, np.maximum(top * floor, 1e-30))).astype(np.float32)
    radius = float(radius_texels) * float(texel)
    local = (P - P.mean(axis=0)).astype(np.float32)            # float32 near the object
    spread = np.float32(-0.5 / range_stops ** 2)
    total = np.ones(B.shape, dtype=np.float64)                 # the texel itself: 1
    summed = B.astype(np.float64)
    for i, j in _close_pairs(P, radius):
        step = local[i] - local[j]
        near = np.maximum(np.float32(1.0) - np.einsum("pc,pc->p", step, step)
                          * np.float32(radius ** -2), np.float32(0.0))    # K(d / r)
        dot = np.einsum("pc,pc->p", N[i], N[j])
        near *= np.clip((dot - min_dot) / (1.0 - min_dot), 0.0, 1.0).astype(np.float32)
        for k in range(B.shape[0]):
            w = near * np.exp(spread * (level[k, i] - level[k, j]) ** 2)
            total[k] += np.bincount(i, w, m) + np.bincount(j, w, m)
            summed[k] += np.bincount(i, w * B[k, j], m) + np.bincount(j, w * B[k, i], m)
    result = (summed / total).astype(np.float32)
    out[:, cov] = result
    return out[0] if single else out


def _close_pairs(points, radius, chunk=_CHUNK):
    """Every pair ``(i, j)``, ``i < j``, of ``points`` closer than ``radius``, once, in
    batches of about ``chunk`` first points (memory stays bounded on large maps): the
    points sorted along x, each batch searched with the points up to ``radius`` beyond
    it, and a pair kept by the batch holding its first point."""
    from scipy.spatial import cKDTree

    order = np.argsort(points[:, 0], kind="stable")
    x = points[order, 0]
    for lo in range(0, len(order), chunk):
        hi = min(lo + chunk, len(order))
        reach = int(np.searchsorted(x, x[hi - 1] + radius, side="right"))
        part = order[lo:reach]
        a, b = cKDTree(points[part]).query_pairs(radius, output_type="ndarray").T
        first = np.minimum(a, b) < hi - lo
        yield part[a[first]], part[b[first]]


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
