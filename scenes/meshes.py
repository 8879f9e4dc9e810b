"""Meshes with UVs for the scripted demo scenes: boxes as rectangles, sheets, lathes.

Each mesh has one UV map ("UVMap") whose islands never overlap, so that a per-texel bake
maps each texel to one place on the surface (a convention of :mod:`scenes.common`).
"""

from __future__ import annotations

import math

import bpy
import numpy as np
from mathutils import Vector


def box_quads(lo, hi, skip=()):
    """The six faces of an axis-aligned box as rectangles ``(p0, p1, p2, p3)``, CCW outside.

    ``p0 -> p1`` is the face's u direction and ``p0 -> p3`` its v direction (up on walls).
    ``skip`` names faces to leave out: any of ``"+x" "-x" "+y" "-y" "+z" "-z"``.
    """
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    faces = {
        "-y": ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
        "+x": ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
        "+y": ((x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)),
        "-x": ((x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)),
        "+z": ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
        "-z": ((x0, y1, z0), (x1, y1, z0), (x1, y0, z0), (x0, y0, z0)),
    }
    return [q for k, q in faces.items() if k not in skip]


def pack_rectangles(sizes, gap=0.004):
    """Shelf-pack rectangles of physical sizes ``(w, h)`` into the unit square.

    One scale (UV units per metre) for all, as large as fits, so texel density is uniform.

    Returns
    -------
    offsets : list of (u, v)
        Lower-left UV corner of each rectangle.
    scale : float
        UV units per metre.
    """
    order = sorted(range(len(sizes)), key=lambda i: -sizes[i][1])

    def place(s):
        offsets = [None] * len(sizes)
        x = y = gap
        row_h = 0.0
        for i in order:
            w, h = sizes[i][0] * s, sizes[i][1] * s
            if w + 2 * gap > 1.0:
                return None
            if x + w + gap > 1.0:
                y += row_h + gap
                x, row_h = gap, 0.0
            offsets[i] = (x, y)
            x += w + gap
            row_h = max(row_h, h)
        return offsets if y + row_h + gap <= 1.0 else None

    lo, hi = 0.0, 1.0 / max(max(w, h) for w, h in sizes)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if place(mid) else (lo, mid)
    return place(lo), lo


def _link(name, mesh, coll, material):
    ob = bpy.data.objects.new(name, mesh)
    (coll or bpy.context.scene.collection).objects.link(ob)
    if material is not None:
        mesh.materials.append(material)
    return ob


def mesh_from_quads(name, quads, coll=None, material=None, gap=0.004):
    """An object made of separate rectangles, each its own UV island, packed without overlap."""
    quads = [[Vector(p) for p in q] for q in quads]
    sizes = [((q[1] - q[0]).length, (q[3] - q[0]).length) for q in quads]
    offsets, s = pack_rectangles(sizes, gap=gap)
    verts, faces, uvs = [], [], []
    for q, (w, h), (u0, v0) in zip(quads, sizes, offsets):
        n = len(verts)
        verts.extend(q)
        faces.append((n, n + 1, n + 2, n + 3))
        uvs.extend([(u0, v0), (u0 + w * s, v0), (u0 + w * s, v0 + h * s), (u0, v0 + h * s)])
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    uv = mesh.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.asarray(uvs, dtype=np.float32).ravel())
    mesh.update()
    return _link(name, mesh, coll, material)


def grid_mesh(name, nu, nv, fn, coll=None, material=None, smooth=False):
    """A (nu x nv)-quad sheet with UVs = its parameters: ``fn(u, v) -> (x, y, z)``, u, v in [0, 1]."""
    us = np.linspace(0.0, 1.0, nu + 1)
    vs = np.linspace(0.0, 1.0, nv + 1)
    verts = [fn(u, v) for v in vs for u in us]
    faces, uvs = [], []
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            faces.append((a, a + 1, a + nu + 2, a + nu + 1))
            uvs.extend([(us[i], vs[j]), (us[i + 1], vs[j]), (us[i + 1], vs[j + 1]), (us[i], vs[j + 1])])
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    uv = mesh.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.asarray(uvs, dtype=np.float32).ravel())
    if smooth:
        mesh.shade_smooth()
    mesh.update()
    return _link(name, mesh, coll, material)


def lathe_mesh(name, profile, segments=32, coll=None, material=None, location=(0, 0, 0)):
    """A surface of revolution about z from a profile of ``(radius, z)`` points (radius 0 = pole)."""
    verts, rings = [], []
    for r, z in profile:
        if r == 0:
            rings.append([len(verts)])
            verts.append((0.0, 0.0, z))
        else:
            ring = []
            for k in range(segments):
                a = 2 * math.pi * k / segments
                ring.append(len(verts))
                verts.append((r * math.cos(a), r * math.sin(a), z))
            rings.append(ring)
    faces = []
    for ra, rb in zip(rings[:-1], rings[1:]):
        for k in range(segments):
            k1 = (k + 1) % segments
            if len(ra) == 1:
                faces.append((ra[0], rb[k], rb[k1]))
            elif len(rb) == 1:
                faces.append((ra[k], ra[k1], rb[0]))
            else:
                faces.append((ra[k], ra[k1], rb[k1], rb[k]))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.shade_smooth()
    mesh.update()
    ob = _link(name, mesh, coll, material)
    ob.location = location
    return ob
