"""The O(N) layered flux solver against the paper's Figure 3 system and physics."""

import numpy as np
import pytest

from lightfade_addon.core.fading.flux import (
    boundary_fluxes,
    boundary_fluxes_dense,
    stack_reflectance,
)
from lightfade_addon.core.fading.kubelka import kubelka_layer, over_ground


def random_stack(rng, N, shape=()):
    K = rng.uniform(0, 5, shape + (N,))
    S = rng.uniform(0, 3, shape + (N,))
    return kubelka_layer(K, S, rng.uniform(0.05, 0.5, shape + (N,)))


class TestBoundaryFluxes:
    @pytest.mark.parametrize("N", [1, 2, 3, 8, 33])
    def test_equals_dense_solve_of_figure_3(self, N):
        rng = np.random.default_rng(N)
        for _ in range(5):
            rho, tau = random_stack(rng, N)
            ground = rng.uniform(0, 1)
            E0 = rng.uniform(0.5, 2)
            Ed, Eu = boundary_fluxes(rho[:, None], tau[:, None], [ground], E0)
            Ed_ref, Eu_ref = boundary_fluxes_dense(rho, tau, ground, E0)
            np.testing.assert_allclose(Ed[:, 0], Ed_ref, rtol=1e-12, atol=1e-14)
            np.testing.assert_allclose(Eu[:, 0], Eu_ref, rtol=1e-12, atol=1e-14)

    def test_satisfies_equations_1_and_2(self):
        rng = np.random.default_rng(3)
        rho, tau = random_stack(rng, 12, (4,))
        rho, tau = rho[..., None], tau[..., None]          # (4 samples, 12 layers, 1 wavelength)
        Ed, Eu = boundary_fluxes(rho, tau, np.full((4, 1), 0.7))
        r, t = rho[..., 0], tau[..., 0]
        np.testing.assert_allclose(Eu[:, :-1, 0], r * Ed[:, :-1, 0] + t * Eu[:, 1:, 0], atol=1e-14)
        np.testing.assert_allclose(Ed[:, 1:, 0], t * Ed[:, :-1, 0] + r * Eu[:, 1:, 0], atol=1e-14)
        np.testing.assert_allclose(Eu[:, -1, 0], 0.7 * Ed[:, -1, 0], atol=1e-14)
        np.testing.assert_allclose(Ed[:, 0, 0], 1.0)

    def test_energy_conservation_with_black_ground(self):
        """Reflected + absorbed + transmitted = incident, each layer absorbing
        (1 - rho - tau) of the flux entering it from both sides."""
        rng = np.random.default_rng(4)
        K = rng.uniform(0, 4, (6, 20, 3))
        S = rng.uniform(0, 2, (6, 20, 3))
        rho, tau = kubelka_layer(K, S, 0.05)
        E0 = rng.uniform(0.5, 3, (6, 3))
        Ed, Eu = boundary_fluxes(rho, tau, 0.0, E0)
        absorbed = ((1 - rho - tau) * (Ed[:, :-1] + Eu[:, 1:])).sum(axis=1)
        reflected, transmitted = Eu[:, 0], Ed[:, -1]
        np.testing.assert_allclose(reflected + absorbed + transmitted, E0, rtol=1e-12)

    def test_homogeneous_layer_split_into_n_layers(self):
        """N layers of thickness d/N have the reflectance and transmittance of one layer."""
        K, S, d = np.array([0.3, 2.0, 7.0]), np.array([1.5, 0.4, 0.05]), 0.9
        rho1, tau1 = kubelka_layer(K, S, d)
        for N in (2, 7, 64, 1024):
            rho, tau = kubelka_layer(K, S, d / N)
            rho_n = np.broadcast_to(rho, (N, 3))
            tau_n = np.broadcast_to(tau, (N, 3))
            Ed, Eu = boundary_fluxes(rho_n, tau_n, 0.0)
            np.testing.assert_allclose(Eu[0], rho1, rtol=1e-10)
            np.testing.assert_allclose(Ed[-1], tau1, rtol=1e-10)

    def test_single_layer_over_ground(self):
        rho, tau = kubelka_layer(np.array([[1.0, 0.2]]), np.array([[0.5, 3.0]]), 1.0)
        R = stack_reflectance(rho, tau, [0.2, 0.9])
        np.testing.assert_allclose(R, over_ground(rho[0], tau[0], np.array([0.2, 0.9])))

    def test_thick_stack_stays_finite(self):
        rho, tau = kubelka_layer(np.full((2000, 1), 50.0), np.full((2000, 1), 1.0), 1.0)
        Ed, Eu = boundary_fluxes(rho, tau, [0.9])
        assert np.all(np.isfinite(Ed)) and np.all(np.isfinite(Eu))
        assert Ed[-1, 0] == 0.0

    def test_batch_shapes(self):
        rng = np.random.default_rng(5)
        rho, tau = random_stack(rng, 5, (2, 3, 4))      # (..., W=5) used as (2,3,N=4,W=5)
        Ed, Eu = boundary_fluxes(rho, tau, np.full(5, 0.5))
        assert Ed.shape == Eu.shape == (2, 3, 5, 5)
        # each column equals its own solve
        Ed11, _ = boundary_fluxes(rho[1, 2][:, 3:4], tau[1, 2][:, 3:4], [0.5])
        np.testing.assert_allclose(Ed[1, 2, :, 3], Ed11[:, 0], rtol=1e-14)
