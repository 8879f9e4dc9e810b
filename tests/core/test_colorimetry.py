"""Tests for lightfade_addon.core.colour.colorimetry."""

import colour
import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    XYZ_to_linear_srgb,
    delta_E_2000,
    delta_E_ab,
    linear_srgb_to_XYZ,
    reflectance_to_Lab,
    reflectance_to_linear_srgb,
    reflectance_to_XYZ,
    rms_delta_R,
    srgb_decode,
    srgb_encode,
    white_XYZ,
    xyz_weights,
)
from lightfade_addon.core.fading.spectra import WAVELENGTHS

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
FINE = np.arange(360.0, 831.0)


def smooth_R(lam):
    """A smooth, non-trivial reflectance in [0.1, 0.8]."""
    return 0.4 + 0.3 * np.sin(lam / 40.0) + 0.1 * np.cos(lam / 90.0)


class TestXyzWeights:
    def test_shape_and_white(self):
        M = xyz_weights(WAVELENGTHS)
        assert M.shape == (41, 3)
        assert M[:, 1].sum() == pytest.approx(1.0, abs=1e-12)

    def test_cached_and_read_only(self):
        M = xyz_weights(WAVELENGTHS)
        assert xyz_weights(list(WAVELENGTHS)) is M
        with pytest.raises(ValueError):
            M[0, 0] = 1.0

    def test_outside_cmf_range_gets_no_weight(self):
        M = xyz_weights(WAVELENGTHS)
        # Hats of 300..348 nm end at or below 360 nm.
        assert np.all(M[WAVELENGTHS <= 348.0] == 0.0)
        assert np.all(M[WAVELENGTHS == 360.0] > 0.0)

    @pytest.mark.parametrize("illuminant", ["D65", "D50", "A"])
    def test_matches_colour_sd_to_XYZ_at_1nm(self, illuminant):
        sd = colour.SpectralDistribution(smooth_R(FINE), FINE)
        # Aligned to the CMF shape as sd_to_XYZ would do itself (minus its warning).
        illum = colour.SDS_ILLUMINANTS[illuminant].copy().align(CMFS.shape)
        expected = colour.sd_to_XYZ(sd, CMFS, illum, method="Integration") / 100.0
        got = reflectance_to_XYZ(smooth_R(FINE), FINE, illuminant)
        np.testing.assert_allclose(got, expected, rtol=1e-5)

    def test_default_grid_close_to_1nm(self):
        lab_fine = reflectance_to_Lab(smooth_R(FINE), FINE)
        lab_grid = reflectance_to_Lab(smooth_R(WAVELENGTHS), WAVELENGTHS)
        assert delta_E_ab(lab_fine, lab_grid) < 1.0

    def test_exact_for_piecewise_linear(self):
        R = np.random.default_rng(1).random(41)
        on_fine = np.interp(FINE, WAVELENGTHS, R)
        np.testing.assert_allclose(
            reflectance_to_XYZ(R, WAVELENGTHS), reflectance_to_XYZ(on_fine, FINE), rtol=1e-12
        )

    def test_bad_inputs(self):
        with pytest.raises(ValueError, match="increasing"):
            xyz_weights([500.0, 400.0])
        with pytest.raises(ValueError, match="illuminant"):
            xyz_weights(WAVELENGTHS, "D99")


class TestReflectanceToLab:
    @pytest.mark.parametrize("illuminant", ["D65", "D50"])
    def test_perfect_white(self, illuminant):
        lab = reflectance_to_Lab(np.ones(41), WAVELENGTHS, illuminant)
        np.testing.assert_allclose(lab, [100.0, 0.0, 0.0], atol=1e-10)

    def test_grey_is_neutral(self):
        lab = reflectance_to_Lab(np.full(41, 0.18), WAVELENGTHS)
        np.testing.assert_allclose(lab[1:], 0.0, atol=1e-10)
        assert lab[0] == pytest.approx(116 * 0.18 ** (1 / 3) - 16)

    def test_black(self):
        np.testing.assert_allclose(reflectance_to_Lab(np.zeros(41), WAVELENGTHS), 0.0, atol=1e-12)

    def test_batches_are_computed_spectrum_by_spectrum(self):
        R = np.random.default_rng(2).random((4, 5, 41))
        lab = reflectance_to_Lab(R, WAVELENGTHS)
        one_by_one = [[reflectance_to_Lab(r, WAVELENGTHS) for r in row] for row in R]
        np.testing.assert_allclose(lab, one_by_one, rtol=1e-12)
        assert len({tuple(v) for v in lab.reshape(-1, 3).round(6)}) == 20   # all distinct


class TestXYZToLab:
    def test_matches_colour(self):
        rng = np.random.default_rng(3)
        XYZ = rng.random((200, 3)) * [0.95, 1.0, 1.09]
        XYZ[:20] *= 1e-3  # the linear segment below epsilon
        W = white_XYZ()
        expected = colour.XYZ_to_Lab(XYZ, W[:2] / W.sum())
        np.testing.assert_allclose(XYZ_to_Lab(XYZ), expected, atol=1e-10)

    def test_matches_colour_under_another_white_for_any_shape(self):
        """Written out for speed (the unmixing's hot path): the same CIE 15 formulae as
        colour-science, with the illuminant's own white, on (..., 3) arrays, below
        zero too (a solver's step can leave the gamut)."""
        rng = np.random.default_rng(5)
        XYZ = rng.uniform(-0.05, 1.1, (4, 25, 3))
        W = white_XYZ("A")
        expected = colour.XYZ_to_Lab(XYZ, W[:2] / W.sum())
        np.testing.assert_allclose(XYZ_to_Lab(XYZ, "A"), expected, atol=1e-10)

    def test_white_point_is_d65(self):
        W = white_XYZ("D65")
        np.testing.assert_allclose(W[:2] / W.sum(), [0.3127, 0.3290], atol=2e-4)


class TestSrgb:
    def test_white_is_one(self):
        np.testing.assert_allclose(
            reflectance_to_linear_srgb(np.ones(41), WAVELENGTHS), 1.0, atol=1e-12
        )

    def test_round_trip(self):
        rgb = np.random.default_rng(4).random((10, 3))
        np.testing.assert_allclose(XYZ_to_linear_srgb(linear_srgb_to_XYZ(rgb)), rgb, atol=1e-12)

    def test_close_to_colour_nominal_srgb(self):
        XYZ = np.random.default_rng(5).random((10, 3)) * 0.9
        expected = colour.XYZ_to_RGB(XYZ, "sRGB", apply_cctf_encoding=False)
        np.testing.assert_allclose(XYZ_to_linear_srgb(XYZ), expected, atol=2e-3)

    def test_consistent_with_xyz_path(self):
        R = np.random.default_rng(6).random((3, 41))
        np.testing.assert_allclose(
            reflectance_to_linear_srgb(R, WAVELENGTHS),
            XYZ_to_linear_srgb(reflectance_to_XYZ(R, WAVELENGTHS)),
            atol=1e-12,
        )

    def test_transfer_function(self):
        np.testing.assert_allclose(srgb_encode([0.0, 0.0031308, 0.5, 1.0]),
                                   [0.0, 0.04045, 0.735357, 1.0], atol=1e-5)
        np.testing.assert_allclose(srgb_decode(0.5), 0.214041, atol=1e-6)
        v = np.linspace(0.0, 1.0, 101)
        np.testing.assert_allclose(srgb_decode(srgb_encode(v)), v, atol=1e-12)

    def test_both_segments_of_iec_61966_2_1(self):
        # Linear below the thresholds (also for negative values), a 2.4 power above.
        low = np.array([-0.2, -0.001, 0.001, 0.003])
        np.testing.assert_allclose(srgb_encode(low), 12.92 * low, rtol=1e-12)
        np.testing.assert_allclose(srgb_decode(12.92 * low), low, rtol=1e-12)
        high = np.array([0.01, 0.2, 0.9, 1.5])
        np.testing.assert_allclose(srgb_encode(high), 1.055 * high ** (1 / 2.4) - 0.055,
                                   rtol=1e-12)
        np.testing.assert_allclose(srgb_decode(srgb_encode(high)), high, rtol=1e-12)

    def test_keeps_the_shape_and_maps_each_value(self):
        v = np.random.default_rng(8).random((3, 4, 3)).astype(np.float32)
        np.testing.assert_array_equal(srgb_encode(v),
                                      np.vectorize(lambda x: float(srgb_encode(x)))(v))
        np.testing.assert_array_equal(srgb_decode(v),
                                      np.vectorize(lambda x: float(srgb_decode(x)))(v))


class TestDeltaE:
    def test_ab(self):
        assert delta_E_ab([50.0, 3.0, 4.0], [50.0, 0.0, 0.0]) == pytest.approx(5.0)
        assert delta_E_ab([10.0, -1.0, 2.0], [12.0, 0.0, 0.0]) == pytest.approx(3.0)

    def test_ab_broadcasts_pair_by_pair(self):
        a = np.random.default_rng(9).normal(50, 20, (2, 7, 3))
        b = np.array([[40.0, 5.0, -3.0]])
        expected = [[np.sqrt(np.sum((a[i, j] - b[0]) ** 2)) for j in range(7)] for i in range(2)]
        np.testing.assert_allclose(delta_E_ab(a, b), expected, rtol=1e-12)

    def test_2000_sharma_2005(self):
        # Sharma, Wu and Dalal (2005), Table 1, pairs 1, 7, 17, 25, 29, 32, 33.
        pairs = np.array([
            [[50.0000, 2.6772, -79.7751], [50.0000, 0.0000, -82.7485]],
            [[50.0000, 0.0000, 0.0000], [50.0000, -1.0000, 2.0000]],
            [[50.0000, 2.5000, 0.0000], [73.0000, 25.0000, -18.0000]],
            [[60.2574, -34.0099, 36.2677], [60.4626, -34.1751, 39.4387]],
            [[90.8027, -2.0831, 1.4410], [91.1528, -1.6435, 0.0447]],
            [[6.7747, -0.2908, -2.4247], [5.8714, -0.0985, -2.2286]],
            [[2.0776, 0.0795, -1.1350], [0.9033, -0.0636, -0.5514]],
        ])
        expected = [2.0425, 2.3669, 27.1492, 1.2644, 1.4441, 0.6377, 0.9082]
        np.testing.assert_allclose(delta_E_2000(pairs[:, 0], pairs[:, 1]), expected, atol=1e-4)

    def test_2000_broadcasts_pair_by_pair(self):
        a = np.random.default_rng(10).normal([50, 0, 0], [20, 30, 30], (4, 2, 3))
        b = np.array([55.0, 10.0, -20.0])
        expected = [[delta_E_2000(a[i, j], b) for j in range(2)] for i in range(4)]
        np.testing.assert_allclose(delta_E_2000(a, b), expected, rtol=1e-12)
        assert np.ptp(delta_E_2000(a, b)) > 1.0


class TestRmsDeltaR:
    def test_value(self):
        assert rms_delta_R(np.full(41, 0.5), np.full(41, 0.4)) == pytest.approx(0.1)
        assert rms_delta_R([0.0, 0.0], [0.3, 0.4]) == pytest.approx(np.sqrt(0.125))

    def test_broadcasting(self):
        R = np.random.default_rng(7).random((2, 3, 41))
        out = rms_delta_R(R, R[0])
        expected = [[np.sqrt(np.mean((R[i, j] - R[0, j]) ** 2)) for j in range(3)]
                    for i in range(2)]
        np.testing.assert_allclose(out, expected, rtol=1e-12)
        assert np.all(out[1] > 0.1)


def test_colour_science_without_matplotlib_says_nothing():
    """In Blender matplotlib is missing (the extension does not ship it) and
    colour-science warns about it on import: LightFade silences that one line."""
    import subprocess
    import sys
    from pathlib import Path

    code = ("import sys, warnings; sys.modules['matplotlib'] = None; "
            "warnings.simplefilter('always'); "
            "from lightfade_addon.core.colour.colorimetry import white_XYZ; white_XYZ()")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=Path(__file__).resolve().parents[2], timeout=120)
    assert run.returncode == 0, run.stderr
    assert "Matplotlib" not in run.stderr
