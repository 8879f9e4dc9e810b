"""Aging evaluated in the material: the node group against its numpy twin, zero years,
years that drive the material without Python, real aged images."""

from types import SimpleNamespace

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
)

bpy = pytest.importorskip("bpy")

BASE_COLOR = SimpleNamespace(groups=(), node="Principled BSDF", socket="Base Color")


def rgba(image):
    a = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(a)
    return a.reshape(image.size[1], image.size[0], 4)


def the_copy(material):
    from lightfade_addon.blender.aging.copies import copies_of

    (copy,) = copies_of(material)
    return copy


def node_evaluation(copy, colour=BASE_COLOR):
    """(H, W, 3) the copy's Base Color as Cycles evaluates it (its aging node group) at
    the key texels' centres: an Emission bake in the exposure UV map."""
    from lightfade_addon.blender.albedo import bake_albedos

    W, H = copy.lightfade.albedo.size
    image = bpy.data.images.new("NodeEvaluation", W, H, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    scene = bpy.context.scene
    out = bake_albedos(scene, bpy.context.view_layer, copy.lightfade.aged_object,
                       [(copy, colour, image)], copy.lightfade.uv_map, margin=0)
    bpy.data.images.remove(image)
    return out[copy.name]


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))


def smooth_albedo(scene, name, side, interpolation):
    """Give ``scene`` (:func:`floor_scene`'s) a ``side``² float albedo ``name`` of many
    smoothly varying colours, read with ``interpolation``, Printed Paper (Blue Wool 2)
    and a strong sun; returns ``scene``."""
    albedo = bpy.data.images.new(name, side, side, alpha=True, float_buffer=True)
    albedo.colorspace_settings.name = "Linear Rec.709"
    y, x = np.mgrid[0:side, 0:side] / float(side)
    px = np.ones((side, side, 4), dtype=np.float32)
    px[..., 0] = 0.45 + 0.4 * np.sin(3 * x + 1)
    px[..., 1] = 0.35 + 0.3 * np.cos(4 * y)
    px[..., 2] = 0.1 + 0.8 * x * y
    albedo.pixels.foreach_set(px.ravel())
    albedo.pack()
    tree = scene["material"].node_tree
    node = next(n for n in tree.nodes if n.type == "TEX_IMAGE")
    node.image = albedo
    node.interpolation = interpolation
    scene["material"].lightfade.recipe = "PRINTED_PAPER"
    scene["material"].lightfade.blue_wool = 2
    scene["sun"].data.energy = 30.0
    return scene


@pytest.fixture
def textured(floor_scene):
    """The floor scene with a 32² albedo of many smoothly varying colours (a float
    image), lit by a strong sun; exposure not baked yet."""
    # Cycles' bake samples a hair (~0.003 texel) off the texel centres: Closest keeps
    # the original colour exact there, and a smooth texture keeps the keys' blend there
    # tiny, so what is compared is the two evaluators
    return smooth_albedo(floor_scene, "Noise", 32, "Closest")


def _bake_and_age(years=5):
    assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
    assert bpy.ops.lightfade.age(years=years) == {"FINISHED"}


class TestNodeGroupAgainstNumpy:
    """The two evaluators of one aging table agree texel by texel."""

    @pytest.mark.parametrize("spectra", [1, 2])
    def test_texel_centres_agree(self, textured, lf, spectra):
        from lightfade_addon import api
        from lightfade_addon.blender.aging.apply import aged_pixels

        if spectra == 2:                       # a lamp of another spectrum: a light mix
            lamp = lf.add_point(power=400.0, location=(-0.5, -0.5, 1.0))
            lamp.data.lightfade.spectrum = "INCANDESCENT"
        _bake_and_age()
        copy = the_copy(textured["material"])
        assert copy.lightfade.table_image["lightfade_table"]["S"] == spectra
        for years in (0.0, 3.0, 40.0):
            api.set_years(bpy.context.scene, years)
            # the outer ring: Cycles' bake samples border texels off their centres
            nodes = node_evaluation(copy)[1:-1, 1:-1]
            numpy = aged_pixels(bpy.context.scene, copy, years)[1:-1, 1:-1, :3]
            dE = delta_E_2000(lab(nodes), lab(numpy))
            assert np.percentile(dE, 99) <= 0.2 and dE.max() <= 0.5, (years, dE.max())
        original = aged_pixels(bpy.context.scene, copy, 0.0)[1:-1, 1:-1, :3]
        assert delta_E_2000(lab(numpy), lab(original)).mean() > 2     # a real fade

    def test_years_reach_the_group_through_the_scene_property(self, textured):
        from lightfade_addon.blender.aging.years import YEARS_PROP

        _bake_and_age()
        copy = the_copy(textured["material"])
        scene = bpy.context.scene
        scene[YEARS_PROP] = 0.0
        new = node_evaluation(copy)
        scene[YEARS_PROP] = 30.0
        old = node_evaluation(copy)
        assert np.abs(new - old).max() > 0.05
        assert scene.lightfade.years == 30.0

    def test_the_table_is_read_without_mip_maps(self, textured):
        """Every table read is an Equirectangular Environment Texture (EEVEE samples it
        without mip-maps: plain bilinear, as Cycles), none an Image Texture."""
        _bake_and_age()
        copy = the_copy(textured["material"])
        (group,) = [n.node_tree for n in copy.node_tree.nodes if n.type == "GROUP"]
        (evaluation,) = [n.node_tree for n in group.nodes if n.type == "GROUP"]
        table = [n for n in evaluation.nodes if getattr(n, "image", None) is not None
                 and n.image.name.startswith("LF_Table_")]
        # 1 spectrum: 2 reads of the unmixing, 4 of the change
        assert len(table) == 6 and all(n.type == "TEX_ENVIRONMENT" for n in table)
        assert all(n.projection == "EQUIRECTANGULAR" and n.interpolation == "Linear"
                   for n in table)


RENDER_WITHOUT_LIGHTFADE = """
import os, sys, numpy as np, bpy
assert not any(p.endswith("lightfade_addon") for p in sys.path)
bpy.context.preferences.filepaths.use_scripts_auto_execute = False
bpy.ops.wm.open_mainfile(filepath={path!r}, load_ui=False)
assert not hasattr(bpy.types.Scene, "lightfade"), "LightFade must not be installed here"
scene = bpy.context.scene
out = []
for frame in (1, 2):
    scene.frame_set(frame)
    scene.render.filepath = {folder!r} + f"/frame{{frame}}.exr"
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    a = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(a)
    out.append(a.reshape(image.size[1], image.size[0], 4)[..., :3])
np.save({out!r}, np.stack(out))
sys.stdout.flush()
os._exit(0)
"""


def _camera_and_render_settings(scene):
    data = bpy.data.cameras.new("Camera")
    cam = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(cam)
    cam.location = (0.0, 0.0, 3.0)
    scene.camera = cam
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False
    scene.cycles.seed = 7
    scene.render.resolution_x = scene.render.resolution_y = 48
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"


def _cube_shot(lf, sun_strength):
    """A slanted sun and a camera looking at a unit cube at the origin from above a corner."""
    from mathutils import Vector

    sun = lf.add_sun(strength=sun_strength)
    sun.rotation_euler = (0.6, 0.3, 0.4)
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    scene.camera.location = (2.2, -2.2, 1.8)
    scene.camera.rotation_euler = (-Vector(scene.camera.location)).to_track_quat(
        "-Z", "Y").to_euler()
    return scene


def _render(scene, folder, name):
    scene.render.filepath = str(folder / name)
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    a = rgba(image)[..., :3].copy()
    bpy.data.images.remove(image)
    return a


def test_a_saved_file_renders_its_keyframed_aging_without_lightfade(textured, tmp_path):
    """Years keyframed 0 → 40: a fresh process where LightFade is not installed (and
    auto-run scripts are off) renders both frames as this process does, and they differ."""
    import subprocess
    import sys

    from lightfade_addon import api

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=0)
    api.keyframe_years(scene, [(1, 0.0), (2, 40.0)])
    here = []
    for frame in (1, 2):
        scene.frame_set(frame)
        here.append(_render(scene, tmp_path, f"here{frame}.exr"))
    path = tmp_path / "aged.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    out = tmp_path / "there.npy"
    code = RENDER_WITHOUT_LIGHTFADE.format(path=str(path), folder=str(tmp_path), out=str(out))
    env = {k: v for k, v in __import__("os").environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-c", code], cwd=str(tmp_path), env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    there = np.load(out)
    for a, b in zip(here, there):
        assert np.percentile(delta_E_2000(lab(a), lab(b)), 95) <= 1.0
    lit = here[0].sum(-1) > 0.05
    change = delta_E_2000(lab(there[0][lit]), lab(there[1][lit]))
    assert np.median(change) > 2.0                    # the aging rendered there


def test_zero_years_renders_the_original_pixels(textured, tmp_path):
    """Age at 0 years: the same render (same seed) as before Age, pixel for pixel."""
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    textured["material"].node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 0.7
    before = _render(scene, tmp_path, "before.exr")
    _bake_and_age(years=0)
    after = _render(scene, tmp_path, "after.exr")
    assert np.abs(after - before).max() <= 1e-6


@pytest.mark.slow
def test_eevee_evaluates_the_same_aging(textured, tmp_path):
    """EEVEE (the Material Preview's engine) renders the group as Cycles does: the same
    fade between 0 and 40 years (GPUs may hold float textures in half precision)."""
    from lightfade_addon import api

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=0)
    eevee = "BLENDER_EEVEE_NEXT" if bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"
    fade = {}
    for engine in ("CYCLES", eevee):
        scene.render.engine = engine
        frames = []
        for years in (0.0, 40.0):
            api.set_years(scene, years)
            frames.append(_render(scene, tmp_path, f"{engine}{years}.exr"))
        fade[engine] = np.median(delta_E_2000(lab(frames[0]), lab(frames[1])))
    assert fade["CYCLES"] > 5
    assert abs(fade[eevee] - fade["CYCLES"]) < 0.1 * fade["CYCLES"]


def test_apply_then_live_aging_round_trip(textured):
    """Apply writes real images at the scene's years and feeds them in; Live puts the
    group back and removes them; Reset leaves nothing of either behind."""
    from lightfade_addon.blender.aging.copies import APPLIED_NAME, GROUP_NODE

    _bake_and_age(years=12)
    copy = the_copy(textured["material"])
    bsdf = copy.node_tree.nodes["Principled BSDF"]
    assert bpy.ops.lightfade.apply_aging() == {"FINISHED"}
    image = copy.lightfade.aged_image
    assert bsdf.inputs["Base Color"].links[0].from_node.name == APPLIED_NAME
    assert image["lightfade_years"] == 12.0
    from lightfade_addon.blender.aging.apply import aged_pixels
    np.testing.assert_allclose(rgba(image), aged_pixels(bpy.context.scene, copy, 12.0), atol=1e-6)
    assert bpy.ops.lightfade.live_aging() == {"FINISHED"}
    assert bsdf.inputs["Base Color"].links[0].from_node.name == GROUP_NODE
    assert copy.lightfade.aged_image is None and not any(
        i.name.startswith("LF_Applied_") for i in bpy.data.images)
    assert bpy.ops.lightfade.apply_aging() == {"FINISHED"}
    assert bpy.ops.lightfade.reset() == {"FINISHED"}
    assert [i.name for i in bpy.data.images if i.name.startswith("LF_")
            and not i.name.startswith("LF_Exposure_")] == []       # the bake stays
    assert not any(g.name.startswith(("LF_Aging_", "LF_Eval_")) for g in bpy.data.node_groups)
    original = textured["material"].node_tree.nodes["Principled BSDF"]
    assert original.inputs["Base Color"].links[0].from_node.type == "TEX_IMAGE"


def _plain_evaluation(scene, copy, years):
    """The copy's aged pixels by the plain numpy evaluator (nothing kept between calls)."""
    from lightfade_addon.blender.aging import data as agingdata, runtime
    from lightfade_addon.core.aging.colourtable import evaluate

    original = runtime.original_rgba(copy, (1, 1))
    H, W = original.shape[:2]
    flat = original.reshape(-1, 4).copy()
    table = runtime.evaluator(copy)
    inputs, _keys = agingdata.map_inputs(scene, copy.lightfade.aged_object)
    evaluate(table, flat[:, :3], agingdata.rates(inputs, table.S, (H, W)), years, out=flat)
    return flat.reshape(H, W, 4)


def test_the_maps_give_annual_doses_of_the_lamps_days_and_hours(textured):
    """Each map counts lux × hours a day × days a year (a lamp used 6 h on 200 days:
    1200 h), and never a negative dose (a map painted below zero)."""
    from lightfade_addon.blender.aging import data as agingdata

    _bake_and_age()
    scene = bpy.context.scene
    copy = the_copy(textured["material"])
    sun = next(o for o in scene.objects if o.type == "LIGHT")
    sun.data.lightfade.hours_per_day, sun.data.lightfade.days_per_year = 6.0, 200.0
    (found,), _keys = agingdata.map_inputs(scene, copy.lightfade.aged_object)
    assert found.hours == pytest.approx(1200.0)
    image = bpy.data.images.new("Painted", 4, 4, float_buffer=True)
    px = np.full((4, 4, 4), 1.0, np.float32)
    px[0, :, 0] = -50.0
    image.pixels.foreach_set(px.ravel())
    doses = agingdata.rates([agingdata.MapInput(image, 0, 1200.0)], 1, (4, 4)).reshape(4, 4)
    assert np.all(doses[0] == 0.0) and np.allclose(doses[2:], 1200.0)


def test_applied_images_follow_years_painting_and_exposure(textured):
    """What Apply keeps per texel between calls (doses, the change around the last
    years) never shows through: each Apply equals the plain evaluator after a years
    change, after the artist paints the texture and after the exposure changes."""
    from lightfade_addon import api

    _bake_and_age(years=12)
    scene = bpy.context.scene
    copy = the_copy(textured["material"])
    for years in (12.0, 12.0, 13.0, 2.0):
        api.apply_aging(scene, years)
        np.testing.assert_allclose(rgba(copy.lightfade.aged_image),
                                   _plain_evaluation(scene, copy, years), atol=2e-5)
    albedo = copy.lightfade.albedo
    px = rgba(albedo)
    px[..., :3] = px[..., :3][::-1, ::-1]                      # painted over
    albedo.pixels.foreach_set(px.ravel())
    api.apply_aging(scene, 2.0)
    np.testing.assert_allclose(rgba(copy.lightfade.aged_image),
                               _plain_evaluation(scene, copy, 2.0), atol=2e-5)
    exposure = copy.lightfade.aged_object.lightfade.exposure_maps[0].image
    lux = rgba(exposure)
    lux[..., :3] *= 4.0
    exposure.pixels.foreach_set(lux.ravel())
    exposure["lightfade_bake_id"] = int(exposure.get("lightfade_bake_id", 0)) + 1  # a re-bake
    api.apply_aging(scene, 2.0)
    np.testing.assert_allclose(rgba(copy.lightfade.aged_image),
                               _plain_evaluation(scene, copy, 2.0), atol=2e-5)


def test_zero_years_is_exact_on_overlapping_out_of_range_uvs_and_procedurals(blender, lf,
                                                                              tmp_path):
    """A tiled text-like texture (UVs far outside 0–1, every face on the same UV square:
    overlapping islands, so the bake makes its own UV map) mixed with a procedural: the
    baked path. At 0 years the render is the original's, pixel for pixel; at 30 years
    it has faded and the tiles' fine detail is as sharp as before (the group multiplies
    the artist's own full-resolution graph)."""
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    cube = bpy.context.active_object
    uv = cube.data.uv_layers.active.data
    corners = ((-2.0, 0.0), (3.0, 0.0), (3.0, 5.0), (-2.0, 5.0))   # outside 0–1
    for poly in cube.data.polygons:                           # every face on one square
        for k, li in enumerate(poly.loop_indices):
            uv[li].uv = corners[k]
    mat = bpy.data.materials.new("Label")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    tree = mat.node_tree
    text = bpy.data.images.new("Text", 64, 64, alpha=True)
    px = np.ones((64, 64, 4), np.float32)
    px[::4, :, :3] = 0.05                                      # thin dark lines: "text"
    px[:, 1::5, 0] = 0.9
    text.pixels.foreach_set(px.ravel())
    text.pack()
    image = tree.nodes.new("ShaderNodeTexImage")
    image.image, image.interpolation, image.extension = text, "Closest", "REPEAT"
    noise = tree.nodes.new("ShaderNodeTexNoise")
    mix = tree.nodes.new("ShaderNodeMixRGB")
    mix.inputs["Fac"].default_value = 0.3
    tree.links.new(image.outputs["Color"], mix.inputs["Color1"])
    tree.links.new(noise.outputs["Color"], mix.inputs["Color2"])
    tree.links.new(mix.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    mat.lightfade.enabled = True
    mat.lightfade.recipe = "PRINTED_PAPER"
    mat.lightfade.blue_wool = 2
    cube.data.materials.append(mat)
    scene = _cube_shot(lf, sun_strength=30.0)
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.lightfade.bake_resolution = 64
    before = _render(scene, tmp_path, "before.exr")
    assert (before.sum(-1) > 0.1).mean() > 0.2                  # the cube fills the frame
    _bake_and_age(years=0)
    copy = the_copy(mat)
    assert copy.lightfade.path == "BAKED" and copy.lightfade.uv_map != "UVMap"
    assert np.abs(_render(scene, tmp_path, "zero.exr") - before).max() <= 1e-6
    from lightfade_addon import api

    api.set_years(scene, 30.0)
    old = _render(scene, tmp_path, "old.exr")
    cube_px = before.sum(-1) > 0.1
    assert np.median(delta_E_2000(lab(old[cube_px]), lab(before[cube_px]))) > 1.0
    # the dark lines keep their contrast: horizontal gradients as strong as before
    edge = lambda a: np.abs(np.diff(a.mean(-1), axis=0))
    assert np.percentile(edge(old), 99) > 0.6 * np.percentile(edge(before), 99)


def test_applied_images_render_as_the_material_does(textured, tmp_path):
    """The real aged images of Apply render what the aging group renders (p95 ΔE00 ≤ 1),
    with texels smaller than pixels, as in a production texture."""
    from lightfade_addon import api

    node = next(n for n in textured["material"].node_tree.nodes if n.type == "TEX_IMAGE")
    node.image.scale(192, 192)
    node.interpolation = "Linear"
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=0)
    api.set_years(scene, 40.0)
    live = _render(scene, tmp_path, "live.exr")
    api.apply_aging(scene)
    applied = _render(scene, tmp_path, "applied.exr")
    lit = live.sum(-1) > 0.05
    scale = 1.0 / live.max()                             # a bright sun: back into [0, 1]
    dE = delta_E_2000(lab(live[lit] * scale), lab(applied[lit] * scale))
    assert np.percentile(dE, 95) <= 1.0
    api.live_aging(scene)
    np.testing.assert_array_equal(_render(scene, tmp_path, "live2.exr"), live)


def test_an_imported_gltf_model_renders_its_original_pixels_at_zero_years(blender, lf,
                                                                          tmp_path):
    """A model as an artist gets it: exported to glTF and imported with Blender's own
    importer (a tiled texture over UVs 0–4, every face on one UV square, sheen 0.6)."""
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    cube = bpy.context.active_object
    uv = cube.data.uv_layers.active.data
    for poly in cube.data.polygons:
        for k, li in enumerate(poly.loop_indices):
            uv[li].uv = ((0, 0), (4, 0), (4, 4), (0, 4))[k]
    mat = bpy.data.materials.new("Fabric")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    weave = bpy.data.images.new("weave", 64, 64)
    y, x = np.mgrid[0:64, 0:64]
    px = np.ones((64, 64, 4), np.float32)
    px[..., 0] = 0.5 + 0.4 * ((x // 8 + y // 8) % 2)
    px[..., 1] = 0.2 + 0.3 * (y % 16 < 2)
    px[..., 2] = 0.3
    weave.pixels.foreach_set(px.ravel())
    weave.filepath_raw, weave.file_format = str(tmp_path / "weave.png"), "PNG"
    weave.save()
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = weave
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Sheen Weight" if "Sheen Weight" in bsdf.inputs else "Sheen"].default_value = 0.6
    cube.data.materials.append(mat)
    bpy.ops.export_scene.gltf(filepath=str(tmp_path / "model.glb"), export_format="GLB")
    lf.reset_file()
    import addon_utils

    addon_utils.enable(lf.ADDON, default_set=True)
    bpy.ops.import_scene.gltf(filepath=str(tmp_path / "model.glb"))
    obj = next(o for o in bpy.context.scene.objects if o.type == "MESH")
    fabric = obj.material_slots[0].material
    fabric.lightfade.enabled = True
    fabric.lightfade.recipe = "DYED_FABRIC"
    fabric.lightfade.blue_wool = 2
    scene = _cube_shot(lf, sun_strength=20.0)
    for o in scene.objects:
        o.select_set(False)
    before = _render(scene, tmp_path, "before.exr")
    assert (before.sum(-1) > 0.1).mean() > 0.2
    _bake_and_age(years=0)
    assert the_copy(fabric).lightfade.uv_map == "LightFadeUV"       # the made UV map
    assert np.abs(_render(scene, tmp_path, "zero.exr") - before).max() <= 1e-6
    from lightfade_addon import api

    api.set_years(scene, 20.0)
    cube_px = before.sum(-1) > 0.1
    old = _render(scene, tmp_path, "old.exr")
    assert np.median(delta_E_2000(lab(old[cube_px] / before.max()),
                                  lab(before[cube_px] / before.max()))) > 1.0


def test_a_procedural_colour_applies_as_the_group_renders(textured):
    """The baked path: a procedural Base Color ages in the material from the shading
    point's colour; Apply to Images bakes that colour (the group muted) and ages it with
    the numpy twin, which agrees with the group at the texel centres."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import aged_pixels

    tree = textured["material"].node_tree
    image_node = next(n for n in tree.nodes if n.type == "TEX_IMAGE")
    wave = tree.nodes.new("ShaderNodeTexWave")           # smooth bands of colour
    wave.inputs["Scale"].default_value = 1.5
    ramp = tree.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.6, 0.15, 0.3, 1.0)
    ramp.color_ramp.elements[1].color = (0.2, 0.5, 0.7, 1.0)
    tree.links.new(wave.outputs["Fac"], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    tree.nodes.remove(image_node)
    _bake_and_age(years=10)
    copy = the_copy(textured["material"])
    assert copy.lightfade.path == "BAKED" and copy.lightfade.albedo is None   # Age bakes nothing
    numpy = aged_pixels(bpy.context.scene, copy, 10.0)[1:-1, 1:-1, :3]
    assert copy.lightfade.albedo is not None                 # baked once applied
    nodes = node_evaluation(copy)[1:-1, 1:-1]
    dE = delta_E_2000(lab(nodes), lab(numpy))
    assert np.percentile(dE, 99) <= 0.3, np.percentile(dE, 99)
    assert api.material_plan(bpy.context.scene)[0]["status"] == "aged"
