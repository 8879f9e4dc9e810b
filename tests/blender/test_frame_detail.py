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


def test_the_level_is_the_coarsest_that_keeps_a_texel_a_pixel():
    from lightfade_addon.blender.aging.detail import HIDDEN_LEVEL, MAX_LEVEL, level

    assert level(0.9, (1024, 1024)) == 0
    assert level(2.0, (1024, 1024)) == 1
    assert level(3.9, (1024, 1024)) == 1
    assert level(4.0, (1024, 1024)) == 2
    assert level(1e6, (1024, 1024)) == MAX_LEVEL
    assert level(math.inf, (1024, 1024)) == HIDDEN_LEVEL
    assert level(4.0, (1000, 1024)) == 2 and level(4.0, (1002, 1024)) == 1   # 2^L divides


def test_blocks_of_two_colours_age_as_the_mean_of_their_aged_texels():
    """A block mixing two colours (a dot's edge) is aged as its two parts; a block of
    one colour (or of two close ones) as its mean: with a strongly non-linear "aging",
    the image is the block mean of the aged texels, where aging the mean is far off."""
    from lightfade_addon.blender.aging.blocks import Pyramid, block_mean
    from lightfade_addon.core.colour.srgb8 import srgb_code_floats

    rgba = np.full((32, 32, 4), 0.3, np.float32)
    rgba[..., 3] = 1.0
    rgba[:3, :5, :3] = (0.9, 0.8, 0.05)                        # a yellow dot on a grey ground
    rgba[:3, :5, 3] = 0.5                                      # half transparent
    rgba[20:, 20:, :3] += np.float32(0.001)                    # two close greys: not split

    def age(rgb):
        return rgb ** 3

    layout, samples, key = Pyramid(rgba, ("inputs", rgba.shape, 0)).samples(2)
    assert len(layout.mixed) == 2                              # the two blocks the dot is in
    assert samples.shape == (8 * 8 + 2, 1, 4) and key[-2:] == (("level", 2, (8, 8)), (0, 2))
    codes = samples[:, 0].copy()
    codes[:, :3] = srgb_code_floats(age(samples[:, 0, :3]))
    image = layout.image(codes)
    truth = block_mean(np.concatenate([age(rgba[..., :3]), rgba[..., 3:]], -1), 2)
    np.testing.assert_allclose(image[..., :3], srgb_code_floats(truth[..., :3]), atol=1.5 / 255)
    np.testing.assert_allclose(image[..., 3], truth[..., 3], atol=1e-6)   # the blocks' alpha
    naive = srgb_code_floats(age(block_mean(rgba, 2)[..., :3]))
    assert np.abs(naive - srgb_code_floats(truth[..., :3])).max() > 20 / 255


def test_block_means_are_linear_means():
    from lightfade_addon.blender.aging.blocks import block_mean

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
    pixel): the render writes the frame image at 64² (a texel a pixel), and renders as
    the live material does; 6 m away, 32²; 1.5 m away, 128²; 0.7 m away, whole; with
    Frame Detail Full, whole."""
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    _camera_and_render_settings(scene)
    _bake_and_age(years=30)
    copy = the_copy(fine["material"])
    framed = _render(scene, tmp_path, "framed.exr")
    assert tuple(frames.frame_image(copy).size) == (64, 64)
    live = _live_render(scene, tmp_path, "live.exr")
    lit = live.sum(-1) > 0.05
    scale = 1.0 / live.max()
    dE = delta_E_2000(lab(live[lit] * scale), lab(framed[lit] * scale))
    assert np.percentile(dE, 95) <= 1.0
    sizes = {}
    for name, z, detail in (("far", 6.0, "CAMERA"), ("near", 1.5, "CAMERA"),
                            ("close", 0.7, "CAMERA"), ("full", 3.0, "FULL")):
        scene.camera.location.z = z
        scene.lightfade.frame_detail = detail
        _render(scene, tmp_path, name + ".exr")
        sizes[name] = tuple(frames.frame_image(copy).size)
    assert sizes == {"far": (32, 32), "near": (128, 128), "close": (256, 256),
                     "full": (256, 256)}
