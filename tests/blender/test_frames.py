"""Renders where LightFade is installed read aged images written for the frame
(blender/aging/frames.py); the saved file keeps rendering the live material."""

import numpy as np
import pytest

from tests.blender.test_material_aging import (
    _bake_and_age,
    _camera_and_render_settings,
    _render,
    lab,
    rgba,
    the_copy,
    textured,  # noqa: F401  (fixture)
)
from lightfade_addon.core.colour.colorimetry import delta_E_2000

bpy = pytest.importorskip("bpy")


def switched(frames):
    """The frame switches' factors (0: live, 1: frame image)."""
    return [mix.inputs["Fac"].default_value for _copy, mix in frames.switches()]


def assert_holds(image, linear):
    """``image`` (8-bit sRGB) holds the linear colours ``linear`` (H, W, 4), each
    rounded to its nearest code."""
    from lightfade_addon.core.colour.srgb8 import encode_srgb_f32 as encode_srgb

    assert not image.is_float and image.colorspace_settings.name == "sRGB"
    codes = np.rint(rgba(image)[..., :3] * 255.0)
    encoded = encode_srgb(linear[..., :3]).astype(np.float32)     # Blender's rounding:
    want = np.floor(np.float32(255.0) * encoded + np.float32(0.5))  # float32, half up
    np.testing.assert_array_equal(codes, np.clip(want, 0, 255))


def _live_render(scene, folder, name):
    """A render without the frame handler (the live material renders)."""
    from lightfade_addon.blender.aging import frames

    bpy.app.handlers.render_pre.remove(frames.on_render_pre)
    try:
        return _render(scene, folder, name)
    finally:
        bpy.app.handlers.render_pre.append(frames.on_render_pre)


def test_a_render_reads_the_frame_images_written_for_it(textured, tmp_path, monkeypatch):
    """The handler writes each copy's aged colour at the frame's years (Apply's pixels),
    the render shows that image (a painted-over frame image shows), the switch is off
    again afterwards, and the render agrees with the live material's."""
    from lightfade_addon.blender.aging import frames
    from lightfade_addon.blender.aging.apply import aged_pixels

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=30)
    copy = the_copy(textured["material"])
    assert switched(frames) == [0.0]
    framed = _render(scene, tmp_path, "framed.exr")
    assert switched(frames) == [0.0]
    image = frames.frame_image(copy)
    assert image["lightfade_years"] == 30.0
    assert_holds(image, aged_pixels(scene, copy, 30.0))

    real = frames.write_frame

    def green(scene, copy, years, *more):           # what the render reads: the image
        image = real(scene, copy, years, *more)
        px = rgba(image)
        px[..., :3] = (0.0, 1.0, 0.0)
        image.pixels.foreach_set(px.ravel())
        return image

    monkeypatch.setattr(frames, "write_frame", green)
    painted = _render(scene, tmp_path, "painted.exr")
    lit = framed.sum(-1) > 0.05
    assert np.median(painted[lit][:, 1] / np.maximum(painted[lit].sum(-1), 1e-6)) > 0.9
    monkeypatch.setattr(frames, "write_frame", real)

    live = _live_render(scene, tmp_path, "live.exr")
    scale = 1.0 / live.max()
    dE = delta_E_2000(lab(live[lit] * scale), lab(framed[lit] * scale))
    assert np.percentile(dE, 95) <= 1.0
    assert np.abs(live - framed).max() > 0                # not the same branch


def test_frame_images_are_written_only_when_what_they_hold_changes(textured, monkeypatch):
    """The same years again writes nothing; other years, a painted texture and a re-bake
    write again, each time Apply's pixels."""
    from lightfade_addon.blender.aging import frames, runtime
    from lightfade_addon.blender.aging.apply import aged_pixels

    scene = bpy.context.scene
    _bake_and_age(years=8)
    copy = the_copy(textured["material"])
    runs = []
    real = runtime.aged_rgb

    def counted(*args, **kwargs):
        runs.append(args[3])
        return real(*args, **kwargs)

    monkeypatch.setattr(runtime, "aged_rgb", counted)
    frames.write_frames(scene, 8.0)
    frames.write_frames(scene, 8.0)
    assert runs == [8.0]
    frames.write_frames(scene, 9.0)
    assert runs == [8.0, 9.0]
    albedo = copy.lightfade.albedo
    px = rgba(albedo)
    px[..., :3] *= 0.5                                           # painted darker
    albedo.pixels.foreach_set(px.ravel())
    frames.write_frames(scene, 9.0)
    assert runs == [8.0, 9.0, 9.0]
    exposure = copy.lightfade.aged_object.lightfade.exposure_maps[0].image
    exposure["lightfade_bake_id"] = int(exposure.get("lightfade_bake_id", 0)) + 1
    frames.write_frames(scene, 9.0)
    assert runs == [8.0, 9.0, 9.0, 9.0]
    assert_holds(frames.frame_image(copy), aged_pixels(scene, copy, 9.0))


def _counting(monkeypatch):
    """``(reads, runs)``: the copies' colours read (``runtime.original_rgba``) and the
    years aged (``runtime.aged_rgb``) from now on."""
    from lightfade_addon.blender.aging import runtime

    reads, runs = [], []
    read, age = runtime.original_rgba, runtime.aged_rgb

    def counted_read(*args, **kwargs):
        reads.append(args[0].name)
        return read(*args, **kwargs)

    def counted_age(*args, **kwargs):
        runs.append(args[3])
        return age(*args, **kwargs)

    monkeypatch.setattr(runtime, "original_rgba", counted_read)
    monkeypatch.setattr(runtime, "aged_rgb", counted_age)
    return reads, runs


def _bmp_texture(textured, path):
    """The texture saved as a BMP at ``path`` (uncompressed: the same size whatever its
    colours) and loaded in its place; returns ``(image, save)``, ``save(px)`` writing
    pixels ``px`` into the file."""
    node = next(n for n in textured["material"].node_tree.nodes if n.type == "TEX_IMAGE")

    def save(px):
        writer = bpy.data.images.new("Writer", 32, 32)
        writer.pixels.foreach_set(px.ravel())
        writer.filepath_raw = str(path)
        writer.file_format = "BMP"
        writer.save()
        bpy.data.images.remove(writer)

    save(rgba(node.image))
    node.image = bpy.data.images.load(str(path))
    return node.image, save


def test_a_texture_as_packed_is_not_read_again(textured, monkeypatch):
    """A frame at the years its image holds does not read a texture that is as it was
    packed; a stroke on one texel packed (packed data of the same size: a float image
    packs uncompressed) is aged once; a stroke not packed is read at every frame (its
    colour compared) and aged once; packed, read once more, and other years age the
    colour held without reading it."""
    from lightfade_addon.blender.aging import frames
    from lightfade_addon.blender.aging.apply import aged_pixels

    scene = bpy.context.scene
    _bake_and_age(years=8)
    copy = the_copy(textured["material"])
    albedo = copy.lightfade.albedo
    albedo.pack()
    assert not albedo.is_dirty and albedo.packed_file is not None
    size = albedo.packed_file.size
    reads, runs = _counting(monkeypatch)
    frames.write_frames(scene, 8.0)
    frames.write_frames(scene, 8.0)
    assert (len(reads), runs) == (1, [8.0])
    px = rgba(albedo)
    px[16, 16, :3] *= 0.5                                        # a one-texel stroke,
    albedo.pixels.foreach_set(px.ravel())
    albedo.pack()                                                # packed
    assert not albedo.is_dirty and albedo.packed_file.size == size
    frames.write_frames(scene, 8.0)
    frames.write_frames(scene, 8.0)
    assert (len(reads), runs) == (2, [8.0, 8.0])
    px[16, 17, :3] *= 0.5                                        # another, not packed:
    albedo.pixels.foreach_set(px.ravel())
    frames.write_frames(scene, 8.0)                              # read at every frame
    frames.write_frames(scene, 8.0)
    assert (len(reads), runs) == (4, [8.0, 8.0, 8.0])
    albedo.pack()
    frames.write_frames(scene, 8.0)                              # read once: the same
    frames.write_frames(scene, 9.0)                              # other years: the colour
    frames.write_frames(scene, 10.0)                             # held is aged again
    assert (len(reads), runs) == (5, [8.0, 8.0, 8.0, 9.0, 10.0])
    assert_holds(frames.frame_image(copy), aged_pixels(scene, copy, 10.0))


def test_a_texture_file_changed_on_disk_is_aged_again(textured, tmp_path, monkeypatch):
    """A texture read from a file: not read again while the file is the same; the file
    overwritten (same size) and the image reloaded, the frame is aged again."""
    from lightfade_addon.blender.aging import frames
    from lightfade_addon.blender.aging.apply import aged_pixels

    scene = bpy.context.scene
    path = tmp_path / "noise.bmp"
    image, save = _bmp_texture(textured, path)
    _bake_and_age(years=8)
    copy = the_copy(textured["material"])
    assert copy.lightfade.albedo == image and image.packed_file is None
    reads, runs = _counting(monkeypatch)
    frames.write_frames(scene, 8.0)
    frames.write_frames(scene, 8.0)
    assert (len(reads), runs) == (1, [8.0])
    size = path.stat().st_size
    px = rgba(image)
    px[..., :3] *= 0.5
    save(px)                                                     # edited elsewhere
    assert path.stat().st_size == size
    image.reload()
    frames.write_frames(scene, 8.0)
    frames.write_frames(scene, 8.0)
    assert (len(reads), runs) == (2, [8.0, 8.0])
    assert_holds(frames.frame_image(copy), aged_pixels(scene, copy, 8.0))


def test_zero_years_renders_the_original_pixels_with_frames(textured, tmp_path, monkeypatch):
    """At 0 years the switch stays on the live side, whose gate passes the original."""
    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    before = _render(scene, tmp_path, "before.exr")
    _bake_and_age(years=0)
    assert np.abs(_render(scene, tmp_path, "after.exr") - before).max() <= 1e-6


def test_the_switch_is_never_saved_on(textured, tmp_path):
    """Saved in the middle of a render: the file holds the switch off and one-texel frame
    images; the render in progress keeps its switch."""
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=10)
    frames.on_render_pre(scene)
    assert switched(frames) == [1.0]
    image = frames.frame_image(the_copy(textured["material"]))
    assert tuple(image.size) == tuple(the_copy(textured["material"]).lightfade.albedo.size)
    path = tmp_path / "mid_render.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    assert switched(frames) == [1.0]
    frames.on_render_end(scene)
    assert switched(frames) == [0.0]
    bpy.ops.wm.open_mainfile(filepath=str(path))
    assert switched(frames) == [0.0]
    (image,) = [i for i in bpy.data.images if i.name.startswith(frames.FRAME_PREFIX)]
    assert tuple(image.size) == (1, 1)


def _links(tree, node):
    return sorted((link.from_node.name, link.from_socket.identifier, link.to_node.name,
                   link.to_socket.identifier) for link in tree.links
                  if node in (link.from_node, link.to_node))


def test_the_render_reads_a_stub_of_the_aging_group_and_gives_it_back(textured, tmp_path):
    """For the render the aging group node reads a stub (its sockets, no nodes: nothing
    for Cycles to convert and fold), with every link kept; a file saved mid-render and
    the end of the render have the group itself again, and the stub is gone."""
    from lightfade_addon.blender.aging import frames
    from lightfade_addon.blender.aging.copies import GROUP_NODE

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=10)
    material = textured["material"].name
    copy = the_copy(textured["material"])
    tree = copy.node_tree
    node = tree.nodes[GROUP_NODE]
    group, links = node.node_tree, _links(tree, node)
    group_name = group.name
    sockets = [(i.identifier, i.in_out) for i in group.interface.items_tree]
    groups = len(bpy.data.node_groups)
    frames.on_render_pre(scene)
    stub = node.node_tree
    assert stub is not group
    assert {n.type for n in stub.nodes} <= {"GROUP_INPUT", "GROUP_OUTPUT"}
    assert [(i.identifier, i.in_out) for i in stub.interface.items_tree] == sockets
    assert _links(tree, node) == links
    path = tmp_path / "mid_render.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    again = tree.nodes[GROUP_NODE].node_tree                   # the render goes on
    assert again != group and {n.type for n in again.nodes} <= {"GROUP_INPUT", "GROUP_OUTPUT"}
    frames.on_render_end(scene)
    assert node.node_tree == group and _links(tree, node) == links
    assert len(bpy.data.node_groups) == groups
    bpy.ops.wm.open_mainfile(filepath=str(path))
    saved = the_copy(bpy.data.materials[material]).node_tree
    assert saved.nodes[GROUP_NODE].node_tree.name == group_name


def test_a_frame_back_at_zero_years_reads_the_aging_group_itself(textured):
    """An animation whose years return to 0: that frame renders the live side, which
    reads the aging group itself, not the previous frame's stub."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import frames
    from lightfade_addon.blender.aging.copies import GROUP_NODE

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=10)
    node = the_copy(textured["material"]).node_tree.nodes[GROUP_NODE]
    group = node.node_tree
    frames.on_render_pre(scene)
    assert node.node_tree != group
    api.set_years(scene, 0.0)
    frames.on_render_pre(scene)                 # the next frame of the same render
    assert switched(frames) == [0.0] and node.node_tree == group
    frames.on_render_end(scene)


def test_an_animation_writes_each_frames_years(textured, tmp_path):
    """Keyed years 0 → 40 rendered as an animation: each frame's images at its years."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=0)
    api.keyframe_years(scene, [(1, 0.0), (3, 40.0)])
    seen = []
    real = frames.write_frame

    def spy(scene, copy, years, *more):
        seen.append(years)
        return real(scene, copy, years, *more)

    frames.write_frame = spy
    try:
        scene.frame_start, scene.frame_end = 1, 3
        scene.render.filepath = str(tmp_path / "anim_")
        bpy.ops.render.render(animation=True)
    finally:
        frames.write_frame = real
    assert seen == pytest.approx([0.0, 20.0, 40.0])
    assert switched(frames) == [0.0]


def test_a_subframe_reads_the_years_between_its_keys(blender):
    """Motion blur renders subframes: each reads the keyed years at its own time."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    api.keyframe_years(scene, [(1, 0.0), (3, 40.0)])
    scene.frame_set(2, subframe=0.5)
    assert frames.frame_years(scene) == pytest.approx(30.0)


def test_a_texture_with_a_history_shows_its_frame_image_at_zero_years(blender):
    """At 0 years a new texture renders the live side (the original pixel for pixel);
    one that was already old renders its frame image: its 0 years is the restoration."""
    from types import SimpleNamespace

    from lightfade_addon.blender.aging import frames

    material = bpy.data.materials.new("Print")
    copy = SimpleNamespace(lightfade=SimpleNamespace(source=material))
    assert not frames._shows(copy, 0.0) and frames._shows(copy, 0.5)
    material.lightfade.already_years = 10.0
    assert frames._shows(copy, 0.0)


def test_reset_removes_the_frame_images(textured):
    from lightfade_addon.blender.aging import frames

    _bake_and_age(years=5)
    assert any(i.name.startswith(frames.FRAME_PREFIX) for i in bpy.data.images)
    assert bpy.ops.lightfade.reset() == {"FINISHED"}
    assert not any(i.name.startswith(frames.FRAME_PREFIX) for i in bpy.data.images)


def test_eevee_renders_the_live_material(textured, tmp_path, monkeypatch):
    """EEVEE evaluates the group at about an image's cost: no frame images for it (a
    switch flipped per render would recompile its shaders)."""
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    _bake_and_age(years=10)
    scene.render.engine = "BLENDER_EEVEE_NEXT" if bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"
    called = []
    monkeypatch.setattr(frames, "write_frames", lambda *a, **k: called.append(a))
    frames.on_render_pre(scene)
    assert called == [] and switched(frames) == [0.0]
    scene.render.engine = "CYCLES"
    frames.on_render_pre(scene)
    assert len(called) == 1 and switched(frames) == [1.0]
    frames.on_render_end(scene)


def test_apply_ages_the_colour_held_until_the_texture_is_painted(textured, monkeypatch):
    """Apply to Images reads a clean texture once (the frame images and Apply share the
    colour held); painted, the texture is read again and the applied image follows
    it, against the evaluator of the colour read afresh."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import frames, runtime

    scene = bpy.context.scene
    _bake_and_age(years=8)
    copy = the_copy(textured["material"])
    albedo = copy.lightfade.albedo
    albedo.pack()
    reads, _runs = _counting(monkeypatch)
    frames.write_frames(scene, 8.0)
    api.apply_aging(scene, 9.0)
    api.apply_aging(scene, 10.0)
    assert len(reads) == 1
    px = rgba(albedo)
    px[..., :3] *= 0.5                                           # painted darker
    albedo.pixels.foreach_set(px.ravel())
    applied = rgba(api.apply_aging(scene, 10.0)[copy.name])
    assert len(reads) == 2
    fresh = runtime.original_rgba(copy, (1, 1))
    want = runtime.aged_rgb(scene, copy, fresh.copy(), 10.0)
    np.testing.assert_allclose(applied[..., :3], want[..., :3], atol=1e-6)
    assert_holds(frames.write_frames(scene, 10.0)[copy.name], want)
