"""Scenes of many small objects and many UV islands for ``benchmarks/scale.py``.

Built with numpy through ``from_pydata`` and ``foreach_set``, so a thousand objects take
a second or two: small cubes (0.12 m, Blender's cube UV layout, one island each) on a
floor under a sun, as separate objects, as one mesh with unique UVs (the same texels), or
as one mesh whose copies share one UV layout (a realized scatter: overlapping islands).
"""

import math

import bpy
import numpy as np

CUBE = 0.12
SPACING = 0.3


def _template():
    """Vertices, faces and loop UVs of Blender's cube of side :data:`CUBE`."""
    mesh = bpy.data.meshes.new("template")
    import bmesh
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_cube(bm, size=CUBE, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    co = np.array([v.co[:] for v in mesh.vertices])
    faces = [list(p.vertices) for p in mesh.polygons]
    uv = np.empty(len(mesh.loops) * 2)
    mesh.uv_layers[0].data.foreach_get("uv", uv)
    bpy.data.meshes.remove(mesh)
    return co, faces, uv.reshape(-1, 2)


def _grid(count, spacing=SPACING):
    side = int(math.ceil(math.sqrt(count)))
    i = np.arange(count)
    offset = np.column_stack([(i % side) * spacing, (i // side) * spacing, np.full(count, CUBE / 2)])
    return offset - [(side - 1) * spacing / 2, (side - 1) * spacing / 2, 0.0]


def aged_material(name="Aged"):
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.6, 0.2, 0.15, 1)
    mat.lightfade.enabled = True
    return mat


def _mesh(name, co, faces, uv):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in co], [], faces)
    mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", np.asarray(uv, np.float32).ravel())
    return mesh


def _link(name, mesh, location=(0, 0, 0)):
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    return obj


def floor_and_sun(extent, strength=3.0):
    """A grey floor (not aged) wide enough for the grid, and a sun 40° from the zenith."""
    mesh = _mesh("Floor", [(-extent, -extent, 0), (extent, -extent, 0), (extent, extent, 0),
                           (-extent, extent, 0)], [[0, 1, 2, 3]],
                 [(0, 0), (1, 0), (1, 1), (0, 1)])
    _link("Floor", mesh)
    data = bpy.data.lights.new("Sun", "SUN")
    data.energy = strength
    sun = _link("Sun", data)
    sun.rotation_euler = (math.radians(40), 0, math.radians(20))


def separate_cubes(count):
    """``count`` cubes as separate objects (each its own mesh, one shared aged material)."""
    co, faces, uv = _template()
    mat = aged_material()
    template = _mesh("Cube", co, faces, uv)
    template.materials.append(mat)
    objects = []
    for k, loc in enumerate(_grid(count)):
        objects.append(_link(f"Cube{k:04d}", template.copy() if k else template, tuple(loc)))
    floor_and_sun(_grid(count)[:, :2].max() + 1.0)
    bpy.context.view_layer.update()
    return objects


def joined_cubes(count, unique=True):
    """The same cubes as one mesh: with unique UVs (each cube's layout in its own cell of
    a grid over the square), or sharing one UV layout (``unique=False``: overlapping
    islands, a realized scatter)."""
    co, faces, uv = _template()
    offsets = _grid(count)
    side = int(math.ceil(math.sqrt(count)))
    verts = (co[None] + offsets[:, None]).reshape(-1, 3)
    n = len(co)
    all_faces = [[f + k * n for f in face] for k in range(count) for face in faces]
    if unique:
        cell = np.arange(count)
        shift = np.column_stack([cell % side, cell // side]) / side
        uvs = (uv[None] / side + shift[:, None]).reshape(-1, 2)
    else:
        uvs = np.tile(uv, (count, 1))
    mesh = _mesh("Cubes", verts, all_faces, uvs)
    mesh.materials.append(aged_material())
    obj = _link("Cubes", mesh)
    floor_and_sun(offsets[:, :2].max() + 1.0)
    bpy.context.view_layer.update()
    return obj
