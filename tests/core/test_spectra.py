"""Tests for lightfade_addon.core.fading.spectra: resampling, light presets, UV filter."""

import numpy as np
import pytest
from scipy.integrate import trapezoid as trapz

from lightfade_addon.core.fading.spectra import (
    LIGHTS,
    WAVELENGTHS,
    illuminance,
    light_spectrum,
    luminous_efficiency,
    resample,
    uv_filter_transmittance,
)

FINE = np.arange(300.0, 831.0)

# That these modules import without bpy: tests/test_package.py (one process for the package).


class TestWavelengths:
    def test_default_grid(self):
        assert WAVELENGTHS.shape == (41,)
        assert WAVELENGTHS[0] == 300.0 and WAVELENGTHS[-1] == 780.0
        np.testing.assert_allclose(np.diff(WAVELENGTHS), 12.0)

    def test_read_only(self):
        with pytest.raises(ValueError):
            WAVELENGTHS[0] = 1.0


class TestResample:
    def test_constant_is_preserved(self):
        out = resample([250.0, 900.0], [0.7, 0.7], WAVELENGTHS)
        np.testing.assert_allclose(out, 0.7, rtol=1e-12)

    def test_linear_is_exact_in_interior_bins(self):
        src = np.arange(300.0, 781.0, 5.0)
        out = resample(src, 2.0 * src + 1.0, WAVELENGTHS)
        np.testing.assert_allclose(out[1:-1], 2.0 * WAVELENGTHS[1:-1] + 1.0, rtol=1e-12)

    def test_integral_of_spiky_spectrum_is_preserved(self):
        # Narrow lines 1 nm wide that fall between target samples.
        src = np.arange(300.0, 780.5, 0.5)
        values = np.zeros_like(src)
        for line in (404.7, 435.8, 546.1, 577.0):
            values[np.abs(src - line) < 0.5] = 100.0
        exact = trapz(values, src)
        out = resample(src, values, WAVELENGTHS)
        np.testing.assert_allclose(trapz(out, WAVELENGTHS), exact, rtol=1e-12)

    def test_line_energy_lands_in_its_bin(self):
        # A triangle of area 12 nm x unit at 550 nm, inside the bin [546, 558] of 552.
        src = np.array([300.0, 549.0, 550.0, 551.0, 780.0])
        out = resample(src, [0.0, 0.0, 12.0, 0.0, 0.0], WAVELENGTHS)
        assert np.argmax(out) == np.argmin(np.abs(WAVELENGTHS - 550.0))
        np.testing.assert_allclose(out.max() * 12.0, 12.0, rtol=1e-12)
        assert np.count_nonzero(out) == 1

    def test_batch_axes(self):
        src = np.linspace(300.0, 780.0, 97)
        values = np.random.default_rng(0).random((2, 3, 97))
        out = resample(src, values, WAVELENGTHS)
        one_by_one = [[resample(src, v, WAVELENGTHS) for v in row] for row in values]
        np.testing.assert_allclose(out, one_by_one, rtol=1e-12)
        assert np.ptp(out[:, :, 20]) > 0.1                      # the rows really differ

    def test_outside_zero_and_edge(self):
        src, values = [400.0, 700.0], [2.0, 3.0]
        zero = resample(src, values, WAVELENGTHS, outside="zero")
        edge = resample(src, values, WAVELENGTHS, outside="edge")
        assert zero[0] == 0.0 and zero[-1] == 0.0
        assert edge[0] == 2.0 and edge[-1] == 3.0

    def test_bad_inputs(self):
        with pytest.raises(ValueError, match="strictly increasing"):
            resample([400.0, 400.0], [1.0, 1.0], WAVELENGTHS)
        with pytest.raises(ValueError, match="samples"):
            resample([400.0, 500.0], [1.0, 1.0, 1.0], WAVELENGTHS)
        with pytest.raises(ValueError, match="outside"):
            resample([400.0, 500.0], [1.0, 1.0], WAVELENGTHS, outside="clamp")


class TestLightSpectrum:
    @pytest.mark.parametrize("name", list(LIGHTS))
    @pytest.mark.parametrize("uv_filter", [False, True])
    def test_one_lux(self, name, uv_filter):
        E = light_spectrum(name, FINE, uv_filter=uv_filter)
        np.testing.assert_allclose(illuminance(E, FINE), 1.0, rtol=1e-4)
        E = light_spectrum(name, uv_filter=uv_filter)
        np.testing.assert_allclose(illuminance(E, WAVELENGTHS), 1.0, rtol=5e-3)

    @pytest.mark.parametrize("name", list(LIGHTS))
    def test_shape_and_sign(self, name):
        E = light_spectrum(name)
        assert E.shape == WAVELENGTHS.shape
        assert np.all(E >= 0.0) and E.max() > 0.0

    def test_daylight_keeps_its_uv(self):
        E = light_spectrum("daylight", FINE)
        uv = trapz(E[FINE < 380], FINE[FINE < 380])
        vis = trapz(E[FINE >= 380], FINE[FINE >= 380])
        # CIE D65 carries about 7 % of its 300-780 nm power below 380 nm.
        assert 0.03 < uv / vis < 0.1

    def test_window_glass_cuts_short_uv(self):
        E = light_spectrum("daylight-glass", FINE)
        assert np.all(E[FINE < 315] == 0.0)
        assert E[FINE == 360][0] > 0.0

    def test_uv_filter_removes_uv(self):
        E = light_spectrum("daylight", FINE, uv_filter=True)
        assert E[FINE < 380].max() < 1e-3 * E.max()
        assert trapz(E[FINE < 380], FINE[FINE < 380]) < 1e-4 * trapz(E, FINE)

    def test_incandescent_is_planckian_2856K(self):
        lam = np.array([400.0, 560.0, 700.0])
        E = light_spectrum("incandescent", np.arange(300.0, 831.0))
        ratio = E[lam.astype(int) - 300] / E[260]
        # CIE A tabulated values (CIE 15:2004), relative to 100 at 560 nm.
        np.testing.assert_allclose(ratio * 100.0, [14.708, 100.0, 198.261], rtol=1e-4)

    def test_lights_without_uv_data_are_zero_there(self):
        for name in ("fluorescent", "led"):
            E = light_spectrum(name, FINE)
            assert np.all(E[FINE < 380] == 0.0)

    def test_each_call_gets_its_own_array(self):
        E = light_spectrum("daylight")
        E *= 0.0                                                # the caller's to change
        assert light_spectrum("daylight").max() > 0.0

    def test_unknown_name_lists_valid_names(self):
        with pytest.raises(ValueError, match="daylight-glass"):
            light_spectrum("sodium")


class TestUvFilter:
    def test_edges(self):
        T = uv_filter_transmittance(np.array([380.0, 390.0, 400.0, 410.0, 420.0]))
        assert T[0] < 1e-4 and T[1] < 5e-3
        assert T[2] == pytest.approx(0.5)
        assert T[3] > 0.995 and T[4] > 0.9999

    def test_monotone_and_bounded(self):
        T = uv_filter_transmittance(FINE, cutoff=395.0, width=15.0)
        assert np.all(np.diff(T) >= 0) and T.min() >= 0 and T.max() <= 1

    def test_bad_width(self):
        with pytest.raises(ValueError):
            uv_filter_transmittance(FINE, width=0.0)


class TestIlluminance:
    def test_batch(self):
        E = np.stack([light_spectrum("daylight"), 2.0 * light_spectrum("led")])
        lux = illuminance(E[None], WAVELENGTHS)
        assert lux.shape == (1, 2)
        np.testing.assert_allclose(lux, [[1.0, 2.0]], rtol=5e-3)

    def test_photopic_peak(self):
        assert luminous_efficiency(555.0) == pytest.approx(1.0, abs=1e-4)
        assert luminous_efficiency(300.0) == 0.0
