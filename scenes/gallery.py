"""A museum wall with three identical colour prints, each under its own spot light:

- ``Print.50lx_LED``: 50 lux, LED, UV filtered (the conservator's choice for sensitive works);
- ``Print.150lx_LED``: 150 lux, LED, UV filtered (three times the dose rate);
- ``Print.50lx_Daylight``: 50 lux, daylight spectrum, no UV filter (UV-rich).

Same image, same recipe: any difference after aging comes from dose and spectrum alone.
Run ``python -m scenes.gallery out.blend`` to build and save.
"""

from __future__ import annotations

import math

import bpy

from . import cli
from . import common as C
from . import textures as T
from .meshes import box_quads, grid_mesh, mesh_from_quads
from .render import configure_render, save_blend, view_settings

WALL_Y = 0.0  # the wall's face; the room is at y < 0
PRINT_SIZE = (0.56, 0.78)
PRINT_Z = 1.55
SPOT_OFFSET = (-1.5, 3.1)  # (y, z) of the ceiling track
HOURS_PER_DAY = 8.0  # museum opening hours
PRINTS = (
    # name suffix, x, lux, spectrum, uv_filter, label
    ("50lx_LED", -1.75, 50.0, "led", True, "50 lx  LED, UV filtered"),
    ("150lx_LED", 0.0, 150.0, "led", True, "150 lx  LED, UV filtered"),
    ("50lx_Daylight", 1.75, 50.0, "daylight", False, "50 lx  daylight, with UV"),
)


def _label(name, text, location, coll, mat):
    curve = bpy.data.curves.new(name, "FONT")
    curve.body = text
    curve.size = 0.06
    curve.align_x = "CENTER"
    ob = bpy.data.objects.new(name, curve)
    ob.location = location
    ob.rotation_euler = (math.pi / 2, 0, 0)  # upright, facing -y
    ob.data.materials.append(mat)
    coll.objects.link(ob)
    return ob


def build(path=None, resolution=512):
    """Build the gallery wall into the current file; save to ``path`` if given.

    Parameters
    ----------
    resolution : int
        Height of each print's albedo image in texels (width follows the aspect ratio).

    Returns
    -------
    dict
        ``camera``, ``cameras``, ``prints`` (object names, left to right), ``spots`` (light
        names, same order), ``lux`` (intended illuminance at each print centre),
        ``materials``.
    """
    scene = C.reset()
    scene.name = "Gallery"
    room = C.collection("Room")
    art = C.collection("Prints")
    lights = C.collection("Lights")

    wall = C.plain_material("Wall_Paint", (0.16, 0.17, 0.20), 0.9)
    mesh_from_quads("Wall", box_quads((-4, WALL_Y, 0), (4, WALL_Y + 0.2, 3.4)), room, wall)
    mesh_from_quads("Floor", box_quads((-4, -5, -0.1), (4, WALL_Y, 0)), room,
                    C.plain_material("Floor_Stone", (0.25, 0.24, 0.22), 0.6))
    frame_mat = C.plain_material("Frame_Black", (0.02, 0.02, 0.02), 0.4)
    label_mat = C.plain_material("Label_Ink", (0.7, 0.7, 0.7), 0.6)

    picture = T.poster((resolution, int(resolution * PRINT_SIZE[0] / PRINT_SIZE[1])), seed=5)
    w, h = PRINT_SIZE
    prints, spots, lux = [], [], {}
    for suffix, x, E, spectrum, uv_filter, text in PRINTS:
        img = C.image_from_array(f"Print_{suffix}", picture)
        mat = C.aging_material(f"Print_{suffix}", img, "printed-paper", blue_wool=2, roughness=0.5, specular=0.3)
        y = WALL_Y - 0.022
        ob = grid_mesh(f"Print.{suffix}", 1, 1,
                       lambda u, v, x=x, y=y: (x + (u - 0.5) * w, y, PRINT_Z + (v - 0.5) * h), art, mat)
        prints.append(ob.name)
        # a black frame 4 cm wide, 2.5 cm deep, around the print
        f = 0.04
        lo, hi = (x - w / 2 - f, PRINT_Z - h / 2 - f), (x + w / 2 + f, PRINT_Z + h / 2 + f)
        bars = [((lo[0], lo[1]), (hi[0], lo[1] + f)), ((lo[0], hi[1] - f), (hi[0], hi[1])),
                ((lo[0], lo[1]), (lo[0] + f, hi[1])), ((hi[0] - f, lo[1]), (hi[0], hi[1]))]
        mesh_from_quads(f"Frame.{suffix}", [q for (a, b) in bars for q in
                                            box_quads((a[0], WALL_Y - 0.025, a[1]), (b[0], WALL_Y, b[1]))],
                        art, frame_mat)
        _label(f"Label.{suffix}", text, (x, WALL_Y - 0.002, PRINT_Z - h / 2 - 0.14), art, label_mat)
        # Spot on the ceiling track aimed at the print centre; power from the intended lux:
        # E = P cos(theta) / (4 pi d^2) W/m^2, 683 lux per W/m^2.
        sy, sz = SPOT_OFFSET
        target = (x, y, PRINT_Z)
        d = math.dist((x, sy, sz), target)
        cos_t = (y - sy) / d  # the print faces -y
        P = C.point_power_for_lux(E, d, cos_t)
        spot = C.add_light(f"Spot.{suffix}", "SPOT", P, (x, sy, sz), lights, spectrum=spectrum,
                           hours_per_day=HOURS_PER_DAY, uv_filter=uv_filter, target=target,
                           spot_size=math.radians(30), spot_blend=0.3, shadow_soft_size=0.03)
        spot.data["lightfade_lux"] = E  # intended illuminance at the print centre, for reference
        spots.append(spot.name)
        lux[ob.name] = E

    # Faint ambient (~2 lux on the wall) so that the wall between the pools is not black.
    world = C.world_sky(scene, (0.8, 0.82, 0.85), 0.002)
    world["lightfade_spectrum"] = "led"
    world["lightfade_hours_per_day"] = HOURS_PER_DAY
    world["lightfade_uv_filter"] = True

    cam = C.add_camera("Camera", (0.0, -4.2, 1.55), (0.0, WALL_Y, 1.4), lens=34.0)
    scene.camera = cam
    configure_render(scene)
    scene.view_settings.exposure = 4.0
    scene.view_settings.look = "AgX - Medium High Contrast"

    info = dict(scene=scene.name, camera=cam.name, cameras=[cam.name], prints=prints, spots=spots,
                lux=lux, lights=spots, materials=sorted(m.name for m in C.tagged_materials()),
                view=view_settings(scene))
    if path:
        save_blend(path)
    return info


if __name__ == "__main__":
    cli.main(build, __doc__.splitlines()[0], default_resolution=512)
