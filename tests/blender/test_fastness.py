"""Per-colourant Blue Wool classes on a material (issue 25: the artist can still ask for a
fugitive dye): the panel shows them, they change the aging, a change makes the copy stale,
and text that cannot be applied is refused in one line naming the material."""

from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, linear_srgb_to_XYZ

from tests.blender.test_panels import draw_all


def _aged_grey(material, fastness):
    """A mid grey aged 30 years at 3 Mlx·h a year with ``material``'s recipe and ``fastness``."""
    from lightfade_addon.blender.aging.runtime import material_recipe
    from lightfade_addon.core.aging.ager import Light, age_image

    material.lightfade.fastness = fastness
    grey = np.full((1, 1, 3), 0.35, np.float32)
    light = Light("daylight-glass", False, 3e6 / (8 * 365), 8.0, 365.0)
    return age_image(grey, [30.0], material_recipe(material), (light,), encoding="linear")[0]


def test_the_panel_shows_each_colourants_class_with_the_override(floor_scene):
    mat = floor_scene["material"]
    mat.lightfade.enabled = True
    mat.lightfade.recipe = "DYED_FABRIC"
    mat.lightfade.blue_wool = 4
    mat.lightfade.fastness = "yellow=1.5"
    ctx = SimpleNamespace(scene=bpy.context.scene, object=floor_scene["floor"], material=mat)
    calls = draw_all(ctx)
    assert ("prop", "fastness") in calls
    assert "Per colourant: cyan 4 · magenta 4 · yellow 1.5" in [t for k, t in calls if k == "label"]


def test_a_fugitive_yellow_turns_a_grey_blue(floor_scene):
    mat = floor_scene["material"]
    mat.lightfade.recipe = "DYED_FABRIC"
    mat.lightfade.blue_wool = 4
    lab = [XYZ_to_Lab(linear_srgb_to_XYZ(_aged_grey(mat, f).reshape(-1, 3)))[0]
           for f in ("", "yellow=1")]
    assert lab[1][2] < lab[0][2] - 3.0                 # b* drops: the yellow went first


def test_a_change_makes_the_copy_stale_and_bad_text_is_refused_in_one_line(floor_scene):
    from lightfade_addon import api

    scene = bpy.context.scene
    mat = floor_scene["material"]
    mat.lightfade.recipe = "DYED_FABRIC"
    api.bake(scene)
    api.age_scene(scene, years=10)
    assert api.material_plan(scene)[0]["status"] == "aged"
    mat.lightfade.fastness = "magenta=2"
    assert api.material_plan(scene)[0]["status"].startswith("stale:")
    mat.lightfade.fastness = "purple=2"
    with pytest.raises(api.AgingError) as err:
        api.age_scene(scene, years=10)
    line = str(err.value)
    assert f"'{mat.name}'" in line and "purple" in line and "cyan, magenta, yellow" in line
