"""A furnished living room from a directory of glTF models (Poly Haven CC0 assets).

Usage (from the repository root)::

    python tools/real_room.py ASSET_DIR [--save room.blend] [--render room.png]

or from Python: ``build(asset_dir)`` returns ``{role: [object names]}``.

The room (metres, z up, scene +Y is geographic north): inside x in [-2.5, 2.5], y in
[-2.25, 2.25], z in [0, 3]; one window in the south wall (y = -2.25), the opening x in
[-1, 1], z in [0.7, 2.5], open (no glass).  Daylight: ``api.set_daylight`` at 52° N,
5° E, a clear sky (one annual bake of the year's sun and sky).  Models are found by their
file names and placed when present (nothing else is needed):

========================  =========================================================
file name contains        placed
========================  =========================================================
``sofa``                  against the north wall, facing the window
``curtain``               just inside the window (panels drawn to the sides)
``cabinet_02``            against the west wall, facing east
``cabinet`` (other)       against the east wall, facing west
``stool``                 on the floor in front of the sofa
========================  =========================================================

Each model keeps its own materials (imported by Blender's glTF importer); LightFade is
enabled on the materials of the models, not on the walls and floor.  Assets are never
part of the repository: pass the directory they are in.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402

ROOM = dict(x=(-2.5, 2.5), y=(-2.25, 2.25), height=3.0)
WINDOW = dict(x=(-1.0, 1.0), z=(0.7, 2.5))
PLACE = dict(latitude=52.0, longitude=5.0, north=0.0)

#: (role, test on the lower-case file name, where: (x, y) of the model's origin, z turn in
#: degrees).  The models face -Y as exported; a turn of +90° makes them face +X.  The
#: curtain model hangs 2.85-3.0 m south of its origin: (0, 0.8) puts it 5-20 cm inside
#: the south wall.
PLACEMENTS = (
    ("sofa", lambda n: "sofa" in n, (0.0, 1.72), 0.0),
    ("curtain", lambda n: "curtain" in n, (0.0, 0.8), 0.0),
    ("tall_cabinet", lambda n: "cabinet_02" in n, (-2.15, 0.0), 90.0),
    ("cabinet", lambda n: "cabinet" in n and "cabinet_02" not in n, (2.17, 0.2), -90.0),
    ("stool", lambda n: "stool" in n, (0.9, 0.5), 20.0),
)


#: The recipe an artist picks for each model: fabric for the upholstery and curtains,
#: paint for the painted furniture (docs/recipes.md).
ROLE_RECIPES = {"sofa": "DYED_FABRIC", "curtain": "DYED_FABRIC", "tall_cabinet": "PAINTED_WOOD",
                "cabinet": "PAINTED_WOOD", "stool": "PAINTED_WOOD"}


def shell():
    """Floor, walls and ceiling (inward faces, one object each), the window left open."""
    from scenes import common as C
    from scenes.daylight_room import shell_quads
    from scenes.meshes import mesh_from_quads

    (x0, x1), (y0, y1) = ROOM["x"], ROOM["y"]
    walls = shell_quads(ROOM, WINDOW)
    mesh_from_quads("Walls", walls, material=C.plain_material("Wall_Paint", (0.7, 0.68, 0.64), 0.9))
    floor = ((x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0))
    mesh_from_quads("Floor", [floor], material=C.plain_material("Floor_Oak", (0.45, 0.3, 0.18), 0.6))


def import_model(path):
    """Import one glTF file; returns its new mesh objects, parented ones made top-level."""
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=str(path))
    new = [o for o in bpy.data.objects if o not in before]
    for obj in new:             # bake the import's hierarchy into world transforms
        world = obj.matrix_world.copy()
        obj.parent = None
        obj.matrix_world = world
    for obj in [o for o in new if o.type != "MESH"]:
        bpy.data.objects.remove(obj)
    return [o for o in new if o.name in bpy.data.objects]


def place(objects, xy, turn_deg):
    """Turn the model's objects about the z axis through the origin, then move them."""
    from mathutils import Matrix

    move = Matrix.Translation((xy[0], xy[1], 0.0)) @ Matrix.Rotation(
        math.radians(turn_deg), 4, "Z")
    for obj in objects:
        obj.matrix_world = move @ obj.matrix_world


def build(asset_dir, daylight=True):
    """Build the room into a fresh file with LightFade enabled; returns
    ``{role: [object names]}`` for the models found in ``asset_dir``."""
    import addon_utils

    from scenes import common as C

    C.reset()
    addon_utils.enable("lightfade_addon", default_set=True)
    shell()
    files = sorted(Path(asset_dir).glob("*.gltf")) + sorted(Path(asset_dir).glob("*.glb"))
    roles = {}
    for role, matches, xy, turn in PLACEMENTS:
        path = next((f for f in files if matches(f.name.lower())), None)
        if path is None:
            continue
        objects = import_model(path)
        place(objects, xy, turn)
        for obj in objects:
            for mat in obj.data.materials:
                if mat is not None:
                    mat.lightfade.enabled = True
                    mat.lightfade.recipe = ROLE_RECIPES[role]
        roles[role] = [o.name for o in objects]
    scene = bpy.context.scene
    if daylight:
        from lightfade_addon import api

        api.set_daylight(scene, **PLACE)
    bpy.context.view_layer.update()
    return roles


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("assets", help="directory of glTF models (sofa, curtain, cabinets...)")
    parser.add_argument("--save", help="save the room as this .blend")
    args = parser.parse_args()
    roles = build(args.assets)
    for role, names in roles.items():
        print(f"{role}: {', '.join(names)}")
    if args.save:
        bpy.ops.wm.save_as_mainfile(filepath=str(Path(args.save).resolve()))


if __name__ == "__main__":
    main()
