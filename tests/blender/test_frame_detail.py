"""Frame images at the detail the camera resolves (blender/aging/detail.py)."""

import math

import numpy as np
import pytest

from tests.blender.test_frames import _live_render
from tests.blender.test_material_aging import (
    _bake_and_age,
    _camera_and_render_settings,
    _render,
    lab,
    smooth_albedo,
    the_copy,
)
from lightfade_addon.core.colour.colorimetry import delta_E_2000

bpy = pytest.importorskip("bpy")


def _square(z=0.0, side=1.0, uv_scale=(1.0, 1.0)):
    """Two triangles of a ``side`` m square at height ``z`` facing +z, UVs over
    ``uv_scale`` of the texture: ``(world (2, 3, 3), uv (2, 3, 2))``."""
    s, (a, b) = side, uv_scale
    world = np.array([[[0, 0, z], [s, 0, z], [s, s, z]], [[0, 0, z], [s, s, z], [0, s, z]]], float)
    uv = np.array([[[0, 0], [a, 0], [a, b]], [[0, 0], [a, b], [0, b]]], float)
    return world, uv


def test_texels_per_metre_is_the_fewest_in_any_direction():
    from lightfade_addon.blender.aging.detail import texels_per_metre

    world, uv = _square()
    np.testing.assert_allclose(texels_per_metre(world, uv, (1024, 1024)), 1024.0)
    np.testing.assert_allclose(texels_per_metre(world, uv, (512, 2048)), 512.0)
    world, uv = _square(uv_scale=(0.25, 1.0))                 # squeezed along u
    np.testing.assert_allclose(texels_per_metre(world, uv, (1024, 1024)), 256.0)
    turn = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])   # a rotation
    np.testing.assert_allclose(texels_per_metre(world @ turn.T, uv, (1024, 1024)), 256.0)
    collapsed = uv.copy()
    collapsed[0, 2] = collapsed[0, 1]                         # no area in the texture:
    assert texels_per_metre(world, collapsed, (1024, 1024))[0] == 0.0   # a palette's swatch
    flat = world.copy()
    flat[0, 2] = flat[0, 1]                                   # no area in the world
    assert np.isinf(texels_per_metre(flat, uv, (1024, 1024))[0])


def _view(distance, res=100, fov=math.radians(40.0)):
    """A square perspective view down −z from ``distance`` m above the origin, as
    :func:`min_texels_per_pixel` takes it, and the world → camera shift."""
    half = math.tan(fov / 2)
    return (-half, half, -half, half), 2 * half / res, (0.1, 100.0), distance


def test_a_pixel_spans_texels_in_proportion_to_its_depth():
    from lightfade_addon.blender.aging.detail import min_texels_per_pixel, texels_per_metre

    world, uv = _square(side=2.0)
    world -= (1.0, 1.0, 0.0)                                   # centred under the camera
    sigma = texels_per_metre(world, uv, (1024, 1024))         # 512 a metre
    found = []
    for distance in (2.0, 4.0):
        frame, per_depth, clip, d = _view(distance)
        found.append(min_texels_per_pixel(world - (0, 0, d), sigma, frame, per_depth, False, clip))
    frame, per_depth, clip, d = _view(2.0)
    assert found[0] == pytest.approx(512.0 * per_depth * 2.0, rel=1e-6)
    assert found[1] == pytest.approx(2.0 * found[0], rel=1e-6)
    behind = min_texels_per_pixel(world + (0, 0, 2.0), sigma, frame, per_depth, False, clip)
    assert math.isinf(behind)                                  # the camera looks away
    aside = min_texels_per_pixel(world + (50.0, 0, -2.0), sigma, frame, per_depth, False, clip)
    assert math.isinf(aside)                                   # out of the frame
    ortho = min_texels_per_pixel(world - (0, 0, 9.0), sigma, (-1, 1, -1, 1), 0.02, True, clip)
    assert ortho == pytest.approx(512.0 * 0.02)               # no depth in an ortho view


def test_a_floor_under_the_camera_counts_where_the_frame_sees_it():
    """A 20 m floor 1.5 m below a camera looking ahead: its corners and centre are out
    of the frame, or far; the nearest point seen lies on the frame's lower edge."""
    from lightfade_addon.blender.aging.detail import min_texels_per_pixel, texels_per_metre

    world, uv = _square(side=20.0)
    world -= (10.0, 10.0, 1.5)
    # camera space: the camera looks along +y of the world (−z of its own), up is +z
    camera = np.stack([world[..., 0], world[..., 2], -world[..., 1]], -1)
    sigma = texels_per_metre(world, uv, (1024, 1024))
    frame, per_depth, clip, _d = _view(0.0)
    found = min_texels_per_pixel(camera, sigma, frame, per_depth, False, clip)
    nearest = 1.5 / math.tan(math.radians(20.0))               # depth of the lower edge
    assert found == pytest.approx(sigma[0] * per_depth * nearest, rel=0.1)


def test_the_level_is_the_coarsest_that_keeps_two_texels_a_pixel():
    from lightfade_addon.blender.aging.detail import HIDDEN_LEVEL, MAX_LEVEL, level

    assert level(1.5, (1024, 1024)) == 0
    assert level(4.0, (1024, 1024)) == 1
    assert level(7.9, (1024, 1024)) == 1
    assert level(8.0, (1024, 1024)) == 2
    assert level(1e6, (1024, 1024)) == MAX_LEVEL
    assert level(math.inf, (1024, 1024)) == HIDDEN_LEVEL
    assert level(8.0, (1000, 1024)) == 2 and level(8.0, (1002, 1024)) == 1   # 2^L divides


def _receding_floor(tile_units=8):
    """A 20 m floor 1.5 m below a camera looking ahead and down 20° (camera space),
    its 1024² texture in tiles of ``1024 / tile_units``: ``(camera (2, 3, 3), uv,
    sigma, size, tile, view args)``."""
    from lightfade_addon.blender.aging.detail import texels_per_metre

    world, uv = _square(side=20.0)
    world -= (10.0, 0.5, 1.5)                                  # from 0.5 m ahead of the camera
    a = math.radians(20.0)                                     # pitched down by a
    forward, up = np.array([0, math.cos(a), -math.sin(a)]), np.array([0, math.sin(a), math.cos(a)])
    camera = np.stack([world[..., 0], world @ up, -(world @ forward)], -1)
    sigma = texels_per_metre(world, uv, (1024, 1024))
    frame, per_depth, clip, _d = _view(0.0)
    return camera, uv, sigma, (1024, 1024), 1024 // tile_units, (frame, per_depth, False, clip)


def test_each_tile_counts_the_nearest_point_it_shows():
    """Tile by tile, the floor's texels a pixel follow its depth: the rows near the
    camera finer than the far ones, the tiles behind the camera or out of the frame
    unseen, and never more than the depth of the tile's nearest corner allows (the
    ground truth: the floor's points inside the frustum, densely sampled)."""
    from lightfade_addon.blender.aging.detail import (frustum_planes, pixel_size,
                                                     tile_texels_per_pixel)

    camera, uv, sigma, size, tile, (frame, per_depth, ortho, clip) = _receding_floor()
    tpp = tile_texels_per_pixel(camera, uv, sigma, size, tile, frame, per_depth, ortho, clip)
    assert tpp.shape == (8, 8) and not np.isnan(tpp).any()     # the floor covers every tile
    seen = np.isfinite(tpp)
    assert seen[:, 3:5].all() and not seen[:, 0].any()         # its sides leave the frame
    column = tpp[:, 4]
    assert np.all(np.diff(column) > 0)                         # farther rows, more texels a pixel
    assert column[-1] > 5 * column[1]
    # the dense truth: no tile claims more texels a pixel than its nearest point shows
    a, b = np.meshgrid(np.linspace(0, 1, 600), np.linspace(0, 1, 600))
    inside_tri = a + b <= 1
    a, b = a[inside_tri], b[inside_tri]
    planes = frustum_planes(frame, ortho, clip)
    truth = np.full((8, 8), np.inf)
    for t in range(2):
        p = camera[t, 0] + a[:, None] * (camera[t, 1] - camera[t, 0]) + b[:, None] * (camera[t, 2] - camera[t, 0])
        q = uv[t, 0] + a[:, None] * (uv[t, 1] - uv[t, 0]) + b[:, None] * (uv[t, 2] - uv[t, 0])
        ok = np.all(p @ planes[:, :3].T + planes[:, 3] >= 0, axis=1)
        ij = np.minimum((q[ok] * 8).astype(int), 7)
        np.minimum.at(truth, (ij[:, 1], ij[:, 0]), sigma[t] * pixel_size(-p[ok, 2], per_depth, False))
    assert np.all(tpp[np.isfinite(truth)] <= truth[np.isfinite(truth)] * 1.0001)
    assert np.all(np.isinf(tpp[np.isinf(truth)]) | (tpp[np.isinf(truth)] < np.inf))


def test_a_repeating_texture_folds_its_tiles():
    """UVs over four repeats: wrapped, every tile takes the nearest of its repeats;
    clamped (Extend), the repeats past the edge land on the edge tiles."""
    from lightfade_addon.blender.aging.detail import tile_texels_per_pixel

    camera, uv, sigma, size, tile, (frame, per_depth, ortho, clip) = _receding_floor()
    wrapped = tile_texels_per_pixel(camera, uv * 4, sigma * 4, size, tile, frame, per_depth,
                                    ortho, clip, wrap=True)
    clamped = tile_texels_per_pixel(camera, uv * 4, sigma * 4, size, tile, frame, per_depth,
                                    ortho, clip, wrap=False)
    assert np.isfinite(wrapped).all()                          # some repeat of each tile is seen
    # clamped, a tile inside the texture is shown by the first repeat alone: no finer
    clamped = np.where(np.isnan(clamped), np.inf, clamped)
    assert np.all(wrapped <= clamped) and np.any(wrapped < clamped)
    assert np.isinf(clamped[:-1, :-1]).sum() > np.isinf(wrapped).sum()


def test_tile_levels_keep_gutters_and_unseen_tiles_coarse():
    from lightfade_addon.blender.aging.detail import HIDDEN_LEVEL, tile_levels, tile_side

    tpp = np.array([[1.0, 4.0, 8.0, np.inf],
                    [np.nan, 1e6, np.nan, np.nan]])
    levels = tile_levels(tpp, 32)
    np.testing.assert_array_equal(levels[0], [0, 1, 2, HIDDEN_LEVEL])
    assert levels[1, 0] == 0                                   # a gutter: its finest neighbour
    assert levels[1, 1] == 4                                   # MAX_LEVEL
    assert levels[1, 2] == 1 and levels[1, 3] == 2
    assert tile_levels(np.array([[1e6]]), 4)[0, 0] == 2        # a tile keeps a texel
    assert tile_side((1024, 512)) == 32 and tile_side((1000, 1000)) == 8 and tile_side((7, 5)) == 1


def test_a_mosaic_gathers_each_tile_at_its_level_and_expands_back():
    from lightfade_addon.blender.aging.mosaic import block_mean
    from lightfade_addon.blender.aging.mosaic import Mosaic

    rng = np.random.default_rng(1)
    rgba = rng.random((64, 96, 4)).astype(np.float32)
    mosaic = Mosaic(np.array([[0, 1, 2], [3, 1, 1]], np.int8), 32)
    samples = mosaic.gather(lambda L: block_mean(rgba, L))
    assert samples.shape == (mosaic.n, 4) and mosaic.n == 32 * 32 + 3 * 16 * 16 + 8 * 8 + 4 * 4
    image = mosaic.expand(samples)
    assert image.shape == (64, 96, 4) and mosaic.base == 0
    np.testing.assert_array_equal(image[:32, :32], rgba[:32, :32])
    level2 = block_mean(rgba, 2)[:8, 16:24]                    # tile (0, 2) at level 2
    np.testing.assert_allclose(image[:32, 64:], np.repeat(np.repeat(level2, 4, 0), 4, 1))
    level3 = block_mean(rgba, 3)[4:8, :4]                      # tile (1, 0) at level 3
    np.testing.assert_allclose(image[32:, :32], np.repeat(np.repeat(level3, 8, 0), 8, 1))
    coarse = Mosaic(np.array([[1, 2]], np.int8), 32)           # written at its finest level
    assert coarse.expand(coarse.gather(lambda L: block_mean(rgba[:32, :64], L))).shape == (16, 32, 4)


def test_blocks_of_two_colours_age_as_the_mean_of_their_aged_texels():
    """A block mixing two colours (a dot's edge) is aged as its two parts; a block of
    one colour (or of two close ones) as its mean: with a strongly non-linear "aging",
    the image is the block mean of the aged texels, where aging the mean is far off."""
    from lightfade_addon.blender.aging.mosaic import block_mean
    from lightfade_addon.blender.aging.mosaic import Mosaic, Pyramid
    from lightfade_addon.core.colour.srgb8 import srgb_code_floats

    rgba = np.full((32, 32, 4), 0.3, np.float32)
    rgba[..., 3] = 1.0
    rgba[:3, :5, :3] = (0.9, 0.8, 0.05)                        # a yellow dot on a grey ground
    rgba[20:, 20:, :3] += np.float32(0.001)                    # two close greys: not split

    def age(rgb):
        return rgb ** 3

    mosaic = Mosaic(np.array([[2]], np.int8), 32)
    layout, samples, _key = Pyramid(rgba, ("inputs", rgba.shape, 0)).samples(mosaic)
    assert len(layout.mixed) == 2                              # the two blocks the dot is in
    codes = samples[:, 0].copy()
    codes[:, :3] = srgb_code_floats(age(samples[:, 0, :3]))
    image = layout.image(codes)
    truth = block_mean(np.concatenate([age(rgba[..., :3]), rgba[..., 3:]], -1), 2)
    np.testing.assert_allclose(image[..., :3], srgb_code_floats(truth[..., :3]), atol=1.5 / 255)
    naive = srgb_code_floats(age(block_mean(rgba, 2)[..., :3]))
    assert np.abs(naive - srgb_code_floats(truth[..., :3])).max() > 20 / 255


def test_block_means_are_linear_means():
    from lightfade_addon.blender.aging.mosaic import block_mean

    rgba = np.arange(4 * 8 * 4, dtype=np.float32).reshape(4, 8, 4)
    small = block_mean(rgba, 1)
    assert small.shape == (2, 4, 4)
    np.testing.assert_allclose(small[0, 0], rgba[:2, :2].mean(axis=(0, 1)))
    assert block_mean(rgba, 0) is rgba


@pytest.fixture
def fine(floor_scene):
    """The floor scene with a 256² smooth albedo read with Linear interpolation."""
    return smooth_albedo(floor_scene, "Fine", 256, "Linear")


def test_a_far_camera_renders_a_coarser_frame_image_that_agrees(fine, tmp_path):
    """The floor 3 m under a 48-pixel camera (about six texels of the 256² texture a
    pixel): the render writes the frame image at 128², and renders as the live material
    does; 6 m away, 64²; 1 m away, whole; with Frame Detail Full, whole."""
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=30)
    copy = the_copy(fine["material"])
    framed = _render(scene, tmp_path, "framed.exr")
    assert tuple(frames.frame_image(copy).size) == (128, 128)
    live = _live_render(scene, tmp_path, "live.exr")
    lit = live.sum(-1) > 0.05
    scale = 1.0 / live.max()
    dE = delta_E_2000(lab(live[lit] * scale), lab(framed[lit] * scale))
    assert np.percentile(dE, 95) <= 1.0
    sizes = {}
    for name, z, detail in (("far", 6.0, "CAMERA"), ("near", 1.0, "CAMERA"), ("full", 3.0, "FULL")):
        scene.camera.location.z = z
        scene.lightfade.frame_detail = detail
        _render(scene, tmp_path, name + ".exr")
        sizes[name] = tuple(frames.frame_image(copy).size)
    assert sizes == {"far": (64, 64), "near": (256, 256), "full": (256, 256)}


def test_a_receding_floor_renders_near_tiles_finer_and_agrees(fine, tmp_path):
    """The floor seen from its edge, receding: its near tiles keep more detail than its
    far ones (a mosaic of levels, not the level of its nearest point everywhere), fewer
    texels are aged than the texture has, and the render agrees with the live one."""
    from mathutils import Vector

    from lightfade_addon.blender.aging import frames, detail

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    scene.camera.location = (0.0, -2.6, 0.9)
    scene.camera.rotation_euler = (Vector((0.0, 0.4, 0.0)) - scene.camera.location).to_track_quat(
        "-Z", "Y").to_euler()
    _bake_and_age(years=30)
    copy = the_copy(fine["material"])
    framed = _render(scene, tmp_path, "framed.exr")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mosaic = frames.frame_mosaic(copy, detail.camera_view(scene, depsgraph), depsgraph)
    seen = mosaic.levels[mosaic.levels < detail.HIDDEN_LEVEL]
    assert seen.min() < seen.max(), mosaic.levels
    near = mosaic.levels[0][mosaic.levels[0] < detail.HIDDEN_LEVEL]        # its corners unseen
    assert near.max() < mosaic.levels[-1].min(), mosaic.levels               # near rows finer
    assert mosaic.n < 256 * 256 // 2
    assert tuple(frames.frame_image(copy).size) == (256 >> mosaic.base,) * 2
    live = _live_render(scene, tmp_path, "live.exr")
    lit = live.sum(-1) > 0.05
    scale = 1.0 / live.max()
    dE = delta_E_2000(lab(live[lit] * scale), lab(framed[lit] * scale))
    assert np.percentile(dE, 95) <= 1.0
    # the texture repeated three times over the floor: every tile is seen in some repeat
    uv = fine["floor"].data.uv_layers[copy.lightfade.uv_map].data
    for loop in uv:
        loop.uv = (loop.uv[0] * 3, loop.uv[1] * 3)
    frames.frame_nodes(copy)[0][1].extension = "REPEAT"
    depsgraph = bpy.context.evaluated_depsgraph_get()
    repeated = frames.frame_mosaic(copy, detail.camera_view(scene, depsgraph), depsgraph)
    assert (repeated.levels < detail.HIDDEN_LEVEL).all(), repeated.levels
