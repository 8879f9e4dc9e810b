"""Cycles light portals in a bake: not a light group, kept where they guide world light.

A portal (an Area light with *Portal* on) emits nothing; it shows Cycles where the
world's light enters a room. It must not become a lamp group, and a bake of a scene
holding one must not crash (Cycles did, baking a "group" of one portal and no world);
it stays visible while the world or annual daylight is baked and is hidden otherwise.
"""

import math

import bpy
import numpy as np
import pytest

from lightfade_addon.blender.bake import BakeSettings, bake_exposure
from lightfade_addon.blender.bake.emitters import (Emitter, LightGroup, find_emitters, is_portal,
                                                   isolate)
from lightfade_addon.blender.bake.state import BakeState

SUN, THETA = 2.0, 40.0
SUN_LUX = 683.0 * SUN * math.cos(math.radians(THETA))


@pytest.fixture
def room(blender, lf):
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    lf.add_sun(SUN, THETA)
    light = bpy.data.lights.new("Portal", "AREA")
    light.cycles.is_portal = True
    portal = bpy.data.objects.new("Portal", light)
    portal.location = (0.0, 0.0, 1.5)
    bpy.context.scene.collection.objects.link(portal)
    bpy.context.view_layer.update()
    return floor, portal


def test_a_portal_is_not_a_light_group_and_the_bake_runs(room, lf):
    floor, portal = room
    scene = bpy.context.scene
    assert is_portal(portal) and portal.data.energy > 0      # a lamp but for the portal flag
    assert [e.name for e in find_emitters(scene)] == ["Sun"]
    result = bake_exposure(scene, [floor], BakeSettings(resolution=32, samples=4, margin=2,
                                                        denoise=False),
                           report=lambda m: None, progress=lambda f, m: None)
    assert result["groups"] == [("Sun", ["Sun"])]
    assert np.median(lf.pixels(result["maps"]["Floor"]["Sun"])) == pytest.approx(SUN_LUX,
                                                                                 rel=0.01)
    assert not portal.hide_render and portal.data.cycles.is_portal      # left as it was


@pytest.mark.parametrize("kind, hidden", [("WORLD", False), ("DAYLIGHT", False), ("SUN", True)])
def test_the_portal_stays_only_where_world_light_is_baked(room, kind, hidden, monkeypatch):
    _floor, portal = room
    scene = bpy.context.scene
    from lightfade_addon.blender.bake import emitters

    monkeypatch.setattr(emitters._daylight, "use_annual_world", lambda state, scene: None)
    name = {"SUN": "Sun", "WORLD": "World", "DAYLIGHT": "Daylight"}[kind]
    obj = scene.objects.get(name)
    group = LightGroup(name, (), [Emitter(name, kind, obj)])
    with BakeState(scene, bpy.context.view_layer) as state:
        isolate(state, scene, group)
        assert portal.hide_render is hidden
    assert portal.hide_render is False                       # restored after the bake
