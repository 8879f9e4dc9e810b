"""Four instances of one chair collection around a table, two in the sun, two in a wall's
shadow, and a geometry-nodes line of books half in the sun: the scene of issue 37
(instances aged where each one stands).

``build()`` makes it in the current file (the tests use it); run as a script, it bakes,
ages 30 years and renders the chairs before and after, side by side::

    ./run py -m scenes.instanced_chairs out/chairs            # before.png, after.png, sheet.png

The chair is one mesh (seat, back, four legs) with its own non-overlapping UVs in a
collection that is not in the scene: only the four empties instance it.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import bpy
import numpy as np

#: Where the four chairs stand (x, y, rotation about z in degrees; they face the table):
#: two at x < 0 in the sun, two at x > 0 behind the wall.
CHAIRS = ((-1.6, -0.9, 90.0), (-1.6, 0.9, 90.0), (1.6, -0.9, -90.0), (1.6, 0.9, -90.0))
#: The wall's centre and size (m): it shades x > 0.3 from a sun 40 degrees from the zenith
#: (its shadow reaches y = 1.6).
WALL = ((2.0, -2.6, 2.5), (3.4, 0.1, 5.0))


def _box(verts, faces, uvs, centre, size, cell):
    """Append an axis-aligned box with each face in its own UV cell (``cell`` = (first
    index, cells per row)): a non-overlapping unwrap."""
    cx, cy, cz = centre
    hx, hy, hz = (s / 2 for s in size)
    corners = [(cx + sx * hx, cy + sy * hy, cz + sz * hz)
               for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    quads = ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3))
    first, per_row = cell
    for k, quad in enumerate(quads):
        i = first + k
        u0, v0, w = (i % per_row) / per_row, (i // per_row) / per_row, 1.0 / per_row
        pad = 0.08 * w
        base = len(verts)
        verts.extend(corners[q] for q in quad)
        faces.append(tuple(range(base, base + 4)))
        uvs.extend([(u0 + pad, v0 + pad), (u0 + w - pad, v0 + pad),
                    (u0 + w - pad, v0 + w - pad), (u0 + pad, v0 + w - pad)])


def chair_mesh(name="Chair"):
    """Seat, back and four legs as one mesh with a non-overlapping UV map."""
    parts = [((0, 0, 0.45), (0.45, 0.45, 0.05)), ((0, 0.2, 0.75), (0.45, 0.05, 0.55))]
    parts += [((sx * 0.19, sy * 0.19, 0.21), (0.05, 0.05, 0.42))
              for sx in (-1, 1) for sy in (-1, 1)]
    verts, faces, uvs = [], [], []
    per_row = math.ceil(math.sqrt(6 * len(parts)))
    for k, (centre, size) in enumerate(parts):
        _box(verts, faces, uvs, centre, size, (6 * k, per_row))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    layer.data.foreach_set("uv", np.array(uvs, dtype=np.float32).ravel())
    return mesh


#: The geometry-nodes line of books in front of the wall: first book's x, spacing, count
#: (four in the sun at x < 0.3, four in the shade).
BOOKS = (-2.8, 0.8, 8)
BOOK_Y = -1.9


def book_mesh(name="Book"):
    """A standing book (4 × 16 × 24 cm) with a non-overlapping UV map."""
    verts, faces, uvs = [], [], []
    _box(verts, faces, uvs, (0.0, 0.0, 0.12), (0.04, 0.16, 0.24), (0, 3))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    layer.data.foreach_set("uv", np.array(uvs, dtype=np.float32).ravel())
    return mesh


def scatter_tree(source, start, step, count, y):
    """Geometry nodes: ``count`` instances of ``source`` along x (a Mesh Line)."""
    tree = bpy.data.node_groups.new("Book Line", "GeometryNodeTree")
    for side in ("INPUT", "OUTPUT"):
        tree.interface.new_socket("Geometry", in_out=side, socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    line = nodes.new("GeometryNodeMeshLine")
    line.inputs["Count"].default_value = count
    line.inputs["Start Location"].default_value = (start, y, 0.0)
    line.inputs["Offset"].default_value = (step, 0.0, 0.0)
    info = nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = source
    info.inputs["As Instance"].default_value = True
    place = nodes.new("GeometryNodeInstanceOnPoints")
    links.new(line.outputs[0], place.inputs["Points"])
    links.new(info.outputs["Geometry"], place.inputs["Instance"])
    links.new(place.outputs[0], nodes.new("NodeGroupOutput").inputs[0])
    nodes.new("NodeGroupInput")
    return tree


def _material(name, rgb, ages):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*rgb, 1.0)
    mat.lightfade.enabled = ages
    return mat


def _plane(name, size, location, rotation=(0.0, 0.0, 0.0), material=None):
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = (*size, 1.0)
    if material is not None:
        obj.data.materials.append(material)
    return obj


def build():
    """The scene in the current (empty) file: returns its parts."""
    scene = bpy.context.scene
    fabric = _material("Chair Fabric", (0.55, 0.08, 0.1), ages=True)
    grey = _material("Grey", (0.5, 0.5, 0.5), ages=False)
    collection = bpy.data.collections.new("Chair")       # not linked to the scene
    chair = bpy.data.objects.new("Chair", chair_mesh())
    chair.data.materials.append(fabric)
    collection.objects.link(chair)
    empties = []
    for i, (x, y, rz) in enumerate(CHAIRS):
        empty = bpy.data.objects.new(f"Chair {i + 1}", None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = collection
        empty.location = (x, y, 0.0)
        empty.rotation_euler = (0.0, 0.0, math.radians(rz))
        scene.collection.objects.link(empty)
        empties.append(empty)
    cloth = _material("Book Cloth", (0.1, 0.25, 0.6), ages=True)
    book = bpy.data.objects.new("Book", book_mesh())
    book.data.materials.append(cloth)
    scene.collection.objects.link(book)
    book.hide_viewport = book.hide_render = True              # a scatter's source, hidden
    shelf = bpy.data.objects.new("Books", bpy.data.meshes.new("Books"))
    scene.collection.objects.link(shelf)
    shelf.modifiers.new("Book Line", "NODES").node_group = scatter_tree(book, *BOOKS, BOOK_Y)
    floor = _plane("Floor", (8.0, 8.0), (0.0, 0.0, 0.0), material=grey)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.36))
    table = bpy.context.active_object
    table.name = "Table"
    table.scale = (1.2, 1.6, 0.72)
    table.data.materials.append(grey)
    (wx, wy, wz), (sx, sy, sz) = WALL
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(wx, wy, wz))
    wall = bpy.context.active_object
    wall.name = "Wall"
    wall.scale = (sx, sy, sz)
    wall.data.materials.append(grey)
    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy = 3.0
    sun_data.angle = math.radians(1.0)
    sun = bpy.data.objects.new("Sun", sun_data)
    scene.collection.objects.link(sun)
    sun.rotation_euler = (math.radians(40.0), 0.0, 0.0)        # from -y, shadows fall to +y
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    return {"chair": chair, "collection": collection, "empties": empties, "floor": floor,
            "table": table, "wall": wall, "sun": sun, "material": fabric, "book": book,
            "books": shelf, "cloth": cloth}


def add_camera(scene):
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    cam.location = (0.0, 7.0, 5.5)                  # from the north: the wall behind
    cam.rotation_euler = (math.radians(52.0), 0.0, math.radians(180.0))
    cam.data.lens = 35.0
    scene.camera = cam
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.15
    scene.world = world
    return cam


def top_view_fades(scene, years, out, size=600):
    """ΔE00 (median over a few pixels) between 0 and ``years`` of each chair's seat and
    each book's top, from an orthographic Cycles render from above (1 cm a pixel)."""
    from lightfade_addon import api
    from lightfade_addon.core.colour.colorimetry import (XYZ_to_Lab, delta_E_2000,
                                                         linear_srgb_to_XYZ)

    cam = bpy.data.objects.new("Top", bpy.data.cameras.new("Top"))
    scene.collection.objects.link(cam)
    cam.data.type, cam.data.ortho_scale = "ORTHO", 6.0
    cam.location = (0.0, 0.0, 6.0)
    camera, scene.camera = scene.camera, cam
    settings = (scene.render.resolution_x, scene.render.resolution_y,
                scene.render.image_settings.file_format)
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.image_settings.file_format = "OPEN_EXR"
    frames = []
    for y in (0.0, years):
        api.set_years(scene, y)
        scene.render.filepath = str(out / f"top_{y:g}.exr")
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(scene.render.filepath)
        frames.append(np.array(image.pixels[:], dtype=np.float32).reshape(size, size, 4))
        bpy.data.images.remove(image)
    scene.camera = camera
    bpy.data.objects.remove(cam)
    (scene.render.resolution_x, scene.render.resolution_y,
     scene.render.image_settings.file_format) = settings

    def fade(x, y):
        r, c = int((y + 3.0) / 6.0 * size), int((x + 3.0) / 6.0 * size)
        lab = [XYZ_to_Lab(linear_srgb_to_XYZ(np.clip(f[r - 1:r + 2, c:c + 1, :3], 1e-6, None)
                                             .reshape(-1, 3).astype(float))) for f in frames]
        return float(np.median(delta_E_2000(*lab)))

    start, step, count = BOOKS
    return ([fade(x, y) for x, y, _ in CHAIRS],
            [fade(start + k * step, BOOK_Y) for k in range(count)])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--years", type=float, default=30.0)
    parser.add_argument("--samples", type=int, default=64)
    args = parser.parse_args(argv)
    import addon_utils

    from scenes.render import configure_render
    from lightfade_addon import api
    from lightfade_addon.contact_sheet import contact_sheet
    from PIL import Image

    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    scene = bpy.context.scene
    build()
    add_camera(scene)
    configure_render(scene, 640, 400, args.samples, view_transform="Standard")
    args.out.mkdir(parents=True, exist_ok=True)
    result = api.bake(scene, quality="PREVIEW")
    print("baked", list(result["maps"]), f"{result['seconds']:.1f} s")
    api.age_scene(scene, years=0)
    frames = []
    for years, name in ((0.0, "before"), (args.years, "after")):
        api.set_years(scene, years)
        scene.render.filepath = str(args.out / f"{name}.png")
        bpy.ops.render.render(write_still=True)
        frames.append((scene.render.filepath, f"{years:g} years"))
    chairs, books = top_view_fades(scene, args.years, args.out)
    print(f"{args.years:g} years, dE00 of each seat (chairs 1-2 in the sun):",
          " ".join(f"{d:.1f}" for d in chairs))
    print(f"{args.years:g} years, dE00 of each book's top (x < 0 in the sun):",
          " ".join(f"{d:.1f}" for d in books))
    api.set_years(scene, args.years)
    bpy.ops.wm.save_as_mainfile(filepath=str(args.out / "chairs.blend"))
    sheet = contact_sheet([Image.open(p).convert("RGB") for p, _ in frames],
                          [label for _, label in frames],
                          ["chairs 1-2 and the books at x < 0 in the sun"] * 2,
                          title="One chair collection instanced four times: aged per instance")
    sheet.save(args.out / "sheet.png")
    print("wrote", args.out / "sheet.png")


if __name__ == "__main__":
    main()
