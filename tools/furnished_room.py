"""The furnished living room of Drake's tutorial (its shell, window and layout) from CC0 glTF assets.

The assets are Poly Haven models (CC0) as laid out by Drake's tutorial room
(``furnished_living_room.dmd.yaml``: a room shell with a window, a sofa, curtains, two
painted cabinets, a bookshelf, a stool). They are not part of this repository: pass the
directory that holds the ``.gltf`` files and their ``textures/``.

    ./run py tools/furnished_room.py ASSETS_DIR out/furnished_room.blend [--render out/real_room.png]

or from Python: ``build(asset_dir)`` returns ``{"sofa": [...], "curtain": [...]}`` (object
names), as ``tools/real_room.py``'s does (``benchmarks/real_room_bake.py`` uses both).

The room is imported the way an artist imports it (``bpy.ops.import_scene.gltf``), placed
as the layout file places it (z-up metres, rotations about +Z), stood at 52° N with
annual daylight (:func:`lightfade_addon.api.set_daylight`), and the fabrics, paints and
woods are marked for aging with the recipe an artist would pick. Nothing is baked.
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys

#: (glTF file, translation in metres, rotation about +Z in degrees): the layout's welds.
LAYOUT = (
    ("living_room.gltf", (0.0, 0.0, 0.0), 0.0),
    ("painted_wooden_cabinet_1k.gltf", (-1.7753, 2.5818, 0.0), 0.0),
    ("wooden_bookshelf_worn_1k.gltf", (2.716, -1.0716, 0.0), -90.0),
    ("painted_wooden_cabinet_02_1k.gltf", (0.0235, 2.6566, 0.0), 0.0),
    ("sofa_03_1k.gltf", (0.0, -2.4117, 0.0), 180.0),
    ("painted_wooden_stool_1k.gltf", (1.7744, 1.6287, 0.0), 30.0),
    ("curtain_open.gltf", (0.0, 0.0, 0.0), 0.0),
)

#: Material name (as imported) -> recipe an artist would choose.
RECIPES = {
    "sofa_03": "DYED_FABRIC",
    "curtain": "DYED_FABRIC",
    "DoorMat": "DYED_FABRIC",
    "painted_wooden_cabinet": "PAINTED_WOOD",
    "painted_wooden_cabinet_02": "PAINTED_WOOD",
    "painted_wooden_stool": "PAINTED_WOOD",
    "wooden_bookshelf_worn": "BARE_WOOD",
    "Floor": "BARE_WOOD",
}


def import_layout(assets):
    """Import every model of :data:`LAYOUT` and place it; returns the new objects."""
    import bpy

    made = []
    for name, (x, y, z), rz in LAYOUT:
        before = set(bpy.data.objects)
        bpy.ops.import_scene.gltf(filepath=str(assets / name))
        new = [o for o in bpy.data.objects if o not in before]
        holder = bpy.data.objects.new(pathlib.Path(name).stem, None)
        bpy.context.scene.collection.objects.link(holder)
        holder.location = (x, y, z)
        holder.rotation_euler = (0.0, 0.0, math.radians(rz))
        for ob in new:
            if ob.parent is None:
                ob.parent = holder
        made += new
    return made


def mark_materials(recipes=RECIPES):
    """Tick *Age this Material* with the recipe of :data:`RECIPES` where a name matches."""
    import bpy

    marked = []
    for mat in bpy.data.materials:
        recipe = recipes.get(mat.name)
        if recipe is not None:
            mat.lightfade.enabled = True
            mat.lightfade.recipe = recipe
            marked.append(mat.name)
    return marked


def build(assets, latitude=52.0, longitude=5.0, north=0.0):
    """Build the room into a fresh file with LightFade enabled (nothing baked); returns
    ``{role: [object names]}``: ``sofa`` and ``curtain`` (the meshes using those
    materials), as :func:`tools.real_room.build` does."""
    import bpy

    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
    import lightfade_addon
    from lightfade_addon import api

    bpy.ops.wm.read_factory_settings(use_empty=True)
    lightfade_addon.register()
    import_layout(pathlib.Path(assets).resolve())
    mark_materials()
    scene = bpy.context.scene
    clear_glass()
    add_view_light(scene)
    api.set_daylight(scene, latitude, longitude, north=north)
    bpy.context.view_layer.update()
    roles = {}
    for role, material in (("sofa", "sofa_03"), ("curtain", "curtain")):
        roles[role] = [o.name for o in bpy.data.objects if o.type == "MESH"
                       and any(m is not None and m.name == material for m in o.data.materials)]
    return roles


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("assets", type=pathlib.Path)
    ap.add_argument("output", type=pathlib.Path)
    ap.add_argument("--latitude", type=float, default=52.0)
    ap.add_argument("--longitude", type=float, default=5.0)
    ap.add_argument("--north", type=float, default=0.0)
    ap.add_argument("--render", type=pathlib.Path)
    args = ap.parse_args(argv)

    import bpy

    roles = build(args.assets, args.latitude, args.longitude, args.north)
    print(", ".join(f"{role}: {names}" for role, names in roles.items()))
    scene = bpy.context.scene
    args.output.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(args.output.resolve()))
    print("saved", args.output)
    if args.render:
        render_view(scene, args.render)


def clear_glass(name="Glass"):
    """The window pane imports opaque (glTF has no transmission here): make it clear, as an
    artist would. Cycles' shadow rays stop at refractive glass, so the pane is made 92 %
    transparent (alpha 0.08, about what a pane reflects), keeping its emission (the glTF's
    ``emissiveFactor``) as imported."""
    import bpy

    mat = bpy.data.materials.get(name)
    if mat is None or mat.node_tree is None:
        return
    for node in mat.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            node.inputs["Alpha"].default_value = 0.08
            node.inputs["Roughness"].default_value = 0.0


def add_view_light(scene, elevation=35.0, strength=4.0):
    """A sun through the window (the room's window faces -Y) and a pale sky, for renders.

    Once the scene has a place, the annual daylight bake replaces both (they are the
    scene's daylight); they only light what a render shows.
    """
    import bpy

    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.data.energy = strength
    sun.rotation_euler = (math.radians(90.0 - elevation), 0.0, math.radians(20.0))
    sun.data.lightfade.spectrum = "DAYLIGHT_GLASS"
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    if world.node_tree is None:           # Blender 4.2; from 5.0 every World has nodes
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.55, 0.65, 0.8, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6


#: The room's view from inside, looking at the sofa and the window: (location in metres,
#: rotation in degrees (X, Y, Z), lens in mm).
ROOM_VIEW = ((0.5, 2.0, 1.5), (78.0, 0.0, 175.0), 18.0)


def place_camera(scene, name="LightFadeRoomCamera", location=ROOM_VIEW[0],
                 rotation=ROOM_VIEW[1], lens=ROOM_VIEW[2]):
    """The camera ``name`` (made if missing) at ``location`` (m), turned by ``rotation``
    (degrees), made the scene's camera."""
    import bpy

    cam = bpy.data.objects.get(name)
    if cam is None:
        cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
        scene.collection.objects.link(cam)
    cam.location = location
    cam.rotation_euler = tuple(math.radians(a) for a in rotation)
    cam.data.lens = lens
    scene.camera = cam
    return cam


def render_view(scene, path, samples=16, size=(480, 270)):
    """A quick Cycles still from inside the room looking at the sofa."""
    import bpy

    place_camera(scene)
    scene.render.engine = "CYCLES"
    scene.cycles.samples = samples
    scene.cycles.device = "CPU"
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.filepath = str(pathlib.Path(path).resolve())
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    main()
