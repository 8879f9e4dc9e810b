"""The detail of a frame image: as much of its texture as the camera can resolve.

A frame image (:mod:`.frames`) holds a copy's aged colour for one render, at its
texture's resolution. Where the camera sees the texture minified — a room's 1k textures
at 240 × 135, where one render pixel spans four to seven texels across — the render averages
what its few samples per pixel happen to read, and writing every texel costs the frame
more than the render itself (ten 1k materials at a new years value: 1.1 s of CPU for
the aging of 10.5 Mtexel against a 1.35 s frame). So, as a renderer chooses a mipmap
level, each **tile** of a frame image (:data:`TILE` texels a side, :mod:`.mosaic`) is
written at the coarsest level ``L`` (blocks of ``2^L × 2^L`` texels, their colours
averaged, then aged: :func:`.mosaic.block_mean`) at which every render pixel that sees
that part of the object still spans at least :data:`MIN_TEXELS` frame texels in every
direction (:func:`level`, :func:`tile_levels`); the exact aged colour at full
resolution is what Apply writes.
Two, not a mipmap's usual one: at one texel a pixel the render showed more of the
bias of aging a block's mean (up to 1.4 ΔE00 of 8 × 8-pixel means against the live
render at 128 spp; at two, 0.56, as two seeds of the live render); a block that mixes
two colours is aged as its two parts (:class:`.mosaic.Pyramid`).

The camera's footprint is found without rendering: for the nearest point of each
triangle inside the camera's frustum (a corner of the triangle clipped to it, or of
small triangles their corners and centre: :func:`triangle_depths`), its triangle's
fewest texels per metre (the smallest singular value of the map from the surface to the
texture, :func:`texels_per_metre`) times the size of a render pixel at its depth
(:func:`pixel_size`): per object, :func:`min_texels_per_pixel`; per tile,
:func:`tile_texels_per_pixel`, where a triangle larger than a tile or two is laid over
its tiles, each counting the nearest of its own corners on the triangle's plane (a
floor from under the camera to the far wall: fine near, coarse far). Occlusion is
ignored (a hidden part counts as seen: more detail, never less). A tile the camera does
not see (its part seen only by bounces, or not at all) gets :data:`HIDDEN_LEVEL`; a
gutter no triangle covers, the finest level of its neighbours. Mirrors and glass show
objects at other scales: the scene's *Frame Detail* ``FULL`` writes every frame image
whole.
"""

from __future__ import annotations

import math

import numpy as np

from .mosaic import Mosaic

#: Frame texels a render pixel spans at least, in every direction, at the level chosen.
MIN_TEXELS = 2.0
#: The coarsest level (a 1k texture: 64²).
MAX_LEVEL = 4
#: The level of an object no point of which lies in the camera's frustum.
HIDDEN_LEVEL = 3
#: Side of the tiles (texels at full resolution) a frame image's level is chosen for.
TILE = 32
#: Triangles whose longest edge is more than this times their nearest corner's depth
#: (a floor under the camera) are clipped to the frustum; smaller ones are sampled.
LARGE = 0.25


# ------------------------------------------------------------------------ pure math


def texels_per_metre(world, uv, size):
    """(T,) fewest texels per metre, in any direction on the surface, of triangles with
    world corners ``world`` (T, 3, 3) m and texture coordinates ``uv`` (T, 3, 2) on a
    texture of ``size`` (W, H) texels: the smallest singular value of the 2 × 2 map
    ``J = P E⁻¹`` from the triangle's plane (edges ``E`` in an orthonormal basis of it) to
    its texels (edges ``P``), ``σ_min = √((S − √(S² − 4 det²)) / 2)`` with ``S = ‖J‖_F²``.
    A triangle with no area in the world gives ``inf`` (it shows nothing: left out by
    the caller); one with no area in the texture gives 0 (its UVs collapsed onto a
    texel or a line, as a palette's swatches: it shows those texels sharp at any
    distance, so it keeps the full resolution)."""
    e1, e2 = world[:, 1] - world[:, 0], world[:, 2] - world[:, 0]
    scale = np.asarray(size, dtype=np.float64)
    p1, p2 = (uv[:, 1] - uv[:, 0]) * scale, (uv[:, 2] - uv[:, 0]) * scale
    l1 = np.linalg.norm(e1, axis=1)
    a = e1 / np.maximum(l1, 1e-30)[:, None]
    b = e2 - np.einsum("ij,ij->i", e2, a)[:, None] * a
    lb = np.linalg.norm(b, axis=1)
    b /= np.maximum(lb, 1e-30)[:, None]
    # E = [[l1, e2·a], [0, lb]] (columns: the edges in the basis (a, b)); J = P E⁻¹.
    e2a = np.einsum("ij,ij->i", e2, a)
    det_e = l1 * lb
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.stack([np.stack([lb, -e2a], -1), np.stack([np.zeros_like(lb), l1], -1)], 1)
        inv /= det_e[:, None, None]
        P = np.stack([p1, p2], -1)                                # (T, 2, 2): columns
        J = P @ inv
        S = np.einsum("tij,tij->t", J, J)
        det = np.abs(np.linalg.det(J))
        sigma = np.sqrt(np.maximum(S - np.sqrt(np.maximum(S * S - 4 * det * det, 0)), 0) / 2)
    collapsed = ~(det > 1e-20) | ~np.isfinite(sigma)
    return np.where(det_e <= 1e-20, np.inf, np.where(collapsed, 0.0, sigma))


def pixel_size(depth, per_depth, ortho):
    """World size (m) of a render pixel at ``depth`` (m along the view): ``per_depth ·
    depth`` for a perspective camera (``per_depth``: the pixel's size at 1 m), the
    constant ``per_depth`` for an orthographic one."""
    return np.full_like(depth, per_depth) if ortho else per_depth * depth


def frustum_planes(frame, ortho, clip):
    """(6, 4) planes ``(a, b, c, e)`` of the camera's frustum in its space: a point
    ``p`` is inside where every ``a x + b y + c z + e >= 0`` (depth ``−z``)."""
    x0, x1, y0, y1 = frame
    near, far = clip
    if ortho:
        sides = [(1, 0, 0, -x0), (-1, 0, 0, x1), (0, 1, 0, -y0), (0, -1, 0, y1)]
    else:                                  # x >= x0 · depth, ... (the frame at 1 m)
        sides = [(1, 0, x0, 0), (-1, 0, -x1, 0), (0, 1, y0, 0), (0, -1, -y1, 0)]
    return np.array(sides + [(0, 0, -1, -near), (0, 0, 1, far)], dtype=np.float64)


def clip_polygon(points, planes):
    """The part of the convex polygon ``points`` (k, 3) inside every plane
    (Sutherland–Hodgman); (0, 3) where nothing is."""
    for plane in planes:
        if not len(points):
            break
        side = points @ plane[:3] + plane[3]
        kept = []
        for k in range(len(points)):
            j = (k + 1) % len(points)
            if side[k] >= 0:
                kept.append(points[k])
            if (side[k] >= 0) != (side[j] >= 0):
                t = side[k] / (side[k] - side[j])
                kept.append(points[k] + t * (points[j] - points[k]))
        points = np.array(kept).reshape(-1, 3)
    return points


def triangle_depths(camera_space, frame, ortho, clip):
    """(T,) depth (m) of the nearest point of each triangle inside the camera's
    frustum, ``inf`` where none is: a corner of its part inside the frustum. Triangles
    large against their distance (:data:`LARGE`: a floor under the camera) are clipped
    to it (:func:`clip_polygon`); the others count by their corners and centre inside it.

    ``camera_space``: (T, 3, 3) corners in the camera's space (it looks down −z);
    ``frame``: ``(x0, x1, y0, y1)`` of the view at 1 m (perspective) or in metres
    (orthographic); ``clip``: (start, end) m."""
    planes = frustum_planes(frame, ortho, clip)
    depth = np.full(len(camera_space), np.inf)
    if not len(camera_space):
        return depth
    edge = np.linalg.norm(camera_space - np.roll(camera_space, 1, axis=1), axis=2).max(axis=1)
    near = np.maximum(-camera_space[..., 2].max(axis=1), 0.0)   # the nearest corner's depth
    large = edge > LARGE * np.maximum(near, 1e-9)
    small = np.flatnonzero(~large)
    if small.size:
        tri = camera_space[small]
        points = np.concatenate([tri, tri.mean(axis=1, keepdims=True)], axis=1)
        inside = np.all(points @ planes[:, :3].T + planes[:, 3] >= 0, axis=-1)   # (n, 4)
        depth[small] = np.where(inside, -points[..., 2], np.inf).min(axis=1)
    for t in np.flatnonzero(large):
        part = clip_polygon(camera_space[t], planes)
        if len(part):
            depth[t] = (-part[:, 2]).min()
    return depth


def min_texels_per_pixel(camera_space, sigma, frame, per_depth, ortho, clip):
    """Fewest texels (full resolution) a render pixel spans, in any direction, over the
    parts of an object's triangles inside the camera's frustum; ``inf`` where none is:
    at the nearest point of each triangle seen (:func:`triangle_depths`), its
    triangle's fewest texels per metre ``sigma`` (T,) (:func:`texels_per_metre`) times
    the size of a render pixel there (``per_depth``: at 1 m)."""
    keep = np.isfinite(sigma)
    if not keep.any():
        return math.inf
    depth = triangle_depths(camera_space[keep], frame, ortho, clip)
    seen = np.isfinite(depth)
    if not seen.any():
        return math.inf
    return float((sigma[keep][seen] * pixel_size(depth[seen], per_depth, ortho)).min())


def _tile_index(i, n, wrap):
    """Tile indices ``i`` on an axis of ``n`` tiles: wrapped (a Repeat texture) or
    clamped to the edge (Extend, Clip)."""
    return np.mod(i, n) if wrap else np.clip(i, 0, n - 1)


def _tiles_of(g, camera_space, planes, lo, span):
    """``(triangle, rows, cols, depth)``: each tile of its bounding box ``lo``,
    ``span`` ((m, 2) unwrapped tile indices and counts, x then y) that each triangle
    ``g`` (m, 3, 2, its corners in tile units) overlaps, and the depth (m) of the
    nearest point there inside the frustum (``inf`` where none is), from the plane of
    the triangle (``camera_space`` (m, 3, 3)) at the tile's corners. Depth is linear
    over the plane, so the nearest of a tile's corners is no farther than the nearest
    point of the triangle inside it (more detail, never less). A tile is left out where
    all its corners lie outside one edge of the triangle, and unseen where they all lie
    outside one plane of the frustum (separating axes)."""
    counts = span[:, 0] * span[:, 1]
    tri = np.repeat(np.arange(len(g)), counts)
    k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    cols = lo[tri, 0] + k % span[tri, 0]
    rows = lo[tri, 1] + k // span[tri, 0]
    P = np.stack([cols, rows], -1)[:, None, :] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]])
    E = np.stack([g[:, 1] - g[:, 0], g[:, 2] - g[:, 0]], -1)       # columns: the UV edges
    rel = P - g[tri, None, 0]
    ab = np.einsum("nij,nkj->nki", np.linalg.inv(E)[tri], rel)     # barycentric (α, β)
    c = camera_space
    points = c[tri, None, 0] + ab[..., :1] * (c[:, 1] - c[:, 0])[tri, None] \
        + ab[..., 1:] * (c[:, 2] - c[:, 0])[tri, None]              # (n, 4, 3)
    orient = np.sign(np.linalg.det(E))[tri, None]
    keep = np.ones(len(tri), bool)
    for a, b in ((0, 1), (1, 2), (2, 0)):
        edge, at = (g[:, b] - g[:, a])[tri, None], P - g[tri, None, a]
        inward = orient * (edge[..., 0] * at[..., 1] - edge[..., 1] * at[..., 0])
        keep &= ~np.all(inward < 0, axis=1)
    side = points @ planes[:, :3].T + planes[:, 3]                  # (n, 4, 6)
    outside = np.any(np.all(side < 0, axis=1), axis=-1)
    depth = np.where(outside, np.inf, (-points[..., 2]).min(axis=1))
    return tri[keep], rows[keep], cols[keep], depth[keep]


#: Tiles one triangle may be laid over tile by tile (a floor repeating its texture
#: hundreds of times); past it the triangle's nearest point counts on every tile it
#: touches.
MAX_TILES = 1 << 16
#: (Triangle, tile) pairs laid at once.
_PAIRS = 1 << 16


def tile_texels_per_pixel(camera_space, uv, sigma, size, tile, frame, per_depth, ortho, clip,
                          wrap=False):
    """(ny, nx) fewest texels (full resolution) a render pixel spans over the part of
    an object each ``tile`` × ``tile`` tile of its texture of ``size`` (W, H) shows
    (:func:`min_texels_per_pixel`, tile by tile); ``inf`` where the tile's triangles are
    out of view, NaN where no triangle covers the tile (a gutter).

    A triangle within two tiles each way counts its nearest point seen
    (:func:`triangle_depths`) on them; a larger one (in texture space) is laid over its
    tiles (:func:`_tiles_of`), so that a floor seen from near to far is detailed only
    where it is near. ``wrap``: the texture repeats (tile indices wrap, else clamp)."""
    W, H = size
    nx, ny = W // tile, H // tile
    out = np.full((ny, nx), np.inf)
    covered = np.zeros((ny, nx), bool)
    keep = np.isfinite(sigma)
    camera_space, uv, sigma = camera_space[keep], uv[keep], sigma[keep]
    g = uv * (W / tile, H / tile)                                   # tile units
    lo = np.floor(g.min(axis=1)).astype(np.int64)
    hi = np.maximum(np.ceil(g.max(axis=1)).astype(np.int64) - 1, lo)
    span = hi - lo + 1
    small = np.all(span <= 2, axis=1)
    depth = triangle_depths(camera_space, frame, ortho, clip)
    value = np.where(np.isinf(depth), np.inf, sigma * pixel_size(np.minimum(depth, clip[1]),
                                                                 per_depth, ortho))
    for dx in (0, 1):
        for dy in (0, 1):
            ix = _tile_index(lo[small, 0] + np.minimum(dx, span[small, 0] - 1), nx, wrap)
            iy = _tile_index(lo[small, 1] + np.minimum(dy, span[small, 1] - 1), ny, wrap)
            covered[iy, ix] = True
            np.minimum.at(out, (iy, ix), value[small])
    large = np.flatnonzero(~small)
    flat = np.abs(np.linalg.det(np.stack([g[:, 1] - g[:, 0], g[:, 2] - g[:, 0]], -1))) < 1e-12
    whole = large[(np.prod(span[large], axis=1) > MAX_TILES) | flat[large]]
    for t in whole:                                  # the triangle's nearest point, everywhere
        iy, ix = np.meshgrid(_tile_index(np.arange(lo[t, 1], hi[t, 1] + 1), ny, wrap),
                             _tile_index(np.arange(lo[t, 0], hi[t, 0] + 1), nx, wrap),
                             indexing="ij")
        covered[iy, ix] = True
        np.minimum.at(out, (iy.ravel(), ix.ravel()), value[t])
    laid = np.setdiff1d(large, whole)
    planes = frustum_planes(frame, ortho, clip)
    chunks = np.cumsum(np.prod(span[laid], axis=1)) // _PAIRS
    for chunk in np.unique(chunks):
        ts = laid[chunks == chunk]
        tri, rows, cols, depth = _tiles_of(g[ts], camera_space[ts], planes, lo[ts], span[ts])
        iy, ix = _tile_index(rows, ny, wrap), _tile_index(cols, nx, wrap)
        covered[iy, ix] = True
        seen = np.isfinite(depth)
        size_there = pixel_size(np.clip(depth[seen], clip[0], clip[1]), per_depth, ortho)
        np.minimum.at(out, (iy[seen], ix[seen]), sigma[ts][tri[seen]] * size_there)
    out[~covered] = np.nan
    return out


def level(texels_per_pixel, size, max_level=MAX_LEVEL):
    """The coarsest level ``L`` (``2^L`` texels to one) at which a pixel spans at least
    :data:`MIN_TEXELS` frame texels where it spans ``texels_per_pixel`` at full
    resolution: ``⌊log₂(texels_per_pixel / MIN_TEXELS)⌋``, within ``[0, max_level]``,
    and ``2^L`` dividing both sides of ``size`` (W, H); :data:`HIDDEN_LEVEL` where
    unseen (``inf``)."""
    if math.isinf(texels_per_pixel):
        L = min(HIDDEN_LEVEL, max_level)
    elif texels_per_pixel <= MIN_TEXELS:
        return 0
    else:
        L = min(int(math.floor(math.log2(texels_per_pixel / MIN_TEXELS))), max_level)
    while L > 0 and (size[0] % (1 << L) or size[1] % (1 << L)):
        L -= 1
    return max(L, 0)


def tile_levels(texels_per_pixel, tile, max_level=MAX_LEVEL):
    """(ny, nx) int8 :func:`level` of each tile of :func:`tile_texels_per_pixel`, at
    most ``log₂ tile`` (a tile keeps one texel at least); an unseen tile (``inf``)
    :data:`HIDDEN_LEVEL`; a tile no triangle covers (NaN: a gutter, read only where
    Linear lookups at an island's edge reach into it) the finest level of its covered
    neighbours, or the coarsest where it has none."""
    top = min(max_level, int(math.log2(tile)))
    tpp = np.asarray(texels_per_pixel, dtype=np.float64)
    gutter = np.isnan(tpp)
    with np.errstate(divide="ignore", invalid="ignore"):
        L = np.floor(np.log2(np.where(gutter, 1.0, tpp) / MIN_TEXELS))
    L = np.where(np.isinf(tpp), min(HIDDEN_LEVEL, top), np.clip(np.nan_to_num(L, neginf=0), 0, top))
    if gutter.any():
        padded = np.pad(np.where(gutter, top, L), 1, constant_values=top)
        ny, nx = L.shape
        near = np.min([padded[1 + dy:1 + dy + ny, 1 + dx:1 + dx + nx]
                       for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)
        L = np.where(gutter, near, L)
    return L.astype(np.int8)


def tile_side(size, tile=TILE):
    """The side of the tiles of a texture of ``size`` (W, H): :data:`TILE`, or the
    largest power of two below it that divides both sides."""
    while tile > 1 and (size[0] % tile or size[1] % tile):
        tile //= 2
    return tile


# ----------------------------------------------------------------------- the scene


def camera_view(scene, depsgraph):
    """``(world → camera 4 × 4, frame (x0, x1, y0, y1), per_depth, ortho, clip)`` of the
    scene's camera as evaluated (animation, constraints, a camera placed since the last
    update) at the render's resolution, or None where the footprint cannot be known this
    way (no camera, a panoramic one)."""
    cam = scene.camera
    if cam is None or cam.type != "CAMERA" or cam.data.type == "PANO":
        return None
    render = scene.render
    scale = render.resolution_percentage / 100.0
    res = (max(render.resolution_x * scale, 1.0), max(render.resolution_y * scale, 1.0))
    corners = np.array([tuple(v) for v in cam.data.view_frame(scene=scene)])
    ortho = cam.data.type == "ORTHO"
    xy = corners[:, :2] if ortho else corners[:, :2] / -corners[:, 2:3]
    x0, y0 = xy.min(axis=0)
    x1, y1 = xy.max(axis=0)
    per_depth = min((x1 - x0) / res[0], (y1 - y0) / res[1])
    to_camera = np.array(cam.evaluated_get(depsgraph).matrix_world.inverted(), dtype=np.float64)
    clip = (cam.data.clip_start, cam.data.clip_end)
    return to_camera, (x0, x1, y0, y1), per_depth, ortho, clip


def object_levels(obj, depsgraph, uv_name, size, view, wrap=False):
    """``(levels (ny, nx), tile)``: the frame image's :func:`tile_levels` of ``obj``'s
    texture of ``size`` (W, H) in its UV map ``uv_name`` under the camera ``view``
    (:func:`camera_view`), tile by tile (:func:`tile_side`); None where the view or the
    map is not known (the whole texture). ``wrap``: the texture repeats."""
    from ..bake.uvmaps import evaluated_mesh, triangle_uvs, world_triangles

    if view is None:
        return None
    with evaluated_mesh(obj, depsgraph) as mesh:
        if uv_name not in mesh.uv_layers or not len(mesh.polygons):
            return None
        uv, _poly = triangle_uvs(mesh, uv_name)
        world = world_triangles(obj.evaluated_get(depsgraph), mesh)
    to_camera, frame, per_depth, ortho, clip = view
    sigma = texels_per_metre(world, uv, size)
    camera_space = world @ to_camera[:3, :3].T + to_camera[:3, 3]
    tile = tile_side(size)
    tpp = tile_texels_per_pixel(camera_space, uv, sigma, size, tile, frame, per_depth, ortho,
                                clip, wrap)
    return tile_levels(tpp, tile), tile


def copy_mosaic(copy, node, view, depsgraph):
    """The :class:`.mosaic.Mosaic` of an aged copy's frame image (its Image Texture node
    ``node``) under the camera ``view``: :func:`object_levels` of its object and texture;
    None (the texture's resolution) without a view, for a flat colour, where the texture
    is read texel by texel (Closest interpolation: pixel art), or where every tile is at
    level 0."""
    props = copy.lightfade
    if view is None or props.path == "FLAT" or props.albedo is None or node.interpolation == "Closest":
        return None
    try:
        found = object_levels(props.aged_object, depsgraph, props.uv_map,
                              tuple(props.albedo.size), view, wrap=node.extension == "REPEAT")
    except (RuntimeError, ValueError, KeyError, np.linalg.LinAlgError):   # the whole texture
        return None
    return None if found is None or not found[0].any() else Mosaic(*found)
