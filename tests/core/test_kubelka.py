"""Kubelka's single-layer formulae: closed form, limits, energy."""

import numpy as np
import pytest

from lightfade_addon.core.fading.kubelka import (
    kubelka_layer,
    kubelka_layer_reference,
    over_ground,
)


class TestKubelkaLayer:
    def test_equals_printed_closed_form(self):
        rng = np.random.default_rng(0)
        K = rng.uniform(0.01, 10, 500)
        S = rng.uniform(0.01, 10, 500)
        d = rng.uniform(0.01, 2, 500)
        rho, tau = kubelka_layer(K, S, d)
        rho_ref, tau_ref = kubelka_layer_reference(K, S, d)
        np.testing.assert_allclose(rho, rho_ref, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(tau, tau_ref, rtol=1e-12, atol=1e-15)

    def test_pure_absorber_is_beer_lambert(self):
        K = np.array([0.0, 1e-6, 0.3, 5.0, 40.0])
        rho, tau = kubelka_layer(K, 0.0, 0.7)
        np.testing.assert_array_equal(rho, 0.0)
        np.testing.assert_allclose(tau, np.exp(-K * 0.7), rtol=1e-13)

    def test_pure_scatterer(self):
        S = np.array([1e-9, 0.2, 3.0, 1e4])
        rho, tau = kubelka_layer(0.0, S, 0.5)
        np.testing.assert_allclose(rho, S * 0.5 / (1 + S * 0.5), rtol=1e-12)
        np.testing.assert_allclose(tau, 1 / (1 + S * 0.5), rtol=1e-12)
        np.testing.assert_allclose(rho + tau, 1.0, rtol=1e-13)

    def test_continuous_across_small_absorption(self):
        S = 0.8
        K = np.geomspace(1e-14, 1e-2, 60)
        rho, tau = kubelka_layer(K, S, 1.0)
        assert np.all(np.diff(rho) < 0) and np.all(np.diff(tau) < 0)
        r0, t0 = kubelka_layer(0.0, S, 1.0)
        assert abs(rho[0] - r0) < 1e-12 and abs(tau[0] - t0) < 1e-12

    def test_optically_thick_is_finite_and_tends_to_r_infinity(self):
        K, S = 2.0, 3.0
        rho, tau = kubelka_layer(K, S, [1e3, 1e6])
        a = 1 + K / S
        r_inf = a - np.sqrt(a * a - 1)
        assert np.all(np.isfinite(rho)) and np.all(tau == 0.0)
        np.testing.assert_allclose(rho, r_inf, rtol=1e-12)

    def test_energy_bounds(self):
        rng = np.random.default_rng(1)
        K, S = rng.uniform(0, 20, (2, 1000))
        rho, tau = kubelka_layer(K, S, rng.uniform(0, 3, 1000))
        assert np.all(rho >= 0) and np.all(tau >= 0) and np.all(rho + tau <= 1 + 1e-15)

    def test_broadcasts(self):
        rho, tau = kubelka_layer(np.ones((4, 1, 3)), np.ones((5, 3)), 1.0)
        assert rho.shape == tau.shape == (4, 5, 3)


class TestOverGround:
    def test_black_ground_and_transparent_layer(self):
        assert over_ground(0.3, 0.5, 0.0) == pytest.approx(0.3)
        assert over_ground(0.0, 1.0, 0.6) == pytest.approx(0.6)
