"""The detail of a frame image: as much of its texture as the camera can resolve.

A frame image (:mod:`.frames`) holds a copy's aged colour for one render, at its
texture's resolution. Where the camera sees the texture minified — a room's 1k textures
at 240 × 135, where one render pixel spans four to seven texels across — the render averages
what its few samples per pixel happen to read, and writing every texel costs the frame
more than the render itself (ten 1k materials at a new years value: 1.1 s of CPU for
the aging of 10.5 Mtexel against a 1.35 s frame). So, as a renderer chooses a mipmap
level, each frame image is written at the coarsest level ``L`` (blocks of ``2^L × 2^L``
texels, aged as their mean colour or, where a block mixes two colours, as its two
parts: :mod:`.blocks`) at which every render pixel that sees the object still spans at
least :data:`MIN_TEXELS` frame texel in every direction (:func:`level`); the exact aged
colour at full resolution is what Apply writes.

The camera's footprint, per object (:func:`min_texels_per_pixel`), is found without
rendering: for the nearest point of each triangle inside the camera's frustum (a corner
of the triangle clipped to it, or of small triangles their corners and centre:
:func:`triangle_depths`), its triangle's fewest texels per metre (the smallest singular
value of the map from the surface to the texture, :func:`texels_per_metre`) times the
size of a render pixel at its depth (:func:`pixel_size`). Occlusion is ignored (a hidden
part counts as seen: more detail, never less). An object the camera does not see at all
(seen only by bounces, or not at all) gets :data:`HIDDEN_LEVEL`. Mirrors and glass show
objects at other scales: the scene's *Frame Detail* ``FULL`` writes every frame image
whole. One level per object, set by its nearest point, is stable while the camera moves
(a level per tile of the texture was measured and set aside: docs/blender.md).
"""

from __future__ import annotations

import math

import numpy as np

#: Frame texels a render pixel spans at least, in every direction, at the level chosen
#: (a mipmap's choice; two before the blocks of two colours were aged as their parts:
#: docs/blender.md).
MIN_TEXELS = 1.0
#: The coarsest level (a 1k texture: 64²).
MAX_LEVEL = 4
#: The level of an object no point of which lies in the camera's frustum.
HIDDEN_LEVEL = 3
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


def object_level(obj, depsgraph, uv_name, size, view):
    """The frame image :func:`level` of ``obj``'s texture of ``size`` (W, H) in its UV
    map ``uv_name`` under the camera ``view`` (:func:`camera_view`); 0 (full) where the
    view or the map is not known."""
    from ..bake.uvmaps import evaluated_mesh, triangle_uvs, world_triangles

    if view is None:
        return 0
    with evaluated_mesh(obj, depsgraph) as mesh:
        if uv_name not in mesh.uv_layers or not len(mesh.polygons):
            return 0
        uv, _poly = triangle_uvs(mesh, uv_name)
        world = world_triangles(obj.evaluated_get(depsgraph), mesh)
    to_camera, frame, per_depth, ortho, clip = view
    sigma = texels_per_metre(world, uv, size)
    camera_space = world @ to_camera[:3, :3].T + to_camera[:3, 3]
    return level(min_texels_per_pixel(camera_space, sigma, frame, per_depth, ortho, clip), size)


def copy_level(copy, node, view, depsgraph):
    """The level of an aged copy's frame image (its Image Texture node ``node``) under
    the camera ``view`` (:func:`object_level`); 0 (the texture's resolution) without a
    view, for a flat colour, or where the texture is read texel by texel (Closest
    interpolation: pixel art)."""
    props = copy.lightfade
    if view is None or props.path == "FLAT" or props.albedo is None or node.interpolation == "Closest":
        return 0
    try:
        return object_level(props.aged_object, depsgraph, props.uv_map,
                            tuple(props.albedo.size), view)
    except (RuntimeError, ValueError, KeyError):          # unknown: the whole texture
        return 0
