"""The paper's Figure 9 room: sunlight through a window fades a rug, a dresser and a poster
and yellows the oak floor, except where the rug and a table lamp stood.

Layout (metres, z up): the room's inside is x, y in [-2, 2], z in [0, 2.6]. The window is
in the left wall (x = -2); a low morning/winter sun shines through it toward +x, +y, so its
patch crosses the back of the rug, the floor in front of the dresser, the dresser top
with the lamp, and the lower part of the poster on the back wall (y = 2). The camera looks
from the front-right corner toward the back-left.

The room stands at 52° N with its window facing south (scene -X is geographic south:
``north = -90``, +X is north) under a clear sky (:data:`PLACE`, the scene's
``lightfade_place`` tag): its daylight exposure is one annual bake of the sun's path over
the year and the sky, so the rug fades in a band swept by the sun, not in the window's
shape at the render's instant.  The sun lamp and the sky colour still light the renders.

Run ``python -m scenes.room out.blend`` to build and save; ``--render out.png`` renders too.
"""

from __future__ import annotations

import math

import bpy

from . import cli
from . import common as C
from . import textures as T
from .meshes import box_quads, grid_mesh, lathe_mesh, mesh_from_quads
from .render import configure_render, save_blend, view_settings

ROOM = dict(x=(-2.0, 2.0), y=(-2.0, 2.0), height=2.6, wall=0.15)
WINDOW = dict(y=(-0.4, 1.5), z=(0.45, 2.3))  # opening in the x = -2 wall
SUN = dict(elevation=20.0, azimuth=20.0)  # low sun, travelling toward +x and +y
# Floor illuminance in the sun patch (horizontal surface), lux. Sun strength follows from it.
SUN_FLOOR_LUX = 20000.0
DRESSER = dict(x=(-1.45, -0.15), y=(1.48, 1.98), height=0.88)
LAMP_XY = (-0.95, 1.70)
FLOOR_TONES = ((0.84, 0.72, 0.55), (0.72, 0.59, 0.43))  # sRGB, lightest and darkest boards
RUG = dict(center=(-0.05, 0.55), size=(2.4, 1.6), height=0.006)
POSTER = dict(center=(-0.62, 1.45), size=(0.56, 0.78))

REMOVABLE = "Removable"
#: Where the room stands: the window (in the x = -2 wall) faces geographic south.
PLACE = dict(latitude=52.0, longitude=5.0, north=-90.0)


def _walls(coll):
    (x0, x1), (y0, y1), H, t = ROOM["x"], ROOM["y"], ROOM["height"], ROOM["wall"]
    (wy0, wy1), (wz0, wz1) = WINDOW["y"], WINDOW["z"]
    boxes = [
        ((x0 - t, y1, 0), (x1 + t, y1 + t, H)),  # back
        ((x0 - t, y0 - t, 0), (x1 + t, y0, H)),  # front (behind the camera)
        ((x1, y0, 0), (x1 + t, y1, H)),  # right
        ((x0 - t, y0, 0), (x0, wy0, H)),  # left wall, four pieces around the window
        ((x0 - t, wy1, 0), (x0, y1, H)),
        ((x0 - t, wy0, 0), (x0, wy1, wz0)),
        ((x0 - t, wy0, wz1), (x0, wy1, H)),
    ]
    quads = [q for lo, hi in boxes for q in box_quads(lo, hi)]
    walls = mesh_from_quads("Walls", quads, coll, C.plain_material("Wall_Paint", (0.62, 0.58, 0.50), 0.9))
    ceiling = mesh_from_quads(
        "Ceiling", box_quads((x0 - t, y0 - t, H), (x1 + t, y1 + t, H + t)), coll,
        C.plain_material("Ceiling_Paint", (0.75, 0.74, 0.70), 0.9))
    # window frame: outer frame, one vertical and one horizontal bar (painted white)
    f, d = 0.05, 0.06
    xm = x0 - t / 2
    frame = [
        ((xm - d / 2, wy0, wz0), (xm + d / 2, wy1, wz0 + f)),
        ((xm - d / 2, wy0, wz1 - f), (xm + d / 2, wy1, wz1)),
        ((xm - d / 2, wy0, wz0), (xm + d / 2, wy0 + f, wz1)),
        ((xm - d / 2, wy1 - f, wz0), (xm + d / 2, wy1, wz1)),
        ((xm - d / 2, (wy0 + wy1) / 2 - f / 2, wz0), (xm + d / 2, (wy0 + wy1) / 2 + f / 2, wz1)),
        ((xm - d / 2, wy0, wz0 + 0.62 * (wz1 - wz0)), (xm + d / 2, wy1, wz0 + 0.62 * (wz1 - wz0) + f)),
    ]
    frame_ob = mesh_from_quads("WindowFrame", [q for lo, hi in frame for q in box_quads(lo, hi)],
                               coll, C.plain_material("Frame_Paint", (0.8, 0.8, 0.78), 0.5))
    return walls, ceiling, frame_ob


def _floor(coll, res):
    (x0, x1), (y0, y1) = ROOM["x"], ROOM["y"]
    # Pale (white) oak: lignin yellowing reads clearly on it, as in the paper's Figure 9.
    img = C.image_from_array("Floor_Oak", T.wood_planks((res, res), extent=(x1 - x0, y1 - y0),
                                                        base=FLOOR_TONES[0], dark=FLOOR_TONES[1]))
    mat = C.aging_material("Floor_Oak", img, "bare-wood", roughness=0.45, specular=0.4)
    return grid_mesh("Floor", 1, 1, lambda u, v: (x0 + u * (x1 - x0), y0 + v * (y1 - y0), 0.0), coll, mat)


def _rug(coll, res):
    (cx, cy), (w, h) = RUG["center"], RUG["size"]
    img = C.image_from_array("Rug_Wool", T.rug((int(res * h / w), res)))
    mat = C.aging_material("Rug_Wool", img, "dyed-fabric", blue_wool=4, roughness=0.95, specular=0.2, sheen=0.4)
    z = RUG["height"]
    return grid_mesh("Rug", 1, 1, lambda u, v: (cx + (u - 0.5) * w, cy + (v - 0.5) * h, z), coll, mat)


def _dresser(coll, res):
    (x0, x1), (y0, y1), top = DRESSER["x"], DRESSER["y"], DRESSER["height"]
    leg, slab, over = 0.12, 0.03, 0.025
    boxes = [((x0, y0, leg), (x1, y1, top - slab), ("-z", "+y"))]  # carcass (back against the wall)
    boxes.append(((x0 - over, y0 - over, top - slab), (x1 + over, y1, top), ("+y",)))  # top slab
    for lx in (x0 + 0.03, x1 - 0.08):  # legs
        for ly in (y0 + 0.03, y1 - 0.08):
            boxes.append(((lx, ly, 0.0), (lx + 0.05, ly + 0.05, leg), ("+z",)))
    n, gap, margin = 3, 0.02, 0.04  # drawer fronts, proud of the carcass by 15 mm
    zlo, zhi = leg + margin, top - slab - margin
    dh = (zhi - zlo - (n - 1) * gap) / n
    knobs = []
    for i in range(n):
        z0 = zlo + i * (dh + gap)
        boxes.append(((x0 + margin, y0 - 0.015, z0), (x1 - margin, y0, z0 + dh), ("+y",)))
        for kx in (x0 + 0.3 * (x1 - x0), x0 + 0.7 * (x1 - x0)):
            knobs.append((kx, y0 - 0.015, z0 + dh / 2))
    quads = [q for lo, hi, skip in boxes for q in box_quads(lo, hi, skip)]
    img = C.image_from_array("Dresser_Paint", T.painted_wood((res, res), (0.10, 0.47, 0.50)))
    mat = C.aging_material("Dresser_Paint", img, "painted-wood", blue_wool=6, roughness=0.4, specular=0.5)
    dresser = mesh_from_quads("Dresser", quads, coll, mat, gap=4.0 / res)
    brass = C.plain_material("Brass", (0.8, 0.55, 0.25), 0.3, metallic=1.0)
    for k, (kx, ky, kz) in enumerate(knobs):
        ob = lathe_mesh(f"DresserKnob.{k}", [(0, 0), (0.008, 0.002), (0.008, 0.012), (0.015, 0.018),
                                              (0.012, 0.03), (0, 0.032)], 16, coll, brass)
        ob.location = (kx, ky, kz)
        ob.rotation_euler = (math.pi / 2, 0, 0)  # knob axis along -y, out of the drawer
    return dresser


def _lamp(coll):
    """Table lamp standing on the dresser: ceramic base, brass stem, linen shade, 60 W bulb."""
    x, y = LAMP_XY
    z = DRESSER["height"]
    ceramic = C.plain_material("Lamp_Ceramic", (0.55, 0.12, 0.08), 0.25)
    base = lathe_mesh("LampBase", [(0, 0), (0.085, 0), (0.085, 0.02), (0.06, 0.04), (0.07, 0.12),
                                    (0.05, 0.2), (0.015, 0.24), (0, 0.24)], 48, coll, ceramic, (x, y, z))
    stem = lathe_mesh("LampStem", [(0, 0.24), (0.008, 0.24), (0.008, 0.42), (0, 0.42)], 16, coll,
                      C.plain_material("Lamp_Brass", (0.8, 0.6, 0.3), 0.3, metallic=1.0), (x, y, z))
    shade_mat = C.plain_material("Lamp_Shade", (0.85, 0.78, 0.62), 0.9)
    shade = lathe_mesh("LampShade", [(0.17, 0.30), (0.11, 0.50)], 48, coll, shade_mat, (x, y, z))
    # An 800 lm incandescent bulb: 800 lm / 683 lm/W ~ 1.2 W in LightFade's convention, i.e.
    # ~700 lux on the dresser top 0.3 m away, ~80 lux at 1 m; on 5 hours a day.
    bulb = C.add_light("Lamp", "POINT", 800.0 / C.LUX_PER_W_M2, (x, y, z + 0.38), coll,
                       spectrum="incandescent", hours_per_day=5.0, uv_filter=False,
                       shadow_soft_size=0.02)
    return base, stem, shade, bulb


def _poster(coll, res):
    (cx, cz), (w, h) = POSTER["center"], POSTER["size"]
    y = ROOM["y"][1] - 0.004
    img = C.image_from_array("Poster_Print", T.poster((res, int(res * w / h))))
    mat = C.aging_material("Poster_Print", img, "printed-paper", blue_wool=2, roughness=0.5, specular=0.3)
    # u along +x, v up; the sheet faces -y (into the room)
    return grid_mesh("Poster", 1, 1, lambda u, v: (cx + (u - 0.5) * w, y, cz + (v - 0.5) * h), coll, mat)


def _curtain(coll, res):
    """A pleated curtain hanging beside the window, on its -y side."""
    x = ROOM["x"][0] + 0.07
    ya, yb = WINDOW["y"][0] - 0.62, WINDOW["y"][0] - 0.05
    z0, z1 = 0.03, 2.45
    img = C.image_from_array("Curtain_Cotton", T.fabric((res, res // 2), (0.72, 0.30, 0.12), threads=(160, 320)))
    mat = C.aging_material("Curtain_Cotton", img, "dyed-fabric", blue_wool=3, roughness=0.9, specular=0.2, sheen=0.5)

    def fn(u, v):
        return (x + 0.035 * math.sin(u * 2 * math.pi * 7), ya + u * (yb - ya), z0 + v * (z1 - z0))

    ob = grid_mesh("Curtain", 56, 1, fn, coll, mat, smooth=True)
    rod = lathe_mesh("CurtainRod", [(0, 0), (0.012, 0), (0.012, 2.6), (0, 2.6)], 12, coll,
                     C.plain_material("Rod_Metal", (0.1, 0.1, 0.1), 0.4, metallic=1.0),
                     (x, ya - 0.1, 2.5))
    rod.rotation_euler = (-math.pi / 2, 0, 0)  # along +y
    return ob


def set_reveal(reveal=True):
    """Hide (True) or show (False) the rug and the lamp: the paper's Figure 9 bottom."""
    C.set_hidden(C.collection_objects(bpy.data.collections[REMOVABLE]), reveal)


def build(path=None, resolution=1024):
    """Build the room into the current file; save to ``path`` (.blend, images packed) if given.

    Parameters
    ----------
    resolution : int
        Size of the floor texture (texels per side, 4 m); the other albedo images scale
        from it (rug and dresser = resolution, poster and curtain = resolution / 2).

    Returns
    -------
    dict
        ``camera``, ``cameras``, ``sun``, ``lights``, ``removable`` (object names hidden by
        :func:`set_reveal`), and object names by role (``floor``, ``rug``, ``dresser``,
        ``lamp``, ``poster``, ``curtain``), plus ``materials`` (aging material names).
    """
    scene = C.reset()
    scene.name = "Room"
    scene.unit_settings.system = "METRIC"
    room = C.collection("Room")
    furniture = C.collection("Furniture")
    removable = C.collection(REMOVABLE)
    lights = C.collection("Lights")

    _walls(room)
    floor = _floor(room, resolution)
    dresser = _dresser(furniture, resolution)
    poster = _poster(furniture, max(64, resolution // 2))
    curtain = _curtain(furniture, max(64, resolution // 2))
    rug = _rug(removable, resolution)
    lamp = _lamp(removable)

    # Sun through the window, "daylight-glass" (window glass cuts UV below ~320 nm).
    # Strength chosen for SUN_FLOOR_LUX on horizontal surfaces (floor, dresser top):
    # 85.6 W/m^2 ~ 58,500 lux at normal incidence, 20,000 lux on the floor at 20 deg elevation,
    # ~18,800 lux on the poster (cos 20 deg x sin 20 deg of normal). Sun in the room ~6 h a day.
    strength = C.sun_strength_for_lux(SUN_FLOOR_LUX, SUN["elevation"])
    sun = C.add_light("Sun", "SUN", strength, (-4.0, -2.0, 3.0), lights,
                      spectrum="daylight-glass", hours_per_day=6.0, uv_filter=False,
                      direction=C.sun_direction(SUN["elevation"], SUN["azimuth"]), angle=math.radians(0.8))
    # Sky seen through the window: uniform strength 2 (~4,300 lux on an unobstructed
    # horizontal plane outside; far less indoors). Tagged on the world for the same schedule.
    world = C.world_sky(scene, (0.55, 0.70, 1.0), 2.0)
    world["lightfade_spectrum"] = "daylight-glass"
    world["lightfade_hours_per_day"] = 10.0
    world["lightfade_uv_filter"] = False
    # The place and climate (clear sky): daylight over the year replaces sun and sky above.
    scene["lightfade_place"] = dict(PLACE)

    cam = C.add_camera("Camera", (1.30, -1.50, 1.35), (-0.70, 1.20, 0.60), lens=22.0)
    detail = C.add_camera("Camera.Dresser", (0.35, 0.05, 1.55), (-0.85, 1.70, 0.80), lens=30.0)
    scene.camera = cam

    configure_render(scene)
    scene.view_settings.exposure = -2.0
    scene.view_settings.look = "AgX - Medium High Contrast"

    info = dict(
        scene=scene.name,
        camera=cam.name,
        cameras=[cam.name, detail.name],
        sun=sun.name,
        lights=[sun.name, lamp[3].name],
        floor=floor.name,
        rug=rug.name,
        dresser=dresser.name,
        lamp=[o.name for o in lamp],
        poster=poster.name,
        curtain=curtain.name,
        removable=sorted(o.name for o in C.collection_objects(removable)),
        materials=sorted(m.name for m in C.tagged_materials()),
        view=view_settings(scene),
    )
    if path:
        save_blend(path)
    return info


if __name__ == "__main__":
    cli.main(build, __doc__.splitlines()[0])
