"""Finding UV islands folded onto themselves, all islands at once (numpy).

``LightFadeUV`` keeps the artist's islands and packs them apart (:mod:`.uvmaps`); only an
island whose own triangles share texels needs a new unwrap.  Each island is rasterised
in its own frame (its bounding box from its lowest corner) on a grid of at most
:data:`ISLAND_TEXELS` texels across: at the map's own scale where the island is smaller
than that, scaled down to it where larger.  All islands share one pass: a texel key is
``island · R² + texel`` and one ``bincount`` counts each island's own coverage, so
thousands of islands cost one rasterisation of a few million texels (a scatter of 5000
cubes sharing one UV layout: about a second), not one full map per island (0.25 s each
at 1024²: 113 s for 500).

An island folds onto itself when more than ``max(2, tolerance · covered)`` of its texels
are covered twice (:data:`.uvmaps.OVERLAP_TOLERANCE`: round-off on shared edges).
"""

from __future__ import annotations

import numpy as np

from . import raster

#: Grid of each island's own rasterisation, texels across (at most).
ISLAND_TEXELS = 64
#: Bins of one ``bincount`` pass (islands are taken in groups of this many texels).
_BINS = 1 << 22


def island_frames(tri, island, size, texels=ISLAND_TEXELS):
    """Each triangle's UVs in its island's own frame, in texels of a ``texels``-wide grid.

    Parameters
    ----------
    tri : (T, 3, 2) float array
        UV triangles (0-1 units).
    island : (T,) int array
        Island label (0..K-1) of each triangle.
    size : int
        Map width the islands are judged at (an island narrower than ``texels`` map
        texels is rasterised at the map's scale).

    Returns
    -------
    (T, 3, 2) float array
        Coordinates in 0-1 of the island's grid (``texels`` wide).
    """
    tri = np.asarray(tri, dtype=np.float64)
    k = int(island.max()) + 1 if len(island) else 0
    corners = tri.reshape(-1, 2)
    label = np.repeat(island, 3)
    lo = np.full((k, 2), np.inf)
    hi = np.full((k, 2), -np.inf)
    np.minimum.at(lo, label, corners)
    np.maximum.at(hi, label, corners)
    extent = np.max(hi - lo, axis=1) * size + 1.0              # map texels across
    small = extent <= texels
    # small islands keep the map's texel grid (their first texel's corner as origin)
    lo = np.where(small[:, None], np.floor(lo * size) / size, lo)
    scale = size * np.where(small, 1.0, texels / extent)       # grid texels per UV unit
    local = (tri - lo[island][:, None, :]) * scale[island][:, None, None]
    return local / texels


def self_overlapping_islands(tri, island, size, tolerance=1e-3, texels=ISLAND_TEXELS):
    """Labels of the islands whose own triangles cover a texel twice (sorted list).

    Islands that overlap *each other* (mirrored halves, stacked copies) are made unique by
    packing alone; an island folded onto itself needs a new unwrap.
    """
    island = np.asarray(island, dtype=np.int64)
    if len(island) == 0:
        return []
    k = int(island.max()) + 1
    local = island_frames(tri, island, size, texels)
    cells = texels * texels
    per_pass = max(_BINS // cells, 1)
    bad = []
    for first in range(0, k, per_pass):
        mine = np.flatnonzero((island >= first) & (island < first + per_pass))
        if len(mine) == 0:
            continue
        count = np.zeros(min(per_pass, k - first) * cells, dtype=np.int64)
        rel = island[mine] - first
        for t, flat in raster.covered_texels(local[mine], texels):
            count += np.bincount(rel[t] * cells + flat, minlength=len(count))
        count = count.reshape(-1, cells)
        covered = np.count_nonzero(count, axis=1)
        twice = np.count_nonzero(count > 1, axis=1)
        bad += (np.flatnonzero(twice > np.maximum(2, tolerance * covered)) + first).tolist()
    return bad


def surely_overlapping(tri, size, tolerance=1e-3):
    """True when triangles inside the 0-1 square hold more area than the square: a
    triangle of area ``A`` and perimeter ``P`` (in texels) covers at least ``A - P``
    texel centres, so more than ``(1 + tolerance) size²`` of those in all means texels
    covered twice (False: not known without rasterising)."""
    tri = np.asarray(tri, dtype=np.float64) * size
    if len(tri) == 0 or tri.min() < 0 or tri.max() > size:
        return False
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    perimeter = (np.linalg.norm(e1, axis=1) + np.linalg.norm(e2, axis=1)
                 + np.linalg.norm(tri[:, 2] - tri[:, 1], axis=1))
    return float(np.maximum(area - perimeter, 0.0).sum()) > (1.0 + tolerance) * size * size


def overlaps(tri, size, tolerance=1e-3):
    """Whether UV triangles cover more than ``max(2, tolerance · covered)`` texels of a
    ``size``² map twice.

    The texels are counted chunk by chunk, and the answer is yes as soon as the texels
    covered twice exceed ``max(2, tolerance · size²)`` (covered ≤ size², so this is
    enough): a mesh of stacked copies (a realized scatter sharing one UV layout) is
    answered after the first few million texels instead of rasterising every copy
    (5000 cubes at 1024²: 2 G texels).
    """
    if surely_overlapping(tri, size, tolerance):
        return True
    count = np.zeros(size * size, dtype=np.int32)
    enough = max(2, tolerance * size * size)
    for _, flat in raster.covered_texels(tri, size):
        count += np.bincount(flat, minlength=size * size).astype(np.int32)
        if np.count_nonzero(count > 1) > enough:
            return True
    return np.count_nonzero(count > 1) > max(2, tolerance * np.count_nonzero(count))
