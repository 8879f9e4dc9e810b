"""The ray gate of an aged copy (Scene > LightFade > Aged Colour On): the aged BSDF on
the rays it names, a duplicate with the original colour on the others, undone by Reset."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from tests.blender.test_material_aging import (  # noqa: E402
    _bake_and_age,
    _camera_and_render_settings,
    _render,
    textured,  # noqa: F401  (fixture)
)


def _age(rays, years=25):
    bpy.context.scene.lightfade.aged_rays = rays
    _bake_and_age(years=years)
    from lightfade_addon.blender.aging.copies import copies_of

    return copies_of(bpy.data.materials["Carpet"])[0]


def _feed(socket):
    """The node feeding ``socket``; through the frame switch, its live side
    (blender/aging/frames.py)."""
    from lightfade_addon.blender.source import FRAME_MIX

    node = socket.links[0].from_node if socket.links else None
    if node is not None and node.name == FRAME_MIX:
        return _feed(node.inputs[1])
    return node


@pytest.mark.parametrize("rays, output", [("VISIBLE", "Is Diffuse Ray"),
                                          ("CAMERA", "Is Camera Ray")])
def test_the_gate_picks_the_aged_bsdf_on_its_rays(textured, rays, output):
    from lightfade_addon.blender.aging.copies import GATE_BSDF, GATE_MIX, GROUP_NODE

    tree = _age(rays).node_tree
    mix = tree.nodes[GATE_MIX]
    aged, original = _feed(mix.inputs[2]), _feed(mix.inputs[1])
    assert aged.name == "Principled BSDF" and original.name == GATE_BSDF
    assert _feed(aged.inputs["Base Color"]).name == GROUP_NODE
    assert _feed(original.inputs["Base Color"]).type == "TEX_IMAGE"     # the artist's colour
    assert original.inputs["Roughness"].default_value == aged.inputs["Roughness"].default_value
    assert original.distribution == aged.distribution
    both = mix.inputs["Fac"].links[0].from_node             # ray choice × (years > 0)
    assert both.operation == "MULTIPLY"
    ray, aged_years = (s.links[0].from_socket for s in both.inputs[:2])
    if rays == "VISIBLE":                                # 1 - Is Diffuse Ray
        fac = ray.node
        assert fac.operation == "SUBTRACT" and fac.inputs[0].default_value == 1.0
        ray = fac.inputs[1].links[0].from_socket
    assert ray.node.type == "LIGHT_PATH" and ray.name == output
    _assert_years_above_zero(aged_years)
    out = tree.get_output_node("ALL") or tree.get_output_node("CYCLES")
    assert _feed(out.inputs["Surface"]) == mix


def _assert_years_above_zero(socket):
    node = socket.node
    assert node.operation == "GREATER_THAN" and node.inputs[1].default_value == 0.0
    years = node.inputs[0].links[0].from_node
    assert years.type == "ATTRIBUTE" and years.attribute_type == "VIEW_LAYER"
    assert years.attribute_name == "lightfade_years"


def test_all_rays_gates_zero_years_only(textured):
    from lightfade_addon.blender.aging.copies import GATE_MIX

    mix = _age("ALL").node_tree.nodes[GATE_MIX]
    _assert_years_above_zero(mix.inputs["Fac"].links[0].from_socket)


def test_a_texture_with_a_history_keeps_the_aged_bsdf_at_zero_years(textured):
    """Its 0 years is the restoration: all rays and no years gate, so no gate at all."""
    from lightfade_addon.blender.aging.copies import GATE_MIX

    textured["material"].lightfade.already_years = 10.0
    assert GATE_MIX not in _age("ALL").node_tree.nodes


def test_zero_years_skips_the_group_in_cycles(textured, tmp_path):
    """At 0 years the gate shows the original BSDF: a render with the aging group's
    output broken (NaN colour) is still the original, pixel for pixel."""
    from lightfade_addon.blender.aging.copies import GROUP_NODE

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    before = _render(scene, tmp_path, "before.exr")
    copy = _age("ALL", years=0)
    group = copy.node_tree.nodes[GROUP_NODE].node_tree
    out = next(n for n in group.nodes if n.type == "GROUP_OUTPUT")
    poison = group.nodes.new("ShaderNodeCombineXYZ")
    poison.inputs[0].default_value = float("nan")
    group.links.new(poison.outputs[0], out.inputs[0])
    assert np.abs(_render(scene, tmp_path, "after.exr") - before).max() <= 1e-6
    from lightfade_addon import api

    api.set_years(scene, 1.0)                          # the broken group shows now
    assert not np.allclose(_render(scene, tmp_path, "one.exr"), before, atol=1e-3)


@pytest.mark.parametrize("rays", ["VISIBLE", "CAMERA"])
def test_the_camera_sees_the_aged_colour_through_the_gate(textured, tmp_path, rays):
    """Without bounces every shading point is a camera ray's: the gated render is the
    ungated one pixel for pixel, and both differ from the original."""
    from lightfade_addon import api

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    scene.cycles.max_bounces = 0
    before = _render(scene, tmp_path, "before.exr")
    _age("ALL")
    everywhere = _render(scene, tmp_path, "all.exr")
    api.reset(scene)
    _age(rays)
    gated = _render(scene, tmp_path, "gated.exr")
    assert np.abs(gated - everywhere).max() <= 1e-6
    assert np.abs(gated - before).max() > 0.02


def test_zero_years_with_the_gate_renders_the_original_pixels(textured, tmp_path):
    """Bounces on (the box sees the floor through diffuse rays): 0 years is the original."""
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    before = _render(scene, tmp_path, "before.exr")
    copy = _age("VISIBLE", years=0)
    assert "LightFade Ray Gate" in copy.node_tree.nodes
    assert np.abs(_render(scene, tmp_path, "after.exr") - before).max() <= 1e-6


def test_reset_leaves_no_gate_and_a_changed_setting_is_stale(textured):
    from lightfade_addon import api
    from lightfade_addon.blender.aging.runtime import signature

    material = bpy.data.materials["Carpet"]
    names = sorted(n.name for n in material.node_tree.nodes)
    copy = _age("VISIBLE")
    scene = bpy.context.scene
    old = signature(scene, copy)
    scene.lightfade.aged_rays = "CAMERA"
    assert signature(scene, copy) != old
    api.reset(scene)
    assert sorted(n.name for n in material.node_tree.nodes) == names
    assert not any(n.name.startswith("LightFade") for m in bpy.data.materials
                   for n in m.node_tree.nodes)


def test_a_bsdf_inside_a_node_group_is_gated_in_the_copy_s_group(textured, tmp_path, lf):
    """The colour BSDF inside a node group: the gate goes into the copy's private group
    (the user's stays as it was), and the camera still sees the aged colour."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.copies import GATE_MIX

    tree = textured["material"].node_tree
    texture = next(n for n in tree.nodes if n.type == "TEX_IMAGE")
    node = lf.wrap_bsdf_in_group(textured["material"], texture.outputs["Color"])
    group = node.node_tree
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    scene.cycles.max_bounces = 0
    _age("ALL")
    everywhere = _render(scene, tmp_path, "all.exr")
    api.reset(scene)
    copy = _age("VISIBLE")
    private = copy.node_tree.nodes[node.name].node_tree
    assert private != group and GATE_MIX in private.nodes
    assert sorted(n.type for n in group.nodes) == ["BSDF_PRINCIPLED", "GROUP_INPUT",
                                                   "GROUP_OUTPUT"]
    assert np.abs(_render(scene, tmp_path, "gated.exr") - everywhere).max() <= 1e-6
