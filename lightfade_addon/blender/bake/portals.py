"""Light portals over a room's windows while the sky is baked.

Inside a room the sky reaches a texel only through its windows, a small part of the
sphere that Cycles samples when it samples the world: most of its sky samples end on
a wall, and the texels that see the sky through a window are the noisiest of the
bake (a sofa in a furnished room: ~90 % of its light is sky through the window,
``docs/bake.md``). A Cycles *light portal* (an Area light with *Portal* on) over the
window adds a way of sampling the world through it; Cycles keeps sampling the sky map
too and weighs the two (multiple importance sampling), so the bake's mean does not
change, only its noise.

A **window** here is a flat patch of a mesh whose material lets light through (a
Glass, Transparent or Refraction BSDF, or a Principled BSDF with transmission or
alpha, feeding its output, node groups included; :func:`.panes.lets_light_through`),
at least :data:`MIN_AREA`, with the world on one side and
the scene on the other: rays from points over it escape along one normal and hit
something along the other (:func:`find_windows`; a mullion in front of some points
does not decide). A glass vase inside a room has the
room on both sides, a pane outdoors the sky on both: neither gets a portal. The
portal covers the patch's rectangle and faces the scene (an Area light shines along
its local −Z). A scene that has portals of its own gets none made; the bake's
*Portals over Windows* (``Scene.lightfade_bake.window_portals``) turns it off.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np
from mathutils import Matrix, Vector

from .emitters import is_portal
from .panes import lets_light_through
from .uvmaps import evaluated_mesh

#: Smallest window (m²) that gets a portal.
MIN_AREA = 0.05
#: Faces of one window: normals within this (as unit-vector difference), planes within
#: :data:`PLANE_TOLERANCE` metres.
NORMAL_TOLERANCE = 0.05
PLANE_TOLERANCE = 0.05
#: Rays from a window's points start this far off its plane (m).
RAY_OFFSET = 0.01
#: Points per side of the grid over a window whose rays find the world's side.
SIDE_GRID = 4
#: Name of the temporary portals.
PORTAL_NAME = "LF_Portal"

@dataclass(frozen=True)
class Window:
    """A portal to make: world-space ``matrix`` (its −Z into the scene), ``size`` (x, y)
    in metres, and the object and material it covers (for the report)."""

    matrix: Matrix
    size: tuple
    obj: str
    material: str


def clear_slots(obj):
    """Indices of ``obj``'s material slots whose material lets light through."""
    return [i for i, slot in enumerate(obj.material_slots) if lets_light_through(slot.material)]


def _patches(obj, depsgraph, slots):
    """Flat patches of ``obj``'s faces on ``slots``: [(unit normal, points (n, 3), area,
    slot)] in world space, faces grouped by slot, normal and plane."""
    with evaluated_mesh(obj, depsgraph) as mesh:
        count = len(mesh.polygons)
        mat = np.empty(count, np.int64)
        mesh.polygons.foreach_get("material_index", mat)
        keep = np.flatnonzero(np.isin(mat, slots))
        if keep.size == 0:
            return []
        co = np.empty(len(mesh.vertices) * 3)
        mesh.vertices.foreach_get("co", co)
        start = np.empty(count, np.int64)
        total = np.empty(count, np.int64)
        mesh.polygons.foreach_get("loop_start", start)
        mesh.polygons.foreach_get("loop_total", total)
        verts = np.empty(len(mesh.loops), np.int64)
        mesh.loops.foreach_get("vertex_index", verts)
    m = np.array(obj.matrix_world)
    co = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    faces = []
    for p in keep:
        pts = co[verts[start[p]:start[p] + total[p]]]
        cross = np.cross(pts[1:-1] - pts[0], pts[2:] - pts[0]).sum(axis=0)
        area = 0.5 * np.linalg.norm(cross)
        if area > 0.0:
            faces.append((cross / (2.0 * area), pts, area, int(mat[p])))
    groups = {}
    for normal, pts, area, slot in faces:
        key = (slot, *np.round(normal / NORMAL_TOLERANCE).astype(int),
               int(round(float(normal @ pts[0]) / PLANE_TOLERANCE)))
        groups.setdefault(key, []).append((normal, pts, area))
    return [(np.mean([f[0] for f in g], axis=0), np.concatenate([f[1] for f in g]),
             sum(f[2] for f in g), key[0]) for key, g in groups.items()]


def _escapes(scene, depsgraph, origin, direction):
    hit = scene.ray_cast(depsgraph, Vector(origin), Vector(direction))[0]
    return not hit


def _sky_side(scene, depsgraph, centre, u, v, size, n):
    """+1 where the world is along ``n`` and the scene along ``-n``, -1 the other way
    round, 0 neither: rays from a :data:`SIDE_GRID`² grid of points over the rectangle
    (a mullion or a muntin in front of some of them does not decide), each point
    counting where it sees the world on one side only; at least a quarter of them."""
    k = (np.arange(SIDE_GRID) + 0.5) / SIDE_GRID - 0.5
    votes = []
    for a in k * size[0]:
        for b in k * size[1]:
            p = centre + a * u + b * v
            out = [_escapes(scene, depsgraph, p + s * RAY_OFFSET * n, s * n) for s in (1.0, -1.0)]
            if out[0] != out[1]:
                votes.append(1 if out[0] else -1)
    if 4 * len(votes) < SIDE_GRID ** 2:
        return 0
    return 1 if 2 * votes.count(1) > len(votes) else -1


def _rectangle(normal, points):
    """Centre, in-plane axes (u, v) and sizes of the patch's rectangle (u horizontal
    where the patch is not)."""
    n = normal / np.linalg.norm(normal)
    up = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(up, n)
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    pu, pv = points @ u, points @ v
    centre = u * (pu.max() + pu.min()) / 2 + v * (pv.max() + pv.min()) / 2 + n * float(
        np.mean(points @ n))
    return centre, u, v, (float(pu.max() - pu.min()), float(pv.max() - pv.min()))


def find_windows(scene, depsgraph, view_layer=None):
    """The :class:`Window` s of the scene (none where it has portals of its own)."""
    objects = (view_layer or bpy.context.view_layer).objects
    if any(is_portal(o) and not o.hide_render for o in scene.objects):
        return []
    windows, seen = [], set()
    for obj in objects:
        if obj.type != "MESH" or obj.hide_render or not obj.visible_get():
            continue
        slots = clear_slots(obj)
        if not slots:
            continue
        for normal, points, area, slot in _patches(obj, depsgraph, slots):
            if area < MIN_AREA:
                continue
            centre, u, v, size = _rectangle(normal, points)
            n = normal / np.linalg.norm(normal)
            side = _sky_side(scene, depsgraph, centre, u, v, size, n)
            if side == 0:
                continue                       # the world on both sides, or on neither
            inward = -side * n
            z = -inward                        # an Area light shines along its local -Z
            x = u
            y = np.cross(z, x)
            matrix = Matrix(np.column_stack([x, y, z, centre]).tolist() + [[0, 0, 0, 1]])
            key = (*np.round(inward / NORMAL_TOLERANCE).astype(int),
                   *np.round(centre / PLANE_TOLERANCE).astype(int))
            if key not in seen:                # a pane's two sides: one portal
                seen.add(key)
                windows.append(Window(matrix, size, obj.name, obj.material_slots[slot].name))
    return windows


def add_portals(state, scene, windows):
    """A temporary portal over each window (removed when ``state`` unwinds)."""
    for k, window in enumerate(windows):
        light = bpy.data.lights.new(f"{PORTAL_NAME}{k}", "AREA")
        light.shape = "RECTANGLE"
        light.size, light.size_y = window.size
        light.cycles.is_portal = True
        obj = bpy.data.objects.new(light.name, light)
        obj.matrix_world = window.matrix
        scene.collection.objects.link(obj)

        def remove(obj=obj, light=light):
            bpy.data.objects.remove(obj)
            bpy.data.lights.remove(light)

        state.push(remove)


def windows_note(windows):
    """One line for the bake report, or ''."""
    if not windows:
        return ""
    names = ", ".join(sorted({f'"{w.obj}" ({w.material})' for w in windows}))
    return (f"Sky through {len(windows)} window(s) of {names}: a Cycles light portal over "
            "each while the sky is baked (less noise, the same mean; off: Exposure Bake > "
            "Portals over Windows)")
