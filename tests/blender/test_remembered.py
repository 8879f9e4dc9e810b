"""bake.emitters.remembered: answers about a scene's emitters kept only while open (a
years change asks every aged copy; none may outlive the call)."""

import bpy

from lightfade_addon.blender.bake.emitters import memo, remembered, schedule_of


def test_answers_are_kept_only_while_open(floor_scene):
    scene, sun = bpy.context.scene, floor_scene["sun"]
    assert memo(scene) is None
    with remembered(scene):
        assert schedule_of(scene, "Sun", "SUN") == sun.data.lightfade
        memo(scene)["asked"] = 1
    assert memo(scene) is None
    sun.name = "Sun2"
    with remembered(scene):
        assert schedule_of(scene, "Sun", "SUN") is None
        assert schedule_of(scene, "Sun2", "SUN") == sun.data.lightfade
        assert memo(scene) == {}
