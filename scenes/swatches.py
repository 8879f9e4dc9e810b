"""A print-test colour chart under a strong light, half covered by an opaque card.

The chart (rows C, M, Y, CM, MY, CY, CMY; columns 0-100 % coverage) is printed twice side
by side on one sheet; a grey card lying 5 mm above the sheet covers the right-hand copy,
so every patch has an exposed twin (left) and an unexposed one (right), as in a Blue Wool
exposure test. ``set_reveal(True)`` hides the card to compare the two.
Run ``python -m scenes.swatches out.blend`` to build and save.
"""

from __future__ import annotations

import bpy

from . import cli
from . import common as C
from . import textures as T
from .meshes import box_quads, grid_mesh, mesh_from_quads
from .render import configure_render, save_blend, view_settings

SHEET = (1.2, 0.42)  # width, height in metres; the sheet's centre is at the origin, facing -y
CARD_GAP = 0.005  # card distance in front of the sheet
# Sun of a light-fastness test: 50,000 lux on the sheet (xenon-arc-like daylight with UV),
# 24 hours a day; it travels in the y-z plane so the card's vertical edge casts no shadow.
SHEET_LUX = 50000.0
SUN_ELEVATION = 30.0  # degrees below the horizontal, coming from the camera side
REMOVABLE = "Removable"


def set_reveal(reveal=True):
    """Hide (True) or show (False) the card covering the right half of the chart."""
    C.set_hidden(C.collection_objects(bpy.data.collections[REMOVABLE]), reveal)


def build(path=None, resolution=1024):
    """Build the chart, card, board and light; save to ``path`` if given.

    Parameters
    ----------
    resolution : int
        Width of the chart image in texels (height follows the sheet's aspect ratio).

    Returns
    -------
    dict
        ``camera``, ``cameras``, ``chart`` (object), ``card`` (object hidden by
        :func:`set_reveal`), ``board``, ``sun``, ``lights``, ``removable``, ``series``,
        ``levels``, ``materials``.
    """
    scene = C.reset()
    scene.name = "Swatches"
    stand = C.collection("Stand")
    removable = C.collection(REMOVABLE)
    lights = C.collection("Lights")

    w, h = SHEET
    board = mesh_from_quads("Board", box_quads((-0.75, 0.001, -0.35), (0.75, 0.03, 0.35)), stand,
                            C.plain_material("Board_Grey", (0.05, 0.05, 0.05), 0.8))
    img = C.image_from_array("Chart_Print", T.colour_chart((int(resolution * h / w), resolution), copies=2))
    mat = C.aging_material("Chart_Print", img, "printed-paper", blue_wool=3, roughness=0.5, specular=0.3)
    chart = grid_mesh("Chart", 1, 1, lambda u, v: ((u - 0.5) * w, 0.0, (v - 0.5) * h), stand, mat)
    # the card: 2 mm grey board over the right half (x >= 0) with a 2 cm overlap outside the sheet
    card = mesh_from_quads("Card", box_quads((0.0, -CARD_GAP - 0.002, -h / 2 - 0.02),
                                             (w / 2 + 0.02, -CARD_GAP, h / 2 + 0.02)),
                           removable, C.plain_material("Card_Grey", (0.12, 0.115, 0.11), 0.9))
    mesh_from_quads("Backdrop", box_quads((-3, 0.03, -2), (3, 0.1, 2)), stand,
                    C.plain_material("Backdrop", (0.02, 0.02, 0.02), 0.9))

    direction = C.sun_direction(SUN_ELEVATION, 90.0)  # travels toward +y, downward
    strength = C.sun_strength_for_lux(SHEET_LUX, 90.0 - SUN_ELEVATION)  # sheet normal is -y
    sun = C.add_light("Sun", "SUN", strength, (0, -2, 1.5), lights, spectrum="daylight",
                      hours_per_day=24.0, uv_filter=False, direction=direction, angle=0.01)
    world = C.world_sky(scene, (0.8, 0.8, 0.8), 0.5)
    world["lightfade_spectrum"] = "daylight"
    world["lightfade_hours_per_day"] = 24.0
    world["lightfade_uv_filter"] = False

    cam = C.add_camera("Camera", (0.0, -1.55, 0.0), (0.0, 0.0, 0.0), lens=40.0)
    scene.camera = cam
    # A colour chart is judged by its patch colours: use the Standard (sRGB) view, whose
    # tone curve does not desaturate bright patches as AgX does. Paper under 50 klx renders
    # at ~21 (white Lambertian radiance E / pi); 2^-4.7 brings it to ~0.8.
    configure_render(scene, view_transform="Standard")
    scene.view_settings.exposure = -4.7
    scene.view_settings.look = "None"

    info = dict(scene=scene.name, camera=cam.name, cameras=[cam.name], chart=chart.name, card=card.name,
                board=board.name, sun=sun.name, lights=[sun.name],
                removable=sorted(o.name for o in C.collection_objects(removable)),
                series=list(T.CHART_SERIES), levels=[round(float(x), 2) for x in T.CHART_LEVELS],
                materials=sorted(m.name for m in C.tagged_materials()), view=view_settings(scene))
    if path:
        save_blend(path)
    return info


if __name__ == "__main__":
    cli.main(build, __doc__.splitlines()[0])
