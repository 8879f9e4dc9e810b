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


# ---------------------------------------------------------------- portals LightFade makes


def _material(name, kind):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # Blender 4.x: no node tree until this
        mat.use_nodes = True
    if kind == "GLASS":
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Alpha"].default_value = 0.1
    return mat


def _plane(name, size, location, rotation, material):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(material)
    return obj


@pytest.fixture
def window_room(blender):
    """A closed 2 m box room (a floor and five walls) but for a 1 × 0.6 m glass pane in
    its +y wall, under a white sky world with a spectrum."""
    import bmesh

    wall = _material("Wall", "WALL")
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0))
    room = bpy.context.active_object
    room.name = "Room"
    room.data.materials.append(wall)
    bm = bmesh.new()
    bm.from_mesh(room.data)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f.normal.y > 0.9], context="FACES")
    bm.to_mesh(room.data)
    bm.free()
    # the +y side: a wall with the pane's opening left open around it
    upright = (math.radians(90), 0, 0)
    for name, location, scale in (("Jamb-0.75", (-0.75, 1.0, 1.0), (0.5, 2.0, 1.0)),
                                  ("Jamb0.75", (0.75, 1.0, 1.0), (0.5, 2.0, 1.0)),
                                  ("Head", (0.0, 1.0, 1.65), (1.0, 0.7, 1.0)),
                                  ("Sill", (0.0, 1.0, 0.35), (1.0, 0.7, 1.0))):
        _plane(name, 1.0, location, upright, wall).scale = scale
    pane = _plane("Pane", 1.0, (0.0, 1.0, 1.0), upright, _material("Glass", "GLASS"))
    pane.scale = (1.0, 0.6, 1.0)
    world = bpy.data.worlds.new("Sky")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.lightfade.spectrum = "DAYLIGHT"
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    bpy.context.scene.world = world
    bpy.context.view_layer.update()
    return room, pane


def _windows():
    from lightfade_addon.blender.bake.portals import find_windows

    return find_windows(bpy.context.scene, bpy.context.evaluated_depsgraph_get())


def test_a_pane_between_the_sky_and_a_room_gets_a_portal_facing_in(window_room):
    windows = _windows()
    assert [(w.obj, w.material) for w in windows] == [("Pane", "Glass")]
    w = windows[0]
    assert sorted(w.size) == pytest.approx([0.6, 1.0], abs=1e-4)        # the pane's rectangle
    assert tuple(w.matrix.translation) == pytest.approx((0.0, 1.0, 1.0), abs=1e-4)
    assert tuple(-w.matrix.col[2].xyz) == pytest.approx((0.0, -1.0, 0.0), abs=1e-6)  # -Z: in


def test_a_mullion_across_the_panes_centre_does_not_hide_the_window(window_room):
    """A bar through the middle of the pane (the centre's rays hit it on both sides): the
    other points of the pane still see the sky one way and the room the other."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 1.0, 1.0))
    bar = bpy.context.active_object
    bar.name, bar.scale = "Mullion", (0.08, 0.1, 0.6)
    bpy.context.view_layer.update()
    windows = _windows()
    assert [w.obj for w in windows] == ["Pane"]
    assert tuple(-windows[0].matrix.col[2].xyz) == pytest.approx((0.0, -1.0, 0.0), abs=1e-6)


def test_no_portal_for_glass_inside_a_room_outdoors_or_beside_a_users_portal(window_room):
    room, pane = window_room
    glass = pane.data.materials[0]
    _plane("Vase", 0.5, (0.0, 0.0, 1.0), (math.radians(90), 0, 0), glass)   # room both sides
    assert [w.obj for w in _windows()] == ["Pane"]
    bpy.data.objects.remove(room)                                         # sky both sides
    for name in ("Jamb-0.75", "Jamb0.75", "Head", "Sill", "Vase"):
        bpy.data.objects.remove(bpy.data.objects[name])
    assert _windows() == []


def test_a_users_portal_means_none_are_made(window_room):
    light = bpy.data.lights.new("Mine", "AREA")
    light.cycles.is_portal = True
    bpy.context.scene.collection.objects.link(bpy.data.objects.new("Mine", light))
    assert _windows() == []


def test_the_sky_bake_with_portals_keeps_its_mean_and_leaves_nothing(window_room, lf):
    """A portal only guides Cycles: the floor's mean lux is the same with and without
    (it would jump if the portal emitted), and no portal is left after the bake."""
    room, _pane = window_room
    _plane("Floor", 1.6, (0.0, 0.0, 0.01), (0, 0, 0), _material("Floor", "WALL"))
    floor = bpy.data.objects["Floor"]
    quiet = dict(report=lambda m: None, progress=lambda f, m: None)
    maps = {}
    for portals in (True, False):
        for seed in (1, 2):
            settings = BakeSettings(resolution=24, samples=32, margin=2, denoise=False,
                                    portals=portals, seed=seed)
            result = bake_exposure(bpy.context.scene, [floor], settings, **quiet)
            maps[portals, seed] = lf.pixels(result["maps"]["Floor"]["World"])
            assert any("window" in n for n in result["notes"]) is portals
    mean = {p: float(np.mean(maps[p, 1] + maps[p, 2])) / 2 for p in (True, False)}
    noise = {p: float(np.std(maps[p, 1] - maps[p, 2])) / mean[p] for p in (True, False)}
    assert mean[True] == pytest.approx(mean[False], rel=0.03)
    assert noise[True] < 0.7 * noise[False]                 # what the portal is for
    assert not any(o.name.startswith("LF_Portal") for o in bpy.data.objects)
    assert not any(light.name.startswith("LF_Portal") for light in bpy.data.lights)
