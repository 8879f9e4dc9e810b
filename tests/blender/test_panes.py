"""Refracting window glass is a clear pane to every ray while the sky is baked.

Cycles' shadow rays stop at refracting glass, so without this the sky reaches a room
through a Glass BSDF window only by bounces that refract out, and neither the sky map's
importance sampling nor the portal over the window helps (noise per texel 0.75 of the
mean against 0.11). The room is ``test_portals.py``'s: a closed 2 m box with a 1 × 0.6 m
pane in one wall under a white sky.
"""

import bpy
import numpy as np
import pytest

from lightfade_addon.blender.bake import BakeSettings, bake_exposure
from lightfade_addon.blender.bake.panes import PANE_PREFIX, pane_colour, refracts, transmittance
from lightfade_addon.blender.bake.portals import clear_slots

from tests.blender.test_bake_surface import exact_tree
from tests.blender.test_portals import _material, _plane, window_room  # noqa: F401 (a fixture)

QUIET = dict(report=lambda m: None, progress=lambda f, m: None)


def _glass(material, kind):
    """Make the pane's material refract: a Glass BSDF or a Principled transmission."""
    tree = material.node_tree
    principled = tree.nodes["Principled BSDF"]
    principled.inputs["Alpha"].default_value = 1.0
    if kind == "glass":
        glass = tree.nodes.new("ShaderNodeBsdfGlass")
        glass.inputs["Roughness"].default_value = 0.0
        glass.inputs["IOR"].default_value = 1.5
        glass.inputs["Color"].default_value = (1, 1, 1, 1)
        tree.links.new(glass.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    else:
        weight = principled.inputs.get("Transmission Weight") or principled.inputs["Transmission"]
        weight.default_value = 1.0
        principled.inputs["Roughness"].default_value = 0.0
        principled.inputs["Base Color"].default_value = (1, 1, 1, 1)
        principled.inputs["IOR"].default_value = 1.5


def test_which_materials_refract(blender):
    glass = _material("G", "WALL")
    _glass(glass, "glass")
    assert pane_colour(refracts(glass)) == pytest.approx((0.9216,) * 3, abs=1e-4)
    principled = _material("P", "WALL")
    _glass(principled, "principled")
    bsdf = principled.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["IOR"].default_value = 1.33
    bsdf.inputs["Base Color"].default_value = (1.0, 0.5, 0.0, 1.0)     # tinted glass
    t = transmittance(1.33)
    assert refracts(principled) == bsdf
    assert pane_colour(bsdf) == pytest.approx((t, t / 2, 0.0), abs=1e-4)
    assert refracts(_material("Alpha", "GLASS")) is None            # shadow rays pass alpha
    assert refracts(_material("Wall", "WALL")) is None
    # the archviz trick: a Transparent BSDF for shadow rays, already clear
    trick = _material("Trick", "WALL")
    _glass(trick, "glass")
    tree = trick.node_tree
    mix, path = tree.nodes.new("ShaderNodeMixShader"), tree.nodes.new("ShaderNodeLightPath")
    clear = tree.nodes.new("ShaderNodeBsdfTransparent")
    tree.links.new(path.outputs["Is Shadow Ray"], mix.inputs[0])
    tree.links.new(tree.nodes["Glass BSDF"].outputs[0], mix.inputs[1])
    tree.links.new(clear.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    assert refracts(trick) is None
    # a Glass BSDF left in the tree but not wired to the output does not count
    loose = _material("Loose", "WALL")
    loose.node_tree.nodes.new("ShaderNodeBsdfGlass")
    assert refracts(loose) is None
    assert transmittance(1.5) == pytest.approx(0.9216)
    # an asset's glass wrapped in a node group
    group = bpy.data.node_groups.new("Glass Shader", "ShaderNodeTree")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    inner = group.nodes.new("ShaderNodeBsdfGlass")
    inner.inputs["IOR"].default_value = 1.45
    group.links.new(inner.outputs[0], group.nodes.new("NodeGroupOutput").inputs[0])
    wrapped = _material("Wrapped", "WALL")
    node = wrapped.node_tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    wrapped.node_tree.links.new(node.outputs[0],
                                wrapped.node_tree.nodes["Material Output"].inputs["Surface"])
    assert refracts(wrapped) == inner
    assert clear_slots(_plane("Wrapped Pane", 1.0, (0, 0, 0), (0, 0, 0), wrapped)) == [0]
    assert pane_colour(inner) == pytest.approx((transmittance(1.45),) * 3, abs=1e-6)


def _floor_maps(lf, floor, targets=None, seeds=(1, 2), portals=True):
    maps, notes = [], []
    for seed in seeds:
        settings = BakeSettings(resolution=24, samples=32, margin=2, denoise=False,
                                portals=portals, seed=seed)
        result = bake_exposure(bpy.context.scene, targets or [floor], settings, **QUIET)
        maps.append(lf.pixels(result["maps"]["Floor"]["World"]))
        notes += result["notes"]
    return maps, notes


def _mean_noise(maps):
    a, b = maps
    mean = float(np.mean(a + b)) / 2
    return mean, float(np.std(a - b)) / mean


@pytest.mark.parametrize("kind", ["glass", "principled"])
def test_a_glass_pane_bakes_as_a_clear_one_of_its_transmittance(window_room, lf, kind):
    """The glass pane's floor: the mean of an alpha pane passing the same 92 %, and its
    low noise (the portal works through it); the material as it was afterwards."""
    _room, pane = window_room
    _plane("Floor", 1.6, (0.0, 0.0, 0.01), (0, 0, 0), _material("Floor", "WALL"))
    floor = bpy.data.objects["Floor"]
    material = pane.data.materials[0]
    material.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 1 - 0.9216
    reference = _mean_noise(_floor_maps(lf, floor)[0])
    _glass(material, kind)
    before = exact_tree(material.node_tree)
    maps, notes = _floor_maps(lf, floor)
    mean, noise = _mean_noise(maps)
    assert mean == pytest.approx(reference[0], rel=0.04)
    assert noise < 1.5 * reference[1] and noise < 0.3
    assert any("refracts" in n and '"Glass"' in n for n in notes)
    assert exact_tree(material.node_tree) == before
    assert not any(n.name.startswith(PANE_PREFIX) for n in material.node_tree.nodes)


def test_a_baked_pane_is_clear_to_the_others_and_comes_back(window_room, lf):
    """The pane itself a target (its material then carries the bake's probe): the floor
    still sees the sky through it, and both come back as they were."""
    _room, pane = window_room
    _plane("Floor", 1.6, (0.0, 0.0, 0.01), (0, 0, 0), _material("Floor", "WALL"))
    floor = bpy.data.objects["Floor"]
    material = pane.data.materials[0]
    _glass(material, "glass")
    alone = _mean_noise(_floor_maps(lf, floor)[0])
    before = exact_tree(material.node_tree)
    both = _mean_noise(_floor_maps(lf, floor, [floor, pane])[0])
    assert both[0] == pytest.approx(alone[0], rel=0.04)
    assert both[1] < 0.3
    assert exact_tree(material.node_tree) == before


def test_without_portals_the_glass_is_left_alone(window_room, lf, monkeypatch):
    from lightfade_addon.blender.bake import panes

    _room, pane = window_room
    _plane("Floor", 1.6, (0.0, 0.0, 0.01), (0, 0, 0), _material("Floor", "WALL"))
    _glass(pane.data.materials[0], "glass")
    calls = []
    real = panes._clear
    monkeypatch.setattr(panes, "_clear", lambda *a: calls.append(a[1].name) or real(*a))
    _floor_maps(lf, bpy.data.objects["Floor"], seeds=(1,), portals=False)
    assert calls == []
    _floor_maps(lf, bpy.data.objects["Floor"], seeds=(1,), portals=True)
    assert calls == ["Glass"]


def _bulb_room(kind="sphere"):
    """A 4 m floor under a 60 W point lamp 1.5 m up inside a 6 cm Glass BSDF sphere, or
    inside a glass cylinder open at the bottom (``kind="open"``)."""
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    light = bpy.data.lights.new("Bulb", "POINT")
    light.energy, light.shadow_soft_size = 60.0, 0.02
    lamp = bpy.data.objects.new("Bulb", light)
    lamp.location = (0.0, 0.0, 1.5)
    bpy.context.scene.collection.objects.link(lamp)
    if kind == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.06, location=(0.0, 0.0, 1.5))
    else:
        bpy.ops.mesh.primitive_cylinder_add(radius=0.1, depth=0.3, location=(0.0, 0.0, 1.5),
                                            end_fill_type="NOTHING")
    shell = bpy.context.active_object
    shell.name = "Shell"
    material = _material("Bulb Glass", "WALL")
    _glass(material, "glass")
    shell.data.materials.append(material)
    bpy.context.view_layer.update()
    return floor, shell, material


def _floor_mean(lf, floor):
    notes = []
    settings = BakeSettings(resolution=32, samples=16, margin=2, denoise=False, seed=1)
    result = bake_exposure(bpy.context.scene, [floor], settings, report=notes.append,
                           progress=lambda f, m: None)
    return float(np.mean(lf.pixels(next(iter(result["maps"]["Floor"].values()))))), notes


def test_a_lamp_in_a_glass_bulb_lights_the_room_through_it(blender, lf):
    """Light leaves a closed glass bulb only by refracting (caustics): the default bake
    read 0.35 of the bare lamp. The glass is a clear pane for the lamp's bake: the floor
    gets the bare lamp's light times the glass's 0.92, and the glass comes back."""
    floor, shell, material = _bulb_room()
    before = exact_tree(material.node_tree)
    bulb, notes = _floor_mean(lf, floor)
    shell.hide_render = True
    bare, _ = _floor_mean(lf, floor)
    assert bulb == pytest.approx(transmittance(1.5) * bare, rel=0.02)
    assert any('"Bulb" in "Bulb Glass"' in n for n in notes)
    assert exact_tree(material.node_tree) == before


def test_an_open_glass_shade_is_left_alone(blender, lf, monkeypatch):
    """Light leaves an open shade straight through its opening: Cycles samples that, and
    the glass stays glass (a plain bake's count)."""
    from lightfade_addon.blender.bake import panes

    floor, _shell, _material_ = _bulb_room("open")
    calls = []
    real = panes._clear
    monkeypatch.setattr(panes, "_clear", lambda *a: calls.append(a[1].name) or real(*a))
    _mean, notes = _floor_mean(lf, floor)
    assert calls == [] and not any("closed in glass" in n for n in notes)
