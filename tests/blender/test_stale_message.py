"""A stale aged material says what refreshes it, and that is what does (issue 27.5): the
Years slider prepares nothing (it stays stale), Age brings it up to date."""

import bpy


def test_a_stale_material_says_press_age_and_age_is_what_refreshes_it(floor_scene):
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import REFRESH

    scene = bpy.context.scene
    floor_scene["sun"].data.energy = 30.0
    api.bake(scene)
    api.age_scene(scene, years=10)
    floor_scene["material"].lightfade.blue_wool += 1          # the recipe changes
    status = api.material_plan(scene)[0]["status"]
    assert status == f"stale: exposure maps, schedule or recipe changed since Age: {REFRESH}"
    assert status.endswith("press Age") and "years change" not in status
    scene.lightfade.years = 20.0                               # the slider
    assert api.material_plan(scene)[0]["status"] == status     # still stale: as it said
    assert bpy.ops.lightfade.age(years=-1) == {"FINISHED"}
    assert api.material_plan(scene)[0]["status"] == "aged"
