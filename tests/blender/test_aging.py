"""Aging in Blender: bake, age, years slider, keyframes, reset, save/reload, bad input."""

import hashlib

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)

bpy = pytest.importorskip("bpy")


def rgba(image):
    a = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(a)
    return a.reshape(image.size[1], image.size[0], 4)


def aged_image(material):
    """Real aged pixels of ``material``'s only aged copy at the scene's years (the numpy
    evaluator of its aging table, which test_material_aging.py checks against the
    material's node group)."""
    from lightfade_addon.blender.aging.apply import apply_copy
    from lightfade_addon.blender.aging.copies import copies_of
    from lightfade_addon.blender.aging.years import get_years

    (copy,) = copies_of(material)
    return apply_copy(bpy.context.scene, copy, get_years(bpy.context.scene))


def the_copy_props(material):
    from lightfade_addon.blender.aging.copies import copies_of

    (copy,) = copies_of(material)
    return copy.lightfade


def lab_linear(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))


@pytest.fixture
def carpet(floor_scene):
    """The floor scene with a uniform 64² wool-red albedo, its exposure baked."""
    mat, albedo = floor_scene["material"], floor_scene["albedo"]
    albedo.scale(64, 64)
    px = np.empty((64, 64, 4), np.float32)
    px[...] = (0.8, 0.2, 0.45, 1.0)
    albedo.pixels.foreach_set(px.ravel())
    albedo.pack()
    mat.lightfade.recipe = "DYED_FABRIC"
    floor_scene["sun"].data.energy = 30.0                   # ~20,000 lux of sunshine
    assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
    floor_scene["original"] = rgba(albedo).copy()
    return floor_scene


def footprint(obj):
    lux = rgba(obj.lightfade.exposure_maps["Sun"].image)[..., 0]
    near = np.max([np.roll(lux, (i, j), (0, 1)) for i in range(-2, 3) for j in range(-2, 3)], 0)  # 2-texel rim: denoised edges
    # ~1 lux at most: the grid's first dose interval overestimates the fade of dim texels
    return near < 1e-4 * np.percentile(lux, 90), lux > 0.5 * np.percentile(lux, 90)


class TestAge:
    def test_shadow_keeps_its_colour_lit_texels_fade(self, carpet):
        assert bpy.ops.lightfade.age(years=5) == {"FINISHED"}
        mat = carpet["material"]
        aged = rgba(aged_image(mat))[..., :3]
        original = srgb_decode(carpet["original"][..., :3])
        dE = delta_E_2000(lab_linear(aged), lab_linear(original)).reshape(64, 64)
        dark, lit = footprint(carpet["floor"])
        assert dark.sum() > 10 and lit.sum() > 100
        assert dE[dark].max() < 0.5
        assert dE[lit].mean() > 5

    def test_original_is_untouched_and_still_in_the_file(self, carpet):
        before = hashlib.sha256(rgba(carpet["albedo"]).tobytes()).hexdigest()
        bpy.ops.lightfade.age(years=5)
        bpy.context.scene.lightfade.years = 30
        assert hashlib.sha256(rgba(carpet["albedo"]).tobytes()).hexdigest() == before
        assert carpet["albedo"].name in bpy.data.images

    def test_zero_years_reproduces_the_original(self, carpet):
        bpy.context.scene.lightfade.years = 5      # the operator's 0 is 0, not the slider
        bpy.ops.lightfade.age(years=0)
        assert bpy.context.scene.lightfade.years == 0
        aged = rgba(aged_image(carpet["material"]))[..., :3]
        original = srgb_decode(carpet["original"][..., :3])
        assert delta_E_2000(lab_linear(aged), lab_linear(original)).max() < 0.01

    def test_years_slider_updates_the_texture(self, carpet):
        bpy.ops.lightfade.age(years=1)
        one = rgba(aged_image(carpet["material"])).copy()
        bpy.context.scene.lightfade.years = 20.0
        twenty = rgba(aged_image(carpet["material"]))
        _, lit = footprint(carpet["floor"])
        assert np.abs(twenty - one)[lit].max() > 0.02

    def test_a_trip_through_huge_years_gives_the_same_pixels_back(self, carpet):
        """The dose axis is absolute and saturates: nothing is prepared for the years."""
        bpy.ops.lightfade.age(years=20)
        twenty = rgba(aged_image(carpet["material"])).copy()
        from lightfade_addon import api

        for years in (1e3, 1e6, 1e9):
            api.set_years(bpy.context.scene, years)
            assert np.abs(rgba(aged_image(carpet["material"])) - twenty).max() > 0.01
        api.set_years(bpy.context.scene, 20.0)
        np.testing.assert_array_equal(rgba(aged_image(carpet["material"])), twenty)

    def test_keyframed_years_update_per_frame(self, carpet):
        bpy.ops.lightfade.age(years=0)
        scene = bpy.context.scene
        from lightfade_addon import api

        api.keyframe_years(scene, [(1, 0.0), (10, 30.0)])
        scene.frame_set(1)
        first = rgba(aged_image(carpet["material"])).copy()
        scene.frame_set(10)
        assert abs(scene.lightfade.years - 30.0) < 1e-6
        assert np.abs(rgba(aged_image(carpet["material"])) - first).max() > 0.02

    def test_animation_renders_frames_that_differ(self, carpet, tmp_path):
        scene = bpy.context.scene
        bpy.ops.lightfade.age(years=0)
        from lightfade_addon import api

        api.keyframe_years(scene, [(1, 0.0), (2, 40.0)])
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        scene.collection.objects.link(cam)
        cam.location = (0, 0, 3)
        scene.camera = cam
        scene.render.engine = "CYCLES"
        scene.cycles.samples = 1
        scene.cycles.device = "CPU"
        scene.render.resolution_x = scene.render.resolution_y = 24
        scene.render.image_settings.file_format = "PNG"
        scene.render.filepath = str(tmp_path / "frame_")
        scene.frame_start, scene.frame_end = 1, 2
        bpy.ops.render.render(animation=True)
        frames = sorted(tmp_path.glob("frame_*.png"))
        assert len(frames) == 2
        a, b = (bpy.data.images.load(str(f)) for f in frames)
        assert np.abs(rgba(a) - rgba(b)).max() > 0.05

    def test_flat_base_colour_is_aged_too(self, carpet):
        mat = carpet["material"]
        tree = mat.node_tree
        bsdf = tree.nodes["Principled BSDF"]
        tree.links.remove(bsdf.inputs["Base Color"].links[0])
        bsdf.inputs["Base Color"].default_value = (0.1, 0.4, 0.7, 1.0)
        assert bpy.ops.lightfade.age(years=10) == {"FINISHED"}
        from lightfade_addon.blender.aging.copies import copies_of

        (copy,) = copies_of(mat)
        assert copy.lightfade.path == "FLAT"
        copy_bsdf = copy.node_tree.nodes["Principled BSDF"]
        group = copy_bsdf.inputs["Base Color"].links[0].from_node
        assert group.name == "LightFade Aging"
        assert tuple(group.inputs[0].default_value) == pytest.approx((0.1, 0.4, 0.7, 1.0))
        assert copy.lightfade.table_image is not None
        assert not bsdf.inputs["Base Color"].is_linked          # the original is untouched
        assert carpet["floor"].material_slots[0].material == copy

    def test_python_api(self, carpet):
        from lightfade_addon import api

        copies = api.age_scene(years=3)
        assert [c.name for c in copies] == ["LF_Aged_Carpet.Floor"]
        assert api.set_years(years=7) >= 0
        assert bpy.context.scene.lightfade.years == 7
        api.reset()
        assert "LF_Aged_Carpet.Floor" not in bpy.data.images


class TestReset:
    def test_reset_restores_the_node_tree_and_removes_images(self, carpet):
        mat = carpet["material"]
        links_before = sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name,
                               l.to_socket.identifier) for l in mat.node_tree.links)
        nodes_before = sorted(n.name for n in mat.node_tree.nodes)
        images_before = sorted(i.name for i in bpy.data.images)
        bpy.ops.lightfade.age(years=5)
        assert bpy.ops.lightfade.reset() == {"FINISHED"}
        assert sorted(n.name for n in mat.node_tree.nodes) == nodes_before
        assert sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name,
                       l.to_socket.identifier) for l in mat.node_tree.links) == links_before
        assert sorted(i.name for i in bpy.data.images) == images_before
        assert not [m for m in bpy.data.materials if m.name.startswith("LF_")]


class TestSaveReload:
    def test_round_trip_renders_without_simulating(self, carpet, tmp_path, monkeypatch):
        bpy.ops.lightfade.age(years=4)
        aged_before = rgba(aged_image(carpet["material"])).copy()
        path = str(tmp_path / "aged.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        mat = bpy.data.materials["Carpet"]
        assert aged_image(mat) is not None and aged_image(mat).packed_file
        np.testing.assert_allclose(rgba(aged_image(mat)), aged_before, atol=1e-6)
        from lightfade_addon.core.fading import gridbuild

        monkeypatch.setattr(gridbuild, "build_grid", lambda *a, **k: pytest.fail("simulated"))
        bpy.context.scene.lightfade.years = 12            # ager rebuilt from the file's grid
        assert np.abs(rgba(aged_image(mat)) - aged_before).max() > 0.01


    def test_saving_twice_keeps_the_aged_pixels(self, carpet, tmp_path):
        bpy.ops.lightfade.age(years=4)
        path = str(tmp_path / "twice.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        (copy,) = [m for m in bpy.data.materials if m.lightfade.source is not None]
        image = copy.lightfade.table_image
        assert image.packed_file is not None and len(image.pixels) > 0
        assert image["lightfade_table"]["T"] > 2


    def test_a_save_after_a_years_change_stores_the_new_pixels(self, carpet, tmp_path):
        bpy.ops.lightfade.age(years=4)
        path = str(tmp_path / "later.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.context.scene.lightfade.years = 12                # the packed image is now dirty
        twelve = rgba(aged_image(carpet["material"])).copy()
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        np.testing.assert_allclose(rgba(aged_image(bpy.data.materials["Carpet"])), twelve,
                                   atol=1e-6)


class TestBadInput:
    def test_without_exposure_maps_the_operator_reports_the_object(self, floor_scene):
        with pytest.raises(RuntimeError, match="Object 'Floor' has no exposure maps"):
            bpy.ops.lightfade.age(years=2)             # no bake yet: one error line
        assert len(bpy.data.materials) == 1

    def test_error_message_names_the_object(self, floor_scene):
        from lightfade_addon.blender.errors import AgingError
        from lightfade_addon.blender.aging.prepare import age_scene

        with pytest.raises(AgingError, match="Floor.*Bake Exposure"):
            age_scene(bpy.context.scene, 2)

    @pytest.mark.parametrize("years", [-1.0, float("nan")])
    def test_negative_or_nan_years(self, carpet, years):
        from lightfade_addon.blender.errors import AgingError
        from lightfade_addon.blender.aging.prepare import age_scene

        with pytest.raises(AgingError, match="Years"):
            age_scene(bpy.context.scene, years)

    def test_every_problem_is_reported_at_once_before_any_change(self, carpet):
        from lightfade_addon.blender.errors import AgingError
        from lightfade_addon.blender.aging.prepare import age_scene

        carpet["box"].data.materials.append(carpet["material"])    # no exposure maps
        node = carpet["material"].node_tree.nodes["Image Texture"]
        missing = bpy.data.images.new("Missing", 8, 8)
        missing.source = "FILE"
        missing.filepath = "//nowhere.png"
        node.image = missing
        with pytest.raises(AgingError) as err:
            age_scene(bpy.context.scene, 2)
        assert "Object 'Box'" in str(err.value) and "Bake Exposure" in str(err.value)
        assert "Image 'Missing'" in str(err.value) and "2 problems" in str(err.value)
        assert len(bpy.data.materials) == 1

    def test_missing_images(self, carpet, tmp_path):
        from lightfade_addon.blender.errors import AgingError
        from lightfade_addon.blender.aging.prepare import age_scene

        node = carpet["material"].node_tree.nodes["Image Texture"]
        missing = bpy.data.images.new("Missing", 8, 8)
        missing.source = "FILE"
        missing.filepath = str(tmp_path / "nowhere.png")
        node.image = missing
        with pytest.raises(AgingError, match="Missing"):
            age_scene(bpy.context.scene, 2)

    def test_material_without_nodes_or_nothing_enabled(self, carpet):
        from lightfade_addon.blender.errors import AgingError
        from lightfade_addon.blender.aging.prepare import age_scene

        carpet["material"].lightfade.enabled = False
        bpy.ops.object.select_all(action="DESELECT")
        with pytest.raises(AgingError, match="Nothing to age"):
            age_scene(bpy.context.scene, 2)


def test_handlers_are_added_once_and_removed(blender):
    import addon_utils

    from lightfade_addon.blender import handlers

    for _ in range(2):
        addon_utils.disable("lightfade_addon", default_set=True)
        addon_utils.enable("lightfade_addon", default_set=True)
    for handler_list, fn in handlers.HANDLERS:
        assert sum(h.__name__ == fn.__name__ for h in handler_list) == 1
    addon_utils.disable("lightfade_addon", default_set=True)
    for handler_list, fn in handlers.HANDLERS:
        assert not any(h.__name__ == fn.__name__ for h in handler_list)
    addon_utils.enable("lightfade_addon", default_set=True)


def test_zero_configuration(blender, lf):
    """Select a mesh with an albedo image, bake, age: defaults apply (printed paper, 8 h/day)."""
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    mat = bpy.data.materials.new("Poster")
    if bpy.app.version < (5, 0, 0):  # Blender 4.x: no node tree until this (5.0+: always on)
        mat.use_nodes = True
    image = bpy.data.images.new("PosterAlbedo", 32, 32)
    px = np.empty((32, 32, 4), np.float32)
    px[...] = (0.9, 0.1, 0.6, 1.0)
    image.pixels.foreach_set(px.ravel())
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    mat.node_tree.links.new(tex.outputs["Color"],
                            mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    plane.data.materials.append(mat)
    lf.add_sun(strength=20.0, theta_deg=10.0)
    scene = bpy.context.scene
    scene.lightfade.bake_resolution, scene.lightfade.bake_samples = 32, 4
    for o in bpy.context.view_layer.objects:
        o.select_set(o == plane)
    bpy.context.view_layer.objects.active = plane
    assert not mat.lightfade.enabled
    assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
    assert bpy.ops.lightfade.age(years=5) == {"FINISHED"}
    aged = rgba(aged_image(mat))[..., :3]
    assert mat.lightfade.recipe == "PRINTED_PAPER"
    dE = delta_E_2000(lab_linear(aged), lab_linear(srgb_decode(px[..., :3])))
    assert dE.mean() > 2


def test_bake_can_report_material_problems_before_cycles(floor_scene):
    """Before any bake: material problems are found, a missing exposure is not one."""
    from lightfade_addon.blender.targets import material_problems

    tree = floor_scene["material"].node_tree
    assert material_problems(bpy.context.scene) == []
    second = tree.nodes.new("ShaderNodeBsdfPrincipled")
    mix = tree.nodes.new("ShaderNodeMixShader")
    out = tree.get_output_node("ALL")
    tree.links.new(tree.nodes["Principled BSDF"].outputs["BSDF"], mix.inputs[1])
    tree.links.new(second.outputs["BSDF"], mix.inputs[2])
    tree.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    (problem,) = material_problems(bpy.context.scene)
    assert "Carpet" in problem and "several colour BSDFs" in problem


def test_diffuse_bsdf_colour_is_aged(carpet):
    """A Diffuse BSDF's Color is the colour socket; the image goes the direct way."""
    from lightfade_addon.blender.aging.copies import copies_of

    mat = carpet["material"]
    tree = mat.node_tree
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(tree.nodes["Image Texture"].outputs["Color"], diffuse.inputs["Color"])
    tree.links.new(diffuse.outputs["BSDF"], tree.get_output_node("ALL").inputs["Surface"])
    assert bpy.ops.lightfade.age(years=5) == {"FINISHED"}
    (copy,) = copies_of(mat)
    assert copy.lightfade.path == "DIRECT"
    fed = copy.node_tree.nodes[diffuse.name].inputs["Color"].links[0].from_node
    assert fed.name == "LightFade Aging"
    assert fed.inputs[0].links[0].from_node.image == mat.node_tree.nodes["Image Texture"].image


def test_only_an_image_colour_through_the_exposure_uv_map_is_read_directly(carpet):
    """The direct path needs the image's Color output, a live link and the exposure's UV
    map; anything else is baked, and a muted link passes nothing (a plain colour)."""
    from lightfade_addon import api

    tree = carpet["material"].node_tree
    tex, bsdf = tree.nodes["Image Texture"], tree.nodes["Principled BSDF"]

    def plan():
        (row,) = api.material_plan(bpy.context.scene)
        return row["path"], row["reason"]

    assert plan()[0] == "DIRECT"
    tree.links.new(tex.outputs["Alpha"], bsdf.inputs["Base Color"])
    assert plan()[0] == "BAKED"
    tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"]).is_muted = True
    assert plan()[0] == "FLAT"
    bsdf.inputs["Base Color"].links[0].is_muted = False
    carpet["floor"].data.uv_layers.new(name="Other")          # a copy of the exposure's UVs
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = "Other"
    tree.links.new(uv.outputs["UV"], tex.inputs["Vector"])
    path, reason = plan()
    assert path == "BAKED" and "samples UV map 'Other'" in reason


def test_material_settings_become_the_core_recipe_and_history(blender):
    """β is in millionths; the Blue Wool class moves the recipe's weakest dye; the texture's
    history is one light of the given spectrum, filter, lux and hours a day, every day."""
    from lightfade_addon.blender.aging.runtime import material_prior, material_recipe
    from lightfade_addon.core.aging.ager import Light, Prior

    s = bpy.data.materials.new("Print").lightfade
    s.blue_wool = 5
    assert material_recipe(s.id_data).blue_wool == (7.0, 5.5, 5.0)    # printed paper: (5, 3.5, 3)
    s.sensitivity_mode, s.beta = "BETA", 23.0
    assert material_recipe(s.id_data).sensitivity().max() == pytest.approx(23e-6)
    assert material_prior(s.id_data) is None
    s.already_years, s.already_spectrum, s.already_uv_filter = 10.0, "LED", True
    s.already_lux, s.already_hours_per_day = 300.0, 5.0
    assert material_prior(s.id_data) == Prior(10.0, (Light("led", True, 300.0, 5.0, 365.0),))


def test_bake_operator_refuses_material_problems_before_cycles(floor_scene):
    tree = floor_scene["material"].node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    with pytest.raises(RuntimeError, match="Carpet.*no Principled or Diffuse BSDF"):
        bpy.ops.lightfade.bake_exposure()
    assert len(floor_scene["floor"].lightfade.exposure_maps) == 0
