"""A small room lit through a mullioned south window: the annual-daylight test room.

Layout (metres, z up, scene +Y is geographic north): the room's inside is x, y in
[-2, 2], z in [0, 2.5]; the window is in the south wall (y = -2), the opening x in
[-1, 1], z in [0.5, 2.0], split by a 0.1 m vertical bar at x = 0 and a 0.06 m
horizontal bar at z = 1.25.  A 0.6 m box stands on the floor at (1.2, 0.6); a 2 × 1.2 m
rug lies in front of the window.  ``static_sun`` adds a sun lamp for one instant (noon
at the equinox at 52° N: 38° up, due south) to compare with the annual bake.

Used by ``benchmarks/daylight_bake.py`` and ``scenes/daylight_figures.py``.
"""

from __future__ import annotations

import math

import bpy

from . import common as C
from .meshes import box_quads, mesh_from_quads

ROOM = dict(x=(-2.0, 2.0), y=(-2.0, 2.0), height=2.5)
WINDOW = dict(x=(-1.0, 1.0), z=(0.5, 2.0), bar=0.1, rail=0.06)
BOX = dict(center=(1.2, 0.6), size=0.6)
RUG = dict(center=(-0.2, -0.6), size=(2.0, 1.2), height=0.005)
PLACE = dict(latitude=52.0, longitude=5.0, north=0.0)


def _wall_y(y, x0, x1, z0, z1):
    return ((x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1))


def shell_quads(room, window):
    """Quads (inward faces) of the walls and ceiling of ``room`` (``x``, ``y`` ranges and
    ``height``, metres) with ``window`` (``x``, ``z`` ranges) left open in the south wall."""
    (x0, x1), (y0, y1), H = room["x"], room["y"], room["height"]
    (wx0, wx1), (wz0, wz1) = window["x"], window["z"]
    return [
        _wall_y(y0, x0, wx0, 0, H), _wall_y(y0, wx1, x1, 0, H),
        _wall_y(y0, wx0, wx1, 0, wz0), _wall_y(y0, wx0, wx1, wz1, H),
        ((x1, y1, 0), (x0, y1, 0), (x0, y1, H), (x1, y1, H)),
        ((x0, y1, 0), (x0, y0, 0), (x0, y0, H), (x0, y1, H)),
        ((x1, y0, 0), (x1, y1, 0), (x1, y1, H), (x1, y0, H)),
        ((x0, y1, H), (x1, y1, H), (x1, y0, H), (x0, y0, H)),
    ]


def walls(bars=True):
    """Walls and ceiling as one object (inward faces), the window opening left open."""
    (x0, x1), (y0, y1) = ROOM["x"], ROOM["y"]
    (wx0, wx1), (wz0, wz1) = WINDOW["x"], WINDOW["z"]
    quads = shell_quads(ROOM, WINDOW)
    paint = C.plain_material("Wall_Paint", (0.7, 0.68, 0.64), 0.9)
    room = mesh_from_quads("Walls", quads, material=paint)
    if bars:
        b, r, zm = WINDOW["bar"] / 2, WINDOW["rail"] / 2, sum(WINDOW["z"]) / 2
        frame = box_quads((-b, y0 - 0.05, wz0), (b, y0 + 0.05, wz1)) + \
            box_quads((wx0, y0 - 0.03, zm - r), (wx1, y0 + 0.03, zm + r))
        mesh_from_quads("Mullion", frame, material=C.plain_material("Frame", (0.9, 0.9, 0.88)))
    return room


def _plane(name, size, center, z, material):
    (sx, sy), (cx, cy) = size, center
    quad = ((cx - sx / 2, cy - sy / 2, z), (cx + sx / 2, cy - sy / 2, z),
            (cx + sx / 2, cy + sy / 2, z), (cx - sx / 2, cy + sy / 2, z))
    return mesh_from_quads(name, [quad], material=material)


def build(bars=True):
    """Build the room into a fresh file; returns its object names by role."""
    C.reset()
    walls(bars)
    floor = _plane("Floor", (4.0, 4.0), (0.0, 0.0), 0.0,
                   C.plain_material("Floor_Oak", (0.55, 0.38, 0.22), 0.6))
    floor.data.materials[0]["lightfade_recipe"] = "bare-wood"
    rug = _plane("Rug", RUG["size"], RUG["center"], RUG["height"],
                 C.plain_material("Rug_Wool", (0.45, 0.08, 0.10), 0.9))
    rug.data.materials[0]["lightfade_recipe"] = "dyed-fabric"
    s, (cx, cy) = BOX["size"], BOX["center"]
    box = mesh_from_quads("Box", box_quads((cx - s / 2, cy - s / 2, 0.0),
                                           (cx + s / 2, cy + s / 2, s), skip=("-z",)),
                          material=C.plain_material("Box_Paint", (0.3, 0.3, 0.32), 0.8))
    return dict(floor=floor.name, rug=rug.name, box=box.name)


def static_sun(elevation=38.0, azimuth=180.0, lux=None):
    """A sun lamp at ``elevation`` degrees, ``azimuth`` degrees clockwise from north
    (+Y), 0.53° wide.  Its strength gives ``lux`` on a plane facing it; default: a clear
    direct beam, 1000 W/m² × 0.7^(AM^0.678) (Meinel and Meinel 1976, air mass 1/sin e)
    at 105 lm/W (a typical direct-beam luminous efficacy), ~64,000 lux at 38°."""
    if lux is None:
        air_mass = 1.0 / math.sin(math.radians(elevation))
        lux = 105.0 * 1000.0 * 0.7 ** (air_mass ** 0.678)
    data = bpy.data.lights.new("Sun", "SUN")
    data.energy = lux / 683.0          # LightFade: 683 lm per Blender watt
    data.angle = math.radians(0.53)
    sun = bpy.data.objects.new("Sun", data)
    bpy.context.scene.collection.objects.link(sun)
    # along -Z locally: tilt to the zenith angle, then turn to the azimuth (toward the sun)
    sun.rotation_euler = (math.radians(90.0 - elevation), 0.0, math.radians(180.0 - azimuth))
    return sun
