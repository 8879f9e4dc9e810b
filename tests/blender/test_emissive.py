"""Emissive surfaces that are not lamps (issue 26.3): window glazing, screens, glTF
``emissiveFactor``.  An emissive material is not a light group unless the user ticks
*Count Emission as Light* on its object; until then its emission is off while baking, and
the bake report and the Exposure Bake panel say so once, naming object and material.

The pane is a real glTF round trip: a Principled BSDF with an emission colour and
strength, written by Blender's glTF exporter (``emissiveFactor`` and
``KHR_materials_emissive_strength``) and read back by its importer.
"""

import math
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from lightfade_addon.blender.bake import BakeSettings, bake_exposure
from lightfade_addon.blender.bake.emitters import emission_sockets, find_emitters

SUN, THETA = 2.0, 40.0
SUN_LUX = 683.0 * SUN * math.cos(math.radians(THETA))
EXACT = BakeSettings(resolution=32, samples=4, margin=2, denoise=False)


@pytest.fixture
def glazed(blender, lf, tmp_path):
    """A glTF-imported emissive pane standing at the edge of a 2 m floor, and a sun."""
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(1.3, 0.0, 0.5),
                                     rotation=(0.0, math.radians(-90), 0.0))
    pane = bpy.context.active_object
    pane.name = "Window"
    mat = bpy.data.materials.new("Glazing")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Emission Color"].default_value = (0.8, 0.9, 1.0, 1.0)
    bsdf.inputs["Emission Strength"].default_value = 5.0
    pane.data.materials.append(mat)
    path = tmp_path / "window.glb"
    bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB")
    lf.reset_file()
    import addon_utils

    addon_utils.enable(lf.ADDON, default_set=True)
    bpy.ops.import_scene.gltf(filepath=str(path))
    pane = next(o for o in bpy.context.scene.objects if o.type == "MESH")
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    lf.add_sun(SUN, THETA)
    bpy.context.view_layer.update()
    return SimpleNamespace(pane=pane, material=pane.material_slots[0].material, floor=floor)


def _bake(scene, floor):
    lines = []
    result = bake_exposure(scene, [floor], EXACT, report=lines.append,
                           progress=lambda f, m: None)
    return result, lines


def test_imported_emission_is_named_once_and_not_a_lamp(glazed, lf):
    scene = bpy.context.scene
    assert emission_sockets(glazed.material), "the glTF import lost the emission"
    assert [e.name for e in find_emitters(scene)] == ["Sun"]
    result, lines = _bake(scene, glazed.floor)
    assert result["groups"] == [("Sun", ["Sun"])]
    named = [m for m in lines if glazed.pane.name in m]
    assert len(named) == 1 and named == [m for m in result["notes"] if glazed.pane.name in m]
    assert glazed.material.name in named[0] and "Count Emission as Light" in named[0]
    # its emission was off while baking: the floor's map is the sun's alone
    assert np.median(lf.pixels(result["maps"]["Floor"]["Sun"])) == pytest.approx(SUN_LUX, rel=0.01)
    assert emission_sockets(glazed.material), "the bake left the emission changed"


def test_counted_as_its_own_group_when_the_user_opts_in(glazed, lf):
    scene = bpy.context.scene
    glazed.pane.lightfade_emitter.enabled = True
    glazed.pane.lightfade_emitter.hours_per_day = 4.0
    result, lines = _bake(scene, glazed.floor)
    assert sorted(g for g, _ in result["groups"]) == sorted(["Sun", glazed.pane.name])
    assert not any("Count Emission as Light" in m for m in lines)
    glow = lf.pixels(result["maps"]["Floor"][glazed.pane.name])
    assert glow[:, -4:].mean() > 100.0 and glow[:, -4:].mean() > 3 * glow[:, :4].mean()


def test_the_bake_panel_names_it(glazed):
    from test_panels import draw_all

    scene = bpy.context.scene
    calls = draw_all(SimpleNamespace(scene=scene, object=glazed.pane, material=glazed.material))
    labels = [t for k, t in calls if k == "label"]
    named = [t for t in labels if glazed.pane.name in t and "Count Emission as Light" in t]
    assert len(named) == 1 and glazed.material.name in named[0]
    assert ("prop", "enabled") in calls  # the opt-in, in the Light Schedule panel
    glazed.pane.lightfade_emitter.enabled = True
    labels = [t for k, t in draw_all(SimpleNamespace(scene=scene, object=glazed.pane,
                                                     material=glazed.material)) if k == "label"]
    assert not any("Count Emission as Light" in t for t in labels)
