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


# ----------------------------------------------------------------------- the apartment

ROOM = 4.0
HEIGHT = 2.6
#: Each room's lamps form a light group of their own: a different schedule (h/day).
ROOM_HOURS = (5.0, 2.0, 3.0, 1.5, 4.0, 6.0)


def _box(name, size, location, material, rotation=0.0):
    """A box (Blender's cube UVs) of ``size`` (x, y, z) metres standing on ``location``."""
    co, faces, uv = _template()
    co = co / CUBE * np.asarray(size)
    mesh = _mesh(name, co, faces, uv)
    mesh.materials.append(material)
    obj = _link(name, mesh, (location[0], location[1], location[2] + size[2] / 2))
    obj.rotation_euler.z = rotation
    return obj


def _wall_with_window(name, x0, y0, x1, y1, material, window):
    """A wall from (x0, y0) to (x1, y1), HEIGHT tall; ``window``: a 1.2 × 1.2 m opening in
    its middle (four quads around it)."""
    length = math.hypot(x1 - x0, y1 - y0)
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    edges = [0.0, length] if not window else [0.0, length / 2 - 0.6, length / 2 + 0.6, length]
    heights = [0.0, HEIGHT] if not window else [0.0, 0.9, 2.1, HEIGHT]
    verts = [(x0 + ux * s, y0 + uy * s, z) for s in edges for z in heights]
    rows = len(heights)
    faces, uvs = [], []
    for i in range(len(edges) - 1):
        for j in range(rows - 1):
            if window and i == 1 and j == 1:
                continue                                    # the opening
            a = i * rows + j
            faces.append([a, a + rows, a + rows + 1, a + 1])
            for v in faces[-1]:
                s, z = edges[v // rows], heights[v % rows]
                uvs.append((s / max(length, HEIGHT), z / max(length, HEIGHT)))
    mesh = _mesh(name, verts, faces, uvs)
    mesh.materials.append(material)
    return _link(name, mesh)


def _lamp(name, location, power, hours):
    data = bpy.data.lights.new(name, "POINT")
    data.energy = power
    data.shadow_soft_size = 0.1
    data.lightfade.hours_per_day = hours
    lamp = _link(name, data, location)
    return lamp


def apartment(rooms=4, small_per_room=60, seed=1):
    """``rooms`` rooms of 4 × 4 m in a row (floor, ceiling, walls, a window each on the
    south side), furniture (sofa, table, shelf, bed or cabinet as boxes), ``small_per_room``
    small objects (books, cups, boxes: 0.06-0.25 m) on the furniture and floor, a ceiling
    lamp and a desk lamp per room (each room's schedule its own: one light group per
    room), annual daylight at 52° N.  Returns the aged objects (all but the lamps)."""
    from lightfade_addon import api

    rng = np.random.default_rng(seed)
    paint, wood, fabric, small = (aged_material(n) for n in ("Paint", "Wood", "Fabric", "Small"))
    objects = []
    for r in range(rooms):
        x = r * ROOM
        objects.append(_box(f"Floor{r}", (ROOM, ROOM, 0.02), (x, 0, -0.02), wood))
        objects.append(_box(f"Ceiling{r}", (ROOM, ROOM, 0.02), (x, 0, HEIGHT), paint))
        h = ROOM / 2
        for k, (a, b, window) in enumerate((((x - h, -h), (x + h, -h), True),
                                           ((x + h, h), (x - h, h), False))):
            objects.append(_wall_with_window(f"Wall{r}_{k}", *a, *b, paint, window))
        if r == 0:
            objects.append(_wall_with_window("WallWest", x - h, h, x - h, -h, paint, False))
        objects.append(_wall_with_window(f"Wall{r}_e", x + h, -h, x + h, h, paint, False))
        furniture = [("Sofa", (2.0, 0.9, 0.8), fabric), ("Table", (1.2, 0.8, 0.75), wood),
                     ("Shelf", (1.0, 0.35, 1.9), wood), ("Cabinet", (0.8, 0.5, 0.9), wood)]
        tops = []
        for k, (name, size, mat) in enumerate(furniture):
            loc = (x - 1.0 + 1.3 * (k % 2), -1.0 + 1.6 * (k // 2), 0.0)
            objects.append(_box(f"{name}{r}", size, loc, mat, rotation=0.1 * k))
            tops.append((loc, size))
        for k in range(small_per_room):
            (lx, ly, _), (sx, sy, sz) = tops[k % len(tops)]
            dims = rng.uniform(0.06, 0.25, 3)
            on = (lx + rng.uniform(-0.4, 0.4) * sx, ly + rng.uniform(-0.4, 0.4) * sy,
                  sz if k % 3 else 0.0)
            if k % 3 == 0:                                  # on the floor, around
                on = (x + rng.uniform(-1.7, 1.7), rng.uniform(-1.7, 1.7), 0.0)
            objects.append(_box(f"Thing{r}_{k:02d}", tuple(dims), on, small,
                                rotation=rng.uniform(0, math.pi)))
        hours = ROOM_HOURS[r % len(ROOM_HOURS)] + 0.01 * (r // len(ROOM_HOURS))
        _lamp(f"Ceiling{r}Lamp", (x, 0.0, HEIGHT - 0.3), 60.0, hours)
        _lamp(f"Desk{r}Lamp", (x - 0.5, 0.6, 1.2), 25.0, hours)
    api.set_daylight(bpy.context.scene, 52.0, 4.5, north=0.0)
    bpy.context.view_layer.update()
    return objects
