"""The grid cache folder is the caller's to set; the gamut rule keeps hue."""

import numpy as np
import pytest

from lightfade_addon.core.fading import cache
from lightfade_addon.core.colour.colorimetry import linear_srgb_to_XYZ
from lightfade_addon.core.colour.gamut import (
    LUMA,
    into_gamut,
    into_gamut_planes,
    out_of_gamut,
)
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.fading.recipes import RECIPES
from lightfade_addon.core.fading.spectra import light_spectrum


class TestCacheDirectory:
    def test_set_directory_wins_over_the_environment(self, tmp_path, monkeypatch):
        monkeypatch.setenv("LIGHTFADE_CACHE", str(tmp_path / "env"))
        try:
            cache.set_directory(tmp_path / "blender")
            assert cache.directory() == tmp_path / "blender"
            cache.load_or_build(RECIPES["printed-paper"], light_spectrum("daylight")[None], 1e6,
                                GridSettings(points=3, doses=5))
            assert len(list((tmp_path / "blender").glob("grid-*.npz"))) == 1
            assert not (tmp_path / "env").exists()
        finally:
            cache.set_directory(None)
        assert cache.directory() == tmp_path / "env"


class TestIntoGamut:
    def test_in_range_colours_are_untouched(self):
        rgb = np.random.default_rng(0).uniform(0, 1, (100, 3)).astype(np.float32)
        np.testing.assert_array_equal(into_gamut(rgb), rgb)

    def test_out_of_range_colours_keep_hue_and_luminance(self):
        rgb = np.array([[1.3, 0.4, 0.1], [0.2, 0.5, -0.15], [-0.1, 0.3, 1.4], [0.9, -0.05, 0.95]])
        out = into_gamut(rgb)
        assert not out_of_gamut(out).any()
        np.testing.assert_allclose(out @ LUMA, np.clip(rgb @ LUMA, 0, 1), atol=1e-6)

        def xy(c):
            XYZ = linear_srgb_to_XYZ(c)
            return XYZ[:, :2] / XYZ.sum(axis=1, keepdims=True)
        # mixing with the neutral keeps the dominant wavelength: the chromaticity moves
        # on the line from the white point towards the original, not past it
        w = xy(np.ones((1, 3)))
        a, b = xy(rgb) - w, xy(out) - w
        np.testing.assert_allclose(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], 0.0, atol=1e-9)
        assert np.all((a * b).sum(axis=1) > 0)

    def test_luminance_above_one_becomes_white_and_below_zero_black(self):
        np.testing.assert_allclose(into_gamut(np.array([[1.5, 1.2, 1.1]])), [[1, 1, 1]])
        np.testing.assert_allclose(into_gamut(np.array([[-0.5, -0.2, -0.1]])), [[0, 0, 0]])

    def test_strided_rgba_view_is_mapped_in_place(self):
        out = np.array([[1.4, 0.2, 0.1, 0.7], [0.1, 0.2, 0.3, 0.4]], np.float32)
        into_gamut(out[:, :3], out=out[:, :3])
        assert not out_of_gamut(out[:, :3]).any()
        np.testing.assert_array_equal(out[:, 3], np.float32([0.7, 0.4]))

    def test_planes_follow_the_same_rule(self):
        """The slider's fast path on (3, k) planes maps every colour as into_gamut does."""
        rgb = np.array([[1.3, 0.4, 0.1], [0.2, 0.5, -0.15], [-0.1, 0.3, 1.4], [0.9, -0.05, 0.95],
                        [1.5, 1.2, 1.1], [-0.5, -0.2, -0.1], [0.3, 0.6, 0.2]], np.float32)
        planes = np.ascontiguousarray(rgb.T)
        assert into_gamut_planes(planes) is planes
        np.testing.assert_allclose(planes.T, into_gamut(rgb), atol=1e-6)

    def test_nan_is_refused(self):
        with pytest.raises(ValueError, match="NaN"):
            into_gamut(np.array([[np.nan, 0.5, 1.5]]))
