"""Image pixels as arrays: resampling and colour-space decoding."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from lightfade_addon.blender.pixels import (
    read_linear,
    read_rgba,
    readable_colourspace,
    resample,
)
from lightfade_addon.core.colour.colorimetry import srgb_decode  # noqa: E402


class TestResample:
    def test_same_shape_is_the_identity(self):
        a = np.random.default_rng(1).random((5, 7))
        assert resample(a, (5, 7)) is a

    def test_a_linear_ramp_stays_exact_inside(self):
        """Texel centres of a finer grid on a linear ramp fall on the ramp."""
        x = (np.arange(8) + 0.5) / 8
        a = np.tile(x, (4, 1))
        b = resample(a, (4, 16))
        X = (np.arange(16) + 0.5) / 16
        inside = (X >= x[0]) & (X <= x[-1])
        np.testing.assert_allclose(b[:, inside], np.tile(X[inside], (4, 1)), atol=1e-12)
        assert b.min() >= a.min() and b.max() <= a.max()

    def test_downsampling_keeps_a_constant(self):
        np.testing.assert_allclose(resample(np.full((64, 32), 3.5), (7, 9)), 3.5)


def test_srgb_byte_images_are_decoded_linear_and_float_are_not(blender):
    px = np.empty((2, 2, 4), np.float32)
    px[...] = (0.5, 0.25, 1.0, 1.0)
    byte = bpy.data.images.new("byte", 2, 2)
    byte.pixels.foreach_set(px.ravel())
    flt = bpy.data.images.new("float", 2, 2, float_buffer=True)
    flt.pixels.foreach_set(px.ravel())
    data = bpy.data.images.new("data", 2, 2)
    data.colorspace_settings.name = "Non-Color"
    data.pixels.foreach_set(px.ravel())
    np.testing.assert_allclose(read_linear(byte)[0, 0, :3],
                               srgb_decode(read_rgba(byte)[0, 0, :3]), atol=1e-6)
    np.testing.assert_allclose(read_linear(flt)[0, 0, :3], (0.5, 0.25, 1.0))
    np.testing.assert_allclose(read_linear(data)[0, 0, :3], read_rgba(data)[0, 0, :3])


def test_only_srgb_linear_rec709_and_data_byte_images_are_read_directly(blender):
    """Byte images in other colour spaces (other primaries or transfer functions, such as
    Blender 5's sRGB-encoded wide gamuts) take the baked path, where Cycles converts them."""
    image = bpy.data.images.new("byte", 2, 2)
    spaces = {i.identifier for i in image.colorspace_settings.bl_rna.properties["name"].enum_items}
    for name, readable in (("sRGB", True), ("Linear Rec.709", True), ("Non-Color", True),
                           ("Linear Rec.2020", False), ("Filmic Log", False),
                           ("sRGB Encoded AP1", False), ("sRGB Encoded P3-D65", False)):
        if name in spaces:
            image.colorspace_settings.name = name
            assert readable_colourspace(image) == readable, name


def test_srgb_codes_and_encoding_match_the_colour_science_functions():
    """The byte decoding table and the float32 encoder are IEC 61966-2-1 (colour-science)."""
    from lightfade_addon.blender.pixels import decode_srgb_bytes
    from lightfade_addon.core.colour.srgb8 import encode_srgb_f32 as encode_srgb
    from lightfade_addon.core.colour.colorimetry import srgb_decode, srgb_encode

    codes = np.arange(256, dtype=np.float32) / np.float32(255.0)
    np.testing.assert_array_equal(decode_srgb_bytes(codes),
                                  srgb_decode(np.arange(256) / 255.0).astype(np.float32))
    linear = np.linspace(0.0, 1.0, 10001, dtype=np.float32)
    np.testing.assert_allclose(encode_srgb(linear), srgb_encode(linear.astype(float)), atol=2e-6)
