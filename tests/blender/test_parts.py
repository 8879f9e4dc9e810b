"""Several recipes in one material, by mask (issue 25.2): each part ages as its own recipe
alone would, a part that does not age keeps its pixels at every years, image, attribute
and node-output masks, bad parts refused in one line, Reset keeps what the user made."""

import bmesh
import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from lightfade_addon.core.colour.colorimetry import (  # noqa: E402
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
)
from tests.blender.test_material_aging import _camera_and_render_settings  # noqa: E402
from tests.blender.test_panels import RecordingLayout  # noqa: E402

N = 16
#: Key texels well inside the left half (u < 0.5) and the right; Cycles' bake samples
#: the outer ring of texels off their centres.
LEFT = np.s_[1:-1, 1: N // 2 - 1]
RIGHT = np.s_[1:-1, N // 2 + 1: -1]


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))


def node_evaluation(copy):
    """(H, W, 3) the copy's Base Color as Cycles evaluates it at the key texels' centres
    (an Emission bake in the exposure UV map; as in test_material_aging)."""
    from lightfade_addon.blender.albedo import bake_albedos
    from lightfade_addon.blender.aging.apply import original_pixels
    from lightfade_addon.blender.aging.parts import colour_socket

    H, W = original_pixels(bpy.context.scene, copy).shape[:2]
    image = bpy.data.images.new("NodeEvaluation", W, H, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    out = bake_albedos(bpy.context.scene, bpy.context.view_layer, copy.lightfade.aged_object,
                       [(copy, colour_socket(copy), image)], copy.lightfade.uv_map, margin=0)
    bpy.data.images.remove(image)
    return out[copy.name]


def _albedo(material):
    """A 16² albedo of greys, browns and a red (a float image), Closest as the tests of
    the node group use, so the bake at texel centres reads the texels themselves."""
    image = bpy.data.images.new("Sofa", N, N, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    y, x = np.mgrid[0:N, 0:N] / N
    px = np.ones((N, N, 4), np.float32)
    px[..., 0] = 0.25 + 0.5 * x
    px[..., 1] = 0.2 + 0.3 * y
    px[..., 2] = 0.1 + 0.2 * x * y
    image.pixels.foreach_set(px.ravel())
    image.pack()
    node = next(n for n in material.node_tree.nodes if n.type == "TEX_IMAGE")
    node.image = image
    node.interpolation = "Closest"
    return px


def _half_mask(name="FrameMask"):
    """White on the left half of the texture (u < 0.5), black on the right."""
    image = bpy.data.images.new(name, N, N)
    px = np.zeros((N, N, 4), np.float32)
    px[:, : N // 2, :3] = 1.0
    px[..., 3] = 1.0
    image.pixels.foreach_set(px.ravel())
    image.pack()
    return image


@pytest.fixture
def sofa(floor_scene):
    """The floor scene, its material a 'Dyed Fabric' sofa texture, lit by a strong sun;
    the box moved off the floor's left half."""
    material = floor_scene["material"]
    px = _albedo(material)
    material.lightfade.recipe = "DYED_FABRIC"
    floor_scene["sun"].data.energy = 30.0
    floor_scene["albedo_px"] = px
    return floor_scene


def _copy(material):
    from lightfade_addon.blender.aging.copies import copies_of

    (copy,) = copies_of(material)
    return copy


def _age(years=20.0):
    from lightfade_addon import api

    scene = bpy.context.scene
    if not bpy.context.scene.objects["Floor"].lightfade.exposure_maps:
        api.bake(scene)
    return api.age_scene(scene, years=years)


def _twin(material, years):
    from lightfade_addon.blender.aging.apply import aged_pixels

    return aged_pixels(bpy.context.scene, _copy(material), years)[..., :3]


def _alone(material, recipe, years):
    """The twin's aged pixels of the material aged with ``recipe`` and no parts."""
    from lightfade_addon import api

    saved = [(p.name, p.recipe, p.image) for p in material.lightfade.parts]
    api.reset(bpy.context.scene)
    material.lightfade.parts.clear()
    material.lightfade.recipe = recipe
    _age(years)
    out = _twin(material, years).copy()
    api.reset(bpy.context.scene)
    for name, part_recipe, image in saved:
        part = material.lightfade.parts.add()
        part.name, part.recipe, part.image = name, part_recipe, image
    material.lightfade.recipe = "DYED_FABRIC"
    return out


def test_two_recipes_by_a_mask_image_age_each_region_as_its_recipe_alone(sofa):
    from lightfade_addon import api

    material = sofa["material"]
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=_half_mask())])
    wood = _alone(material, "BARE_WOOD", 20.0)
    fabric = _alone(material, "DYED_FABRIC", 20.0)
    assert delta_E_2000(lab(wood[LEFT]), lab(fabric[LEFT])).mean() > 1.0   # they differ
    _age(20.0)
    twin = _twin(material, 20.0)
    np.testing.assert_allclose(twin[LEFT], wood[LEFT], atol=2e-6)
    np.testing.assert_allclose(twin[RIGHT], fabric[RIGHT], atol=2e-6)
    nodes = node_evaluation(_copy(material))                  # the material, by Cycles
    dE = delta_E_2000(lab(nodes[1:-1, 1:-1]), lab(twin[1:-1, 1:-1]))
    assert np.percentile(dE, 99) <= 0.2 and dE.max() <= 0.5


def _render(scene, folder, name):
    scene.render.filepath = str(folder / name)
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    w, h = image.size
    a = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(a)
    bpy.data.images.remove(image)
    return a.reshape(h, w, 4)[..., :3]


def test_a_part_that_does_not_age_keeps_its_pixels_at_0_and_30_years(sofa, tmp_path):
    from lightfade_addon import api

    material = sofa["material"]
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    scene.cycles.max_bounces = 0      # light the aged half bounces off the box stays out
    before = _render(scene, tmp_path, "before.exr")
    api.set_parts(material, [dict(name="Glass", recipe="KEEP", image=_half_mask())])
    _age(0.0)
    frames = {}
    for years in (0.0, 30.0):
        api.set_years(scene, years)
        frames[years] = _render(scene, tmp_path, f"{years}.exr")
    # render columns over the floor's left half, past its edge (where a Repeat mask meets
    # its own right border)
    left = np.s_[:, 4:20]
    assert np.array_equal(frames[0.0], before)                  # all of it, at 0 years
    assert np.array_equal(frames[30.0][left], before[left])     # the glass, at 30 years
    lit = before[:, 30:].sum(-1) > 0.05
    assert np.median(delta_E_2000(lab(frames[30.0][:, 30:][lit]), lab(before[:, 30:][lit]))) > 2
    twin = _twin(material, 30.0)
    assert np.array_equal(twin[LEFT], sofa["albedo_px"][LEFT][..., :3])
    assert np.array_equal(node_evaluation(_copy(material))[LEFT], sofa["albedo_px"][LEFT][..., :3])


def _split_floor(floor):
    """Cut the floor into 2 x 2 faces (UVs follow), for masks on faces."""
    bm = bmesh.new()
    bm.from_mesh(floor.data)
    bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=1, use_grid_fill=True)
    bm.to_mesh(floor.data)
    bm.free()


def _keep_left(material, years=30.0):
    """After Age with a 'Does Not Age' part on the left: left texels exact, right aged."""
    _age(years)
    twin = _twin(material, years)
    albedo = np.asarray(material.node_tree.nodes["Image Texture"].image.pixels[:],
                        np.float32).reshape(N, N, 4)[..., :3]
    np.testing.assert_array_equal(twin[LEFT], albedo[LEFT])
    assert delta_E_2000(lab(twin[RIGHT]), lab(albedo[RIGHT])).mean() > 2
    nodes = node_evaluation(_copy(material))
    np.testing.assert_allclose(nodes[1:-1, 1:-1], twin[1:-1, 1:-1], atol=0.02)
    np.testing.assert_array_equal(nodes[LEFT], albedo[LEFT])


def test_an_attribute_mask(sofa):
    from lightfade_addon import api

    floor = sofa["floor"]
    _split_floor(floor)
    attribute = floor.data.attributes.new("glass", "FLOAT", "FACE")
    centres = np.array([p.center.x for p in floor.data.polygons])
    attribute.data.foreach_set("value", (centres < 0).astype(np.float32))
    api.set_parts(sofa["material"], [dict(name="Glass", recipe="KEEP", attribute="glass")])
    _keep_left(sofa["material"])


def test_a_node_output_mask(sofa):
    """The artist's own node 'Glass Mask' (1 where u < 0.5) picked by name."""
    from lightfade_addon import api

    tree = sofa["material"].node_tree
    coords = tree.nodes.new("ShaderNodeTexCoord")
    xyz = tree.nodes.new("ShaderNodeSeparateXYZ")
    less = tree.nodes.new("ShaderNodeMath")
    less.name = "Glass Mask"
    less.operation = "LESS_THAN"
    less.inputs[1].default_value = 0.5
    tree.links.new(coords.outputs["UV"], xyz.inputs[0])
    tree.links.new(xyz.outputs["X"], less.inputs[0])
    api.set_parts(sofa["material"], [dict(name="Glass", recipe="KEEP", node="Glass Mask",
                                          socket="Value")])
    _keep_left(sofa["material"])


@pytest.mark.parametrize("part, says", [
    (dict(name="Frame", recipe="BARE_WOOD", image=None),
     "Material 'Carpet', part 'Frame': no mask image: pick one"),
    (dict(name="Frame", recipe="BARE_WOOD", attribute="wood"),
     "Material 'Carpet', part 'Frame': attribute 'wood' is not on mesh 'Plane'"),
    (dict(name="Frame", recipe="BARE_WOOD", node="Wood Mask"),
     "Material 'Carpet', part 'Frame': no node named 'Wood Mask'"),
    (dict(name="Frame", recipe="BARE_WOOD", node="Principled BSDF", socket="Fac"),
     "Material 'Carpet', part 'Frame': node 'Principled BSDF' has no output 'Fac'"),
    (dict(name="Frame", recipe="BARE_WOOD", node="Principled BSDF", socket="BSDF"),
     "Material 'Carpet', part 'Frame': output 'BSDF' of node 'Principled BSDF' is a shader: "
     "pick a colour or value output"),
])
def test_bad_parts_are_refused_in_one_line_and_nothing_changes(sofa, part, says):
    from lightfade_addon import api

    material = sofa["material"]
    api.bake(bpy.context.scene)
    api.set_parts(material, [part])
    nodes = len(material.node_tree.nodes)
    with pytest.raises(api.AgingError) as err:
        api.age_scene(bpy.context.scene, years=5)
    assert str(err.value).startswith(says) and "\n" not in str(err.value)
    assert len(material.node_tree.nodes) == nodes
    assert not [m for m in bpy.data.materials if m.name.startswith("LF_")]
    assert any(says in p for row in api.material_plan(bpy.context.scene) for p in row["problems"])


def test_set_parts_refuses_bad_values_before_changing_anything(sofa):
    from lightfade_addon import api

    material = sofa["material"]
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", attribute="wood")])
    for bad, says in (([dict(name="X", recipe="STONE", attribute="a")], "recipe 'STONE'"),
                      ([dict(name="X", recipe="KEEP")], "one mask"),
                      ([dict(name="X", recipe="KEEP", attribute="a", colour=1)], "'colour'")):
        with pytest.raises(ValueError, match=says):
            api.set_parts(material, bad)
        assert [p.attribute for p in material.lightfade.parts] == ["wood"]
    with pytest.raises(ValueError, match="rest"):
        api.set_parts(material, [], rest="NEVER")


def test_reset_keeps_what_the_user_made_and_a_changed_part_needs_age(sofa):
    from lightfade_addon import api

    material = sofa["material"]
    mask = _half_mask()
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=mask,
                                  blue_wool=5)], rest="KEEP")
    nodes = sorted(n.name for n in material.node_tree.nodes)
    _age(10.0)
    copy = _copy(material)
    assert [lane.recipe for lane in copy.lightfade.lanes] == ["BARE_WOOD"]
    material.lightfade.parts[0].blue_wool = 6
    assert api.material_plan(bpy.context.scene)[0]["status"] == \
        "stale: the material's parts changed since Age: press Age"
    api.reset(bpy.context.scene)
    assert sorted(n.name for n in material.node_tree.nodes) == nodes
    part = material.lightfade.parts[0]
    assert (part.name, part.recipe, part.image, part.blue_wool) == ("Frame", "BARE_WOOD",
                                                                   mask, 6)
    assert material.lightfade.rest == "KEEP"
    left = [d.name for d in (*bpy.data.images, *bpy.data.node_groups, *bpy.data.materials)
            if d.name.startswith("LF_") and not d.name.startswith("LF_Exposure")]
    assert left == []
    assert "lightfade_grids" not in bpy.context.scene


def test_the_parts_panel_shows_each_choice_and_what_stops_age(sofa):
    from types import SimpleNamespace

    from lightfade_addon.blender.parts.panel import MATERIAL_PT_lightfade_parts

    material = sofa["material"]
    context = SimpleNamespace(scene=bpy.context.scene, object=sofa["floor"], material=material)

    def draw():
        calls = []
        MATERIAL_PT_lightfade_parts.draw(SimpleNamespace(layout=RecordingLayout(calls)), context)
        return calls

    assert ("label", "No parts: the whole material ages with the recipe above") in draw()
    with bpy.context.temp_override(material=material):
        assert bpy.ops.lightfade.part_add() == {"FINISHED"}
    part = material.lightfade.parts[0]
    seen = {}
    for mask in ("IMAGE", "ATTRIBUTE", "SOCKET"):
        for recipe in ("KEEP", "BARE_WOOD"):
            part.mask, part.recipe = mask, recipe
            seen[mask, recipe] = draw()
    assert ("prop", "image") in seen["IMAGE", "KEEP"] and ("prop", "uv_map") in seen["IMAGE", "KEEP"]
    assert ("prop", "attribute") in seen["ATTRIBUTE", "KEEP"]
    assert ("prop", "node") in seen["SOCKET", "KEEP"]
    assert ("prop", "blue_wool") in seen["SOCKET", "BARE_WOOD"]
    assert ("label", "Its pixels stay exactly as they are, at every years") in seen["IMAGE", "KEEP"]
    assert ("label", "Material 'Carpet', part 'Part 1': no node named '' in the node tree of "
            "its colour BSDF: give the mask node that name (Node Editor > N > Node > Name)") \
        in seen["SOCKET", "BARE_WOOD"]
    with bpy.context.temp_override(material=material):
        assert bpy.ops.lightfade.part_remove() == {"FINISHED"}
    assert len(material.lightfade.parts) == 0


def test_info_apply_and_a_rebake_with_parts(sofa):
    """info lists the parts; Apply to Images writes the twin's pixels; a re-bake (the sun
    moved) reaches every recipe's group without Age, as for any copy."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import aged_pixels
    from lightfade_addon.pipeline.info import as_text, gather

    material = sofa["material"]
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=_half_mask()),
                             dict(name="Glass", recipe="KEEP", attribute="glass")])
    floor = sofa["floor"]
    floor.data.attributes.new("glass", "FLOAT", "POINT")         # zero everywhere
    scene = bpy.context.scene
    _age(20.0)
    report = gather(scene)
    (entry,) = report["would_age"]
    assert [p["name"] for p in entry["parts"]] == ["Frame", "Glass", "(rest)"]
    from lightfade_addon.blender.vocabulary import RECIPE_BLUE_WOOL   # the recipe's own class

    assert entry["parts"][0]["recipe"] == f"bare-wood, Blue Wool {RECIPE_BLUE_WOOL['BARE_WOOD']}"
    text = as_text({**report, "file": "sofa.blend"})
    assert "part Glass: does not age - attribute 'glass', channel R" in text
    weights = [i.name for i in bpy.data.images if i.name.startswith("LF_Weights_")]
    assert weights == []                      # Age bakes nothing: Apply bakes the weights
    images = api.apply_aging(scene)
    assert [i.name for i in bpy.data.images if i.name.startswith("LF_Weights_")] == \
        ["LF_Weights_LF_Aged_Carpet.Floor~0"]
    copy = _copy(material)
    applied = np.empty(N * N * 4, np.float32)
    images[copy.name].pixels.foreach_get(applied)
    np.testing.assert_allclose(applied.reshape(N, N, 4), aged_pixels(scene, copy, 20.0),
                               atol=1e-6)
    api.live_aging(scene)
    before = aged_pixels(scene, copy, 20.0).copy()
    sofa["sun"].rotation_euler[0] = 1.2                           # lower sun: less light
    api.bake(scene)                       # the groups read the new maps: no Age needed
    assert api.material_plan(scene)[0]["status"] == "aged"
    after = aged_pixels(scene, copy, 20.0)
    assert not np.allclose(after[RIGHT], before[RIGHT], atol=1e-3)
    groups = sorted(g.name for g in bpy.data.node_groups if not g.name.startswith("LF_Eval_"))
    assert groups == ["LF_Aging_LF_Aged_Carpet.Floor~0", "LF_Aging_LF_Aged_Carpet.Floor~1",
                      "LF_Parts_LF_Aged_Carpet.Floor"]
    # one evaluation group per table (recipe), shared by the lanes that read it
    assert len([g for g in bpy.data.node_groups if g.name.startswith("LF_Eval_")]) == 2
    tables = [lane.table_image for lane in copy.lightfade.lanes]    # one per recipe, shared
    assert len(set(tables)) == 2 and all(t.name.startswith("LF_Table_") for t in tables)


def test_a_bsdf_inside_a_node_group_on_the_baked_path(sofa, lf):
    """The colour BSDF inside a node group (the baked path): the mix goes into the copy's
    private group; a 'Does Not Age' attribute part keeps its texels at 30 years."""
    from lightfade_addon import api

    material = sofa["material"]
    tree = material.node_tree
    image = tree.nodes["Image Texture"]
    group = lf.wrap_bsdf_in_group(material, image.outputs["Color"]).node_tree
    floor = sofa["floor"]
    _split_floor(floor)
    attribute = floor.data.attributes.new("glass", "FLOAT", "FACE")
    centres = np.array([p.center.x for p in floor.data.polygons])
    attribute.data.foreach_set("value", (centres < 0).astype(np.float32))
    api.set_parts(material, [dict(name="Glass", recipe="KEEP", attribute="glass")])
    _age(30.0)
    assert api.material_plan(bpy.context.scene)[0]["path"] == "BAKED"
    new, old = _twin(material, 0.0), _twin(material, 30.0)
    w = new.shape[1]
    left, right = np.s_[2:-2, 2: w // 2 - 2], np.s_[2:-2, w // 2 + 2: -2]
    np.testing.assert_array_equal(old[left], new[left])
    assert delta_E_2000(lab(old[right]), lab(new[right])).mean() > 2
    assert group.nodes.get("LightFade Aging") is None        # the user's group untouched


RENDER_THERE = """
import os, sys, numpy as np, bpy
bpy.context.preferences.filepaths.use_scripts_auto_execute = False
bpy.ops.wm.open_mainfile(filepath={path!r}, load_ui=False)
assert not hasattr(bpy.types.Scene, "lightfade"), "LightFade must not be installed here"
scene = bpy.context.scene
scene.render.filepath = {out!r}
bpy.ops.render.render(write_still=True)
sys.stdout.flush()
os._exit(0)
"""


def test_a_saved_file_renders_its_parts_without_lightfade(sofa, tmp_path):
    import os
    import subprocess
    import sys

    from lightfade_addon import api

    material = sofa["material"]
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=_half_mask())])
    _age(30.0)
    here = _render(scene, tmp_path, "here.exr")
    path = tmp_path / "parts.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = RENDER_THERE.format(path=str(path), out=str(tmp_path / "there.exr"))
    proc = subprocess.run([sys.executable, "-c", code], cwd=str(tmp_path), env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    image = bpy.data.images.load(str(tmp_path / "there.exr"))
    w, h = image.size
    there = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(there)
    there = there.reshape(h, w, 4)[..., :3]
    assert np.percentile(delta_E_2000(lab(here), lab(there)), 95) <= 1.0
    assert np.abs(here - there).max() < 1e-3


def test_a_mask_image_whose_file_is_missing_is_named(sofa, tmp_path):
    from lightfade_addon import api

    mask = bpy.data.images.new("LostMask", 4, 4)
    mask.source = "FILE"
    mask.filepath = str(tmp_path / "lost_mask.png")
    api.set_parts(sofa["material"], [dict(name="Frame", recipe="BARE_WOOD", image=mask)])
    api.bake(bpy.context.scene)
    with pytest.raises(api.AgingError, match="Image 'LostMask' of material 'Carpet' has no "
                       "pixels: the file is missing"):
        api.age_scene(bpy.context.scene, years=5)


def test_removing_a_copy_of_an_aged_copy_keeps_the_aged_copys_parts(sofa):
    """A copy of an aged copy (a user's duplicate) shares its mixing group, recipe groups
    and weights: removing the duplicate leaves the aged copy whole."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.parts import _lane_groups
    from lightfade_addon.blender.reset import remove_aged

    material = sofa["material"]
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=_half_mask())])
    _age(20.0)
    scene = bpy.context.scene
    copy = _copy(material)
    before = _twin(material, 20.0).copy()                   # bakes the weights
    groups = _lane_groups(copy)
    remove_aged(copy.copy())
    assert _lane_groups(copy) == groups and len(groups) == 2
    assert all(lane.weight_image is not None for lane in copy.lightfade.lanes)
    np.testing.assert_array_equal(_twin(material, 20.0), before)
    assert api.material_plan(scene)[0]["status"] == "aged"


def _full_mask(name="PaintMask"):
    """White everywhere."""
    image = bpy.data.images.new(name, N, N)
    image.pixels.foreach_set(np.ones(N * N * 4, np.float32))
    image.pack()
    return image


def test_overlapping_masks_share_each_texel_out(sofa):
    """Two parts whose masks both cover the left half: each gets half of it (the weights
    sum to one), so the texel is the mean of the two recipes' aging there, never aged
    twice (no channel above 1); the node group (Cycles) and the numpy twin agree."""
    from lightfade_addon import api

    material = sofa["material"]
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=_half_mask()),
                             dict(name="Paint", recipe="PRINTED_PAPER", image=_full_mask())])
    wood = _alone(material, "BARE_WOOD", 30.0)
    paper = _alone(material, "PRINTED_PAPER", 30.0)
    _age(30.0)
    twin = _twin(material, 30.0)
    np.testing.assert_allclose(twin[LEFT], 0.5 * (wood[LEFT] + paper[LEFT]), atol=2e-6)
    np.testing.assert_allclose(twin[RIGHT], paper[RIGHT], atol=2e-6)
    nodes = node_evaluation(_copy(material))
    assert twin.max() <= 1.0 and nodes.max() <= 1.0
    dE = delta_E_2000(lab(nodes[1:-1, 1:-1]), lab(twin[1:-1, 1:-1]))
    assert np.percentile(dE, 99) <= 0.2 and dE.max() <= 0.5


def test_the_numpy_mix_shares_overlapping_weights_out():
    """Apply's mix: lanes' weights summing past one (two parts both claiming a texel) are
    shared out, never a second aging on top of the first; below one the rest stays."""
    from lightfade_addon.blender.aging.parts import mix_pixels

    original = np.full((3, 3), 0.6, np.float32)
    aged = [np.full((3, 3), 0.9, np.float32), np.full((3, 3), 0.95, np.float32)]
    weights = np.array([[1.0, 0.7, 0.3], [1.0, 0.6, 0.2]], np.float32)
    out = mix_pixels(original, aged, weights)
    assert out.max() <= 1.0                            # 1.25 if both aged the texel in full
    np.testing.assert_allclose(out[0], 0.925, atol=1e-6)              # half each
    np.testing.assert_allclose(out[1], 0.6 + (0.7 * 0.3 + 0.6 * 0.35) / 1.3, atol=1e-6)
    np.testing.assert_allclose(out[2], 0.6 + 0.3 * 0.3 + 0.2 * 0.35, atol=1e-6)   # as today
