"""The demo's materials scene shows every material: all plates and labels inside the
frame, nothing between the camera and the plates, and a light level under which the
demo's years read from new through a visible fade to clearly faded, not bleached."""

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

bpy = pytest.importorskip("bpy")
from bpy_extras.object_utils import world_to_camera_view  # noqa: E402
from mathutils import Vector  # noqa: E402

from lightfade_addon.core.aging.ager import TextureAger  # noqa: E402
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
)  # noqa: E402
from lightfade_addon.core.fading.lights import Light  # noqa: E402
from lightfade_addon.core.fading.recipes import get_recipe  # noqa: E402
from scenes import demo  # noqa: E402
from scenes import materials as M  # noqa: E402


@pytest.fixture
def built(blender):
    info = M.build(resolution=32)
    scene = bpy.context.scene
    w, h = demo.PRESETS["full"]["size"]  # the demo renders at this size
    scene.render.resolution_x, scene.render.resolution_y = w, h
    bpy.context.view_layer.update()
    return info


def _corners(obj, inset=0.0):
    """World positions of ``obj``'s bounding-box corners, pulled ``inset`` toward its centre."""
    box = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    centre = sum(box, Vector()) / 8
    return [c + (centre - c) * inset for c in box]


def test_every_plate_and_label_is_inside_the_frame(built):
    scene = bpy.context.scene
    camera = scene.objects[built["camera"]]
    names = [n for kind in M.KINDS for n in built["plates"][kind]] + list(built["labels"].values())
    assert len(built["labels"]) == len(M.KINDS) == 8
    for name in names:
        for corner in _corners(scene.objects[name]):
            x, y, z = world_to_camera_view(scene, camera, corner)
            assert 0.02 < x < 0.98 and 0.02 < y < 0.98 and z > 0, (name, x, y)


def test_nothing_stands_between_the_camera_and_any_plate(built):
    scene = bpy.context.scene
    camera = scene.objects[built["camera"]].matrix_world.translation
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for kind in M.KINDS:
        for name in built["plates"][kind]:
            plate = scene.objects[name]
            for u in (-0.4, 0.0, 0.4):  # the front (lit) half, the middle, the back half
                for v in (-0.4, 0.0, 0.4):
                    target = plate.matrix_world @ Vector((u, v, 0.0))
                    hit, _loc, _n, _i, obj, _m = scene.ray_cast(
                        depsgraph, camera, (target - camera).normalized())
                    assert hit and obj.name == name, (name, u, v, obj and obj.name)


def _lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))


def test_the_demo_years_go_from_a_visible_fade_to_clearly_faded_not_bleached():
    """The scene's colours aged in full sun (``SUN_LUX``, 8 h a day) for the demo's years,
    with the scenes' recipe and Blue Wool class."""
    years = demo.SCENES["materials"]["years"]
    srgb = np.array([(0.75, 0.15, 0.3), (0.2, 0.45, 0.7), (0.85, 0.7, 0.2)])  # the stripes
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    colours = np.vstack([linear, [(0.7, 0.1, 0.35)]])  # and the shared material's colour
    recipe = get_recipe(M.RECIPE).with_blue_wool(M.BLUE_WOOL)
    ager = TextureAger(colours, recipe, [Light("daylight-glass", False, M.SUN_LUX, 8.0)],
                       max_years=max(years))
    new = _lab(colours)
    fade = {y: delta_E_2000(_lab(ager.age(y)), new) for y in years[1:]}
    second, last = fade[years[1]], fade[years[-1]]
    assert second.max() > 3                  # a visible change after the first step
    assert np.median(second) < 12            # most colours far from bleached by then
    assert np.all(last > second)             # still going
    assert (last > 10).sum() >= 2            # some clearly faded by the last frame
    L, a, b = _lab(ager.age(years[-1])).T
    assert np.median(np.hypot(a, b)) > 8     # but not all bleached to grey-white
