"""UV triangles on the texel grid (numpy): coverage counts and island labels.

Texel ``(row, col)`` of an ``N × N`` map has its centre at ``u = (col + 0.5) / N``,
``v = (row + 0.5) / N`` (Blender's images run bottom-up, like ``v``).  A texel belongs
to a triangle when its centre lies strictly inside (all barycentric weights above a small
tolerance), so that texels on an edge two triangles share count once or not at all.
"""

from __future__ import annotations

import numpy as np

_EPS = 1e-6
_CHUNK = 1 << 22  # candidate texels per numpy pass (memory bound)


def _candidates(tri, size):
    """Per-triangle bounding boxes in texels: ``(x0, y0, w, h)`` int arrays."""
    lo = np.floor(tri.min(axis=1) * size - 0.5).astype(np.int64) + 1
    hi = np.floor(tri.max(axis=1) * size - 0.5).astype(np.int64)
    lo = np.clip(lo, 0, size)
    hi = np.clip(hi, -1, size - 1)
    extent = np.maximum(hi - lo + 1, 0)
    return lo[:, 0], lo[:, 1], extent[:, 0], extent[:, 1]


def covered_texels(tri, size, strict=True):
    """The texels each UV triangle covers, in chunks (memory bound).

    Yields ``(t, flat)`` int arrays: triangle index and texel index ``row * size + col``
    of every (triangle, texel) pair whose centre lies inside (strictly inside with
    ``strict``, else also on an edge); see :func:`rasterise`.
    """
    tri = np.asarray(tri, dtype=np.float64)
    if len(tri) == 0:
        return
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    den = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    x0, y0, w, h = _candidates(tri, size)
    n = w * h
    keep = np.flatnonzero((np.abs(den) > 1e-14) & (n > 0))
    ends = np.cumsum(n[keep])
    start = 0
    while start < len(keep):
        # as many triangles as fit the chunk (at least one)
        base = ends[start] - n[keep[start]]
        stop = max(int(np.searchsorted(ends, base + _CHUNK, side="right")), start + 1)
        idx = keep[start:stop]
        start = stop
        t = np.repeat(idx, n[idx])
        offset = np.arange(len(t)) - np.repeat(np.cumsum(n[idx]) - n[idx], n[idx])
        col = x0[t] + offset % w[t]
        row = y0[t] + offset // w[t]
        px, py = (col + 0.5) / size, (row + 0.5) / size
        l1 = ((b[t, 1] - c[t, 1]) * (px - c[t, 0]) + (c[t, 0] - b[t, 0]) * (py - c[t, 1])) / den[t]
        l2 = ((c[t, 1] - a[t, 1]) * (px - c[t, 0]) + (a[t, 0] - c[t, 0]) * (py - c[t, 1])) / den[t]
        eps = _EPS if strict else -_EPS
        inside = (l1 > eps) & (l2 > eps) & (1.0 - l1 - l2 > eps)
        yield t[inside], row[inside] * size + col[inside]


def rasterise(tri, size, labels=None, strict=True):
    """Texels covered by UV triangles.

    Parameters
    ----------
    tri : (T, 3, 2) float array
        UV coordinates of each triangle's corners (0-1 is the image).
    size : int
        Map width and height in texels.
    labels : (T,) int array, optional
        A label per triangle (e.g. its UV island).
    strict : bool
        Count only texel centres strictly inside (for overlap tests); else also those on
        an edge (for island maps without cracks along shared edges).

    Returns
    -------
    count : (size, size) int32 array
        How many triangles cover each texel (0 outside every island).
    label : (size, size) int32 array
        The label of a triangle covering the texel (-1 where none), when ``labels`` given.
    """
    count = np.zeros(size * size, dtype=np.int32)
    label = np.full(size * size, -1, dtype=np.int32) if labels is not None else None
    for t, flat in covered_texels(tri, size, strict):
        count += np.bincount(flat, minlength=size * size).astype(np.int32)
        if label is not None:
            label[flat] = labels[t]
    count = count.reshape(size, size)
    return count, None if label is None else label.reshape(size, size)


def barycentric(tri, size, label):
    """Barycentric weights of texel centres in the triangle each texel belongs to.

    Parameters
    ----------
    tri : (T, 3, 2) float array
        UV triangles.
    size : int
        Map width and height.
    label : (size, size) int array
        Triangle index per texel (-1: none), as :func:`rasterise` gives with
        ``labels=np.arange(T)``.

    Returns
    -------
    (size, size, 3) float64 array
        Weights of the triangle's corners (zero where ``label`` is -1); a point ``X``
        given per corner is ``Σ_k w_k X_k``.
    """
    tri = np.asarray(tri, dtype=np.float64)
    out = np.zeros((size, size, 3))
    row, col = np.nonzero(label >= 0)
    t = label[row, col]
    a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]
    px, py = (col + 0.5) / size, (row + 0.5) / size
    den = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    l1 = ((b[:, 1] - c[:, 1]) * (px - c[:, 0]) + (c[:, 0] - b[:, 0]) * (py - c[:, 1])) / den
    l2 = ((c[:, 1] - a[:, 1]) * (px - c[:, 0]) + (a[:, 0] - c[:, 0]) * (py - c[:, 1])) / den
    out[row, col] = np.column_stack([l1, l2, 1.0 - l1 - l2])
    return out


def overlapping_texels(tri, size):
    """Number of texels covered by more than one triangle."""
    count, _ = rasterise(tri, size)
    return int(np.count_nonzero(count > 1))


def outside_unit_square(tri, tolerance=1e-4):
    """Share of triangles with a corner outside the 0-1 UV square (tiled UVs)."""
    tri = np.asarray(tri)
    if len(tri) == 0:
        return 0.0
    out = ((tri < -tolerance) | (tri > 1 + tolerance)).any(axis=(1, 2))
    return float(out.mean())


def island_labels(loop_vertex, loop_uv, loop_polygon, decimals=5):
    """UV island of each polygon: polygons sharing a vertex at the same UV are one island.

    Parameters
    ----------
    loop_vertex : (L,) int array
        Vertex index of each loop.
    loop_uv : (L, 2) float array
        UV of each loop.
    loop_polygon : (L,) int array
        Polygon of each loop.

    Returns
    -------
    (P,) int array
        Island label of each polygon, 0..n_islands-1.
    """
    uv_key = np.round(np.asarray(loop_uv, dtype=np.float64), decimals)
    keys = np.column_stack([np.asarray(loop_vertex, dtype=np.float64), uv_key])
    _, uv_vertex = np.unique(keys, axis=0, return_inverse=True)
    uv_vertex = uv_vertex.ravel()
    n_poly = int(loop_polygon.max()) + 1 if len(loop_polygon) else 0
    # Bipartite graph: polygon nodes [0, P) and UV-vertex nodes [P, P + V).
    a = np.asarray(loop_polygon, dtype=np.int64)
    b = uv_vertex.astype(np.int64) + n_poly
    parent = np.arange(n_poly + int(uv_vertex.max(initial=-1)) + 1)
    while True:
        m = np.minimum(parent[a], parent[b])
        new = parent.copy()
        np.minimum.at(new, a, m)
        np.minimum.at(new, b, m)
        new = new[new]  # pointer jumping
        if np.array_equal(new, parent):
            break
        parent = new
    _, labels = np.unique(parent[:n_poly], return_inverse=True)
    return labels.ravel()


def dilate_labels(label, steps):
    """Grow labelled regions into unlabelled (-1) texels by ``steps`` texels (4-neighbours).

    The bake's margin extends each island's values outward; this gives the margin texels
    the label of the island they extend.
    """
    label = label.copy()
    for _ in range(int(steps)):
        empty = label < 0
        if not empty.any():
            break
        grown = label.copy()
        for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):
            moved = np.roll(label, shift, axis=axis)
            edge = [slice(None)] * 2
            edge[axis] = 0 if shift == 1 else -1
            moved[tuple(edge)] = -1  # no wrap-around
            take = empty & (grown < 0) & (moved >= 0)
            grown[take] = moved[take]
        label = grown
    return label
