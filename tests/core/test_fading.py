"""simulate(): the paper's time stepping (equations 3-5) and its invariants."""

import numpy as np
import pytest
from scipy.integrate import trapezoid

from lightfade_addon.core import boundary_fluxes, kubelka_layer, over_ground, simulate
from lightfade_addon.core.fading.layered import LayeredStack, trapezoid_weights

from .conftest import run

MIX = np.array([[0.6, 0.3, 0.5], [0.1, 0.9, 0.2], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])


class TestInitialState:
    def test_single_layer_is_kubelka_over_ground(self, toy):
        c = np.array([0.4, 0.2, 0.7])
        r = run(toy, c, layers=1, steps=1, duration=0.0, thickness=0.8)
        K = c @ toy["absorption"]
        S = c @ toy["scattering"]
        expected = over_ground(*kubelka_layer(K, S, 0.8), toy["substrate"])
        np.testing.assert_allclose(r.initial, expected, rtol=1e-12)

    def test_layer_count_does_not_change_the_unexposed_reflectance(self, toy):
        one = run(toy, MIX, layers=1, steps=1, duration=0.0)
        many = run(toy, MIX, layers=37, steps=1, duration=0.0)
        np.testing.assert_allclose(many.initial, one.initial, rtol=1e-10)

    def test_empty_medium_shows_the_substrate(self, toy):
        r = run(toy, [0.0, 0.0, 0.0], layers=4, steps=2)
        np.testing.assert_allclose(r.initial, toy["substrate"], rtol=1e-14)
        np.testing.assert_allclose(r.reflectance, toy["substrate"], rtol=1e-14)


class TestInvariants:
    def test_zero_sensitivity_changes_nothing(self, toy):
        r = run(toy, MIX, sensitivity=np.zeros(3), layers=8, steps=5, duration=50.0)
        np.testing.assert_array_equal(r.reflectance, r.initial)
        np.testing.assert_array_equal(r.fractions, np.broadcast_to(MIX[:, None, :], (4, 8, 3)))

    @pytest.mark.parametrize("scheme", ["paper", "heun"])
    def test_reciprocity(self, toy, scheme):
        a = run(toy, MIX, duration=40.0, layers=8, steps=6, scheme=scheme)
        b = run(toy, MIX, duration=20.0, irradiance=2 * toy["irradiance"], layers=8, steps=6,
                scheme=scheme)
        np.testing.assert_allclose(b.reflectance, a.reflectance, rtol=1e-12)
        np.testing.assert_allclose(b.fractions, a.fractions, rtol=1e-12)

    def test_fading_is_monotone_in_dose(self, toy):
        times = np.linspace(5, 100, 20)
        r = run(toy, MIX[:3], duration=100.0, layers=8, steps=20, record=times)
        # every later state has less of every colourant; reflectance rises at every
        # wavelength where the dyes absorb (the ground is whiter than the dyes)
        assert np.all(np.diff(r.history, axis=0) >= -1e-15)
        assert np.all(r.reflectance - r.initial > -1e-15)
        assert np.all(r.fractions <= MIX[:3, None, :])
        assert np.any(r.reflectance - r.initial > 0.05)

    def test_top_layer_fades_most(self, toy):
        r = run(toy, [0.8, 0.8, 0.8], duration=60.0, layers=16, steps=10)
        cyan = r.fractions[:, 0]
        assert np.argmin(cyan) == 0
        assert np.all(np.diff(cyan[:8]) > 0)   # deeper is shielded (the white ground
        # reflects light back into the lowest layers, so the bottom is not the maximum)

    def test_threads_do_not_change_the_result(self, toy):
        rng = np.random.default_rng(0)
        c = rng.uniform(0, 1, (300, 3))
        a = run(toy, c, duration=30.0, layers=6, steps=4, workers=1)
        b = run(toy, c, duration=30.0, layers=6, steps=4, workers=3)
        np.testing.assert_array_equal(a.reflectance, b.reflectance)

    def test_batch_shape_is_tiled(self, toy):
        c = np.broadcast_to(MIX[1], (2, 3, 3))
        r = run(toy, c, duration=30.0, layers=5, steps=3)
        assert r.initial.shape == r.reflectance.shape == (2, 3, 41)
        assert r.fractions.shape == (2, 3, 5, 3)
        single = run(toy, MIX[1], duration=30.0, layers=5, steps=3)
        assert single.reflectance.shape == (41,)
        np.testing.assert_allclose(r.reflectance[1, 2], single.reflectance, rtol=1e-14)


class TestEquation3:
    @pytest.mark.parametrize("kinetics", ["paper", "first-order"])
    def test_one_layer_one_step_by_hand(self, toy, kinetics):
        """f(dt) = f exp(-dt beta trapz(mu_a F)) with F the layer's mean fluence and
        mu_a = f A (paper: equation 3 as printed) or A (first order)."""
        c = np.array([0.3, 0.5, 0.2])
        dt = 7.0
        r = run(toy, c, layers=1, steps=1, duration=dt, scheme="paper", kinetics=kinetics)
        K = c @ toy["absorption"]
        S = c @ toy["scattering"]
        rho, tau = kubelka_layer(K, S, 1.0)
        Ed, Eu = boundary_fluxes(rho[None], tau[None], toy["substrate"], toy["irradiance"])
        F = 0.5 * ((Ed + Eu)[0] + (Ed + Eu)[1])
        mu_a = (c[:, None] if kinetics == "paper" else 1.0) * toy["absorption"]
        exponent = dt * toy["sensitivity"] * trapezoid(mu_a * F, toy["wavelengths"], axis=1)
        np.testing.assert_allclose(r.fractions[0], c * np.exp(-exponent), rtol=1e-12)

    def test_shared_by_hand(self, toy):
        """Shared: every colourant's exponent is its beta times the layer's absorbed light
        per unit of colourant, sum_i f_i trapz(A_i F) / sum_i f_i."""
        c = np.array([0.3, 0.5, 0.2])
        dt = 7.0
        r = run(toy, c, layers=1, steps=1, duration=dt, scheme="paper", kinetics="shared")
        rho, tau = kubelka_layer(c @ toy["absorption"], c @ toy["scattering"], 1.0)
        Ed, Eu = boundary_fluxes(rho[None], tau[None], toy["substrate"], toy["irradiance"])
        F = 0.5 * ((Ed + Eu)[0] + (Ed + Eu)[1])
        absorbed = trapezoid(toy["absorption"] * F, toy["wavelengths"], axis=1)
        exponent = dt * toy["sensitivity"] * (c @ absorbed) / c.sum()
        np.testing.assert_allclose(r.fractions[0], c * np.exp(-exponent), rtol=1e-12)

    def test_shared_matched_dyes_fade_together_and_one_dye_is_first_order(self, toy):
        """Equal betas lose the same fraction in every layer whatever the mixture (one
        shields the others); a colourant alone fades exactly as with first order."""
        same = dict(toy, sensitivity=np.full(3, 0.0005))
        c = np.array([[0.9, 0.1, 0.5], [0.05, 1.0, 0.2]])
        r = run(same, c, layers=4, steps=3, kinetics="shared")
        kept = r.fractions / c[:, None, :]
        np.testing.assert_allclose(kept, np.broadcast_to(kept[..., :1], kept.shape), rtol=1e-12)
        assert kept[0, 0, 0] < kept[0, -1, 0] - 0.01             # the top layer fades most
        first = run(same, c, layers=4, steps=3)
        assert np.ptp(first.fractions[0, -1] / c[0]) > 0.01     # first order: they drift
        alone = np.array([0.0, 0.7, 0.0])
        np.testing.assert_allclose(run(toy, alone, kinetics="shared").fractions,
                                   run(toy, alone).fractions, rtol=1e-12)
        white = run(toy, np.zeros(3), kinetics="shared")         # nothing to fade: no NaN
        assert np.all(np.isfinite(white.reflectance))

    def test_first_order_is_the_default_and_pale_tints_fade_at_the_same_rate(self, toy):
        """First order: in an optically thin layer (no shielding) the surviving fraction
        does not depend on the concentration; with the paper's law a pale tint keeps
        relatively more."""
        thin = dict(toy, absorption=toy["absorption"] * 1e-3, scattering=toy["scattering"] * 1e-3,
                    sensitivity=toy["sensitivity"] * 1e3)
        c = np.array([[0.9, 0.0, 0.0], [0.1, 0.0, 0.0]])
        first = run(thin, c, layers=1, steps=1, duration=0.2, scheme="paper")
        kept = first.fractions[:, 0, 0] / c[:, 0]
        assert 0.2 < kept[0] < 0.8
        np.testing.assert_allclose(kept[0], kept[1], rtol=1e-2)
        paper = run(thin, c, layers=1, steps=1, duration=0.2, scheme="paper", kinetics="paper")
        kept = paper.fractions[:, 0, 0] / c[:, 0]
        assert kept[1] > kept[0] + 0.05

    @pytest.mark.parametrize("kinetics", ["paper", "first-order"])
    def test_fused_stack_equals_plain_functions(self, toy, kinetics):
        rng = np.random.default_rng(2)
        N, B = 9, 5
        f = rng.uniform(0, 1, (N, B, 3))
        stack = LayeredStack(toy["absorption"], toy["scattering"], toy["sensitivity"],
                             toy["irradiance"], toy["substrate"], toy["wavelengths"], 1.3, N, B,
                             kinetics=kinetics)
        rate, R0 = stack.rates(f)
        K = f @ toy["absorption"]
        S = f @ toy["scattering"]
        rho, tau = kubelka_layer(K, S, 1.3 / N)                       # (N, B, W)
        Ed, Eu = boundary_fluxes(np.moveaxis(rho, 0, 1), np.moveaxis(tau, 0, 1),
                                 toy["substrate"], toy["irradiance"])
        F = Ed + Eu
        Fl = 0.5 * (F[:, :-1] + F[:, 1:])                             # (B, N, W)
        w = trapezoid_weights(toy["wavelengths"])
        per_unit = f if kinetics == "paper" else np.ones_like(f)
        expected = np.einsum("bnw,nbc,cw,w->nbc", Fl, per_unit, toy["absorption"], w)
        expected *= toy["sensitivity"]
        np.testing.assert_allclose(rate, expected, rtol=1e-11)
        np.testing.assert_allclose(R0, Eu[:, 0] / toy["irradiance"], rtol=1e-12)


class TestConvergence:
    #: a clear fade, in the asymptotic regime, for each rate law
    DURATION = {"paper": 20.0, "first-order": 2.0}

    @classmethod
    def errors(cls, toy, scheme, steps_list, kinetics):
        c = np.array([[0.7, 0.4, 0.6], [0.2, 0.9, 0.5]])
        kw = dict(duration=cls.DURATION[kinetics], layers=8, kinetics=kinetics)
        ref = run(toy, c, steps=2048, scheme="heun", **kw).reflectance
        assert np.abs(ref - run(toy, c, duration=0.0, layers=8).initial).max() > 0.05
        return np.array([np.abs(run(toy, c, steps=s, scheme=scheme, **kw).reflectance - ref).max()
                         for s in steps_list])

    @pytest.mark.parametrize("kinetics", ["paper", "first-order"])
    def test_paper_scheme_is_first_order(self, toy, kinetics):
        e = self.errors(toy, "paper", [16, 32, 64, 128], kinetics)
        ratios = e[:-1] / e[1:]
        assert np.all((ratios > 1.8) & (ratios < 2.3)), ratios

    @pytest.mark.parametrize("kinetics", ["paper", "first-order"])
    def test_heun_scheme_is_second_order(self, toy, kinetics):
        e = self.errors(toy, "heun", [16, 32, 64], kinetics)
        ratios = e[:-1] / e[1:]
        assert np.all((ratios > 3.4) & (ratios < 4.6)), ratios


class TestRecord:
    def test_history_matches_separate_runs(self, toy):
        r = run(toy, MIX[:2], duration=90.0, layers=6, steps=9, record=[30.0, 90.0])
        assert r.history.shape == (2, 2, 41)
        np.testing.assert_array_equal(r.history[1], r.reflectance)
        part = run(toy, MIX[:2], duration=30.0, layers=6, steps=3)
        np.testing.assert_allclose(r.history[0], part.reflectance, rtol=1e-12)

    def test_off_grid_record_time_becomes_a_step_boundary(self, toy):
        r = run(toy, MIX[0], duration=10.0, layers=4, steps=2, record=[3.0])
        np.testing.assert_allclose(r.times, [3.0])
        assert r.history.shape == (1, 41)
        assert np.all(r.history[0] <= r.reflectance + 1e-15)


class TestYields:
    def test_loss_is_transferred_with_the_yield(self, toy):
        yields = np.zeros((3, 3))
        yields[0, 2] = 1.0                      # "cyan" turns into "yellow" one for one
        beta = np.array([0.01, 0.0, 0.0])       # only the precursor reacts
        c = np.array([0.8, 0.0, 0.1])
        r = run(toy, c, sensitivity=beta, yields=yields, duration=80.0, layers=5, steps=8)
        f = r.fractions
        assert np.all(f[:, 0] < 0.8)
        np.testing.assert_allclose(f[:, 0] + f[:, 2], 0.9, rtol=1e-12)
        np.testing.assert_array_equal(f[:, 1], 0.0)


class TestValidation:
    @pytest.mark.parametrize("field, value, word", [
        ("absorption", -1.0, "absorption"),
        ("scattering", np.nan, "scattering"),
        ("substrate", 1.5, "substrate"),
        ("irradiance", -0.1, "irradiance"),
        ("sensitivity", np.inf, "sensitivity"),
    ])
    def test_bad_values_name_the_argument(self, toy, field, value, word):
        args = {k: np.array(v, dtype=float) for k, v in toy.items()}
        args[field].flat[2] = value
        with pytest.raises(ValueError, match=word):
            simulate(concentrations=[0.1, 0.2, 0.3], **args)

    @pytest.mark.parametrize("kw, word", [
        (dict(concentrations=[0.1, 1.2, 0.3]), "concentrations"),
        (dict(concentrations=[0.1, 0.2]), "concentrations"),
        (dict(concentrations=[0.1, np.nan, 0.2]), "concentrations"),
        (dict(layers=0), "layers"),
        (dict(steps=0), "steps"),
        (dict(steps=2.5), "steps"),
        (dict(scheme="rk4"), "scheme"),
        (dict(kinetics="second-order"), "kinetics"),
        (dict(thickness=0.0), "thickness"),
        (dict(duration=-1.0), "duration"),
        (dict(record=[2.0, 1.0]), "record"),
        (dict(record=[5.0], duration=1.0), "record"),
        (dict(yields=np.eye(3)), "yields"),
    ])
    def test_bad_arguments_name_themselves(self, toy, kw, word):
        args = dict(toy, concentrations=[0.1, 0.2, 0.3])
        args.update(kw)
        with pytest.raises(ValueError, match=word):
            simulate(**args)

    def test_shape_mismatch_and_wavelength_order(self, toy):
        args = dict(toy, concentrations=[0.1, 0.2, 0.3])
        with pytest.raises(ValueError, match="irradiance"):
            simulate(**dict(args, irradiance=np.ones(40)))
        with pytest.raises(ValueError, match="wavelengths"):
            simulate(**dict(args, wavelengths=toy["wavelengths"][::-1]))
        with pytest.raises(ValueError, match="absorption"):
            simulate(**dict(args, absorption=toy["absorption"][:, :40]))


class TestThinLayerSeries:
    def test_series_equals_closed_form_below_the_threshold(self):
        from lightfade_addon.core.fading.kubelka import kubelka_layer
        from lightfade_addon.core.fading.layered import THIN_LAYER_Y, kubelka_into

        rng = np.random.default_rng(9)
        Kd = np.concatenate([rng.uniform(0, 0.03, 4000), [0.0, 1e-12]])
        Sd = np.concatenate([rng.uniform(0, 0.01, 4000), [0.004, 0.0]])
        y = Kd * (Kd + 2 * Sd)
        keep = y <= THIN_LAYER_Y
        Kd, Sd = Kd[keep], Sd[keep]
        rho, tau, *scratch = (np.empty_like(Kd) for _ in range(5))
        kubelka_into(Kd, Sd, rho, tau, *scratch)
        rho_ref, tau_ref = kubelka_layer(Kd, Sd, 1.0)
        np.testing.assert_allclose(rho, rho_ref, rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(tau, tau_ref, rtol=1e-12)


class TestChunks:
    def test_few_layers_get_wide_chunks_and_the_result_does_not_depend_on_them(self):
        """A colour table's 729 samples of 3 layers are one chunk (fewer, longer numpy
        calls); 64 layers keep narrow ones; and the split never changes the result."""
        from lightfade_addon.core.fading import model

        assert model._chunks(729, 41, 1, layers=3) == [(0, 729)]
        assert len(model._chunks(729, 41, 1, layers=64)) == 5
        rng = np.random.default_rng(5)
        A, S = rng.uniform(0.1, 3.0, (2, 3, 41))
        c = rng.uniform(0.0, 1.0, (729, 3))
        lam = np.linspace(300.0, 780.0, 41)
        args = (A, S, c, [1.0, 0.5, 0.2], np.ones(41), np.full(41, 0.8), lam)
        wide = simulate(*args, duration=0.3, record=[0.1, 0.3], workers=1)
        saved = model._CHUNK_CELLS
        try:
            model._CHUNK_CELLS = 0                      # 5 chunks of 6144 columns
            narrow = simulate(*args, duration=0.3, record=[0.1, 0.3], workers=1)
        finally:
            model._CHUNK_CELLS = saved
        np.testing.assert_allclose(wide.history, narrow.history, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(wide.fractions, narrow.fractions, rtol=1e-13, atol=1e-15)


class TestSettled:
    def test_a_faded_chunk_stops_stepping_and_records_the_same(self, monkeypatch):
        """Once every fading colourant is gone (below SETTLED) the chunk stops: far
        fewer flux solves, the same records; a non-fading colourant fed by yields
        (bare wood's quinone) keeps its share."""
        from lightfade_addon.core.fading import model

        calls = [0]
        rates = LayeredStack.rates

        def counted(self, f):
            calls[0] += 1
            return rates(self, f)

        monkeypatch.setattr(LayeredStack, "rates", counted)
        rng = np.random.default_rng(6)
        A, S = rng.uniform(0.1, 3.0, (2, 3, 41))
        c = rng.uniform(0.0, 1.0, (40, 3))
        lam = np.linspace(300.0, 780.0, 41)
        yields = np.zeros((3, 3))
        yields[0, 2] = 0.3
        record = np.geomspace(1e-4, 1e2, 60)
        args = (A, S, c, [1.0, 0.5, 0.0], np.ones(41), np.full(41, 0.8), lam)
        kw = dict(duration=1e2, record=record, yields=yields, workers=1)
        early = simulate(*args, **kw)
        stopped, calls[0] = calls[0], 0
        monkeypatch.setattr(model, "SETTLED", 0.0)        # never settled: every step
        full = simulate(*args, **kw)
        assert stopped < 0.6 * calls[0]
        np.testing.assert_allclose(early.history, full.history, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(early.reflectance, full.reflectance, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(early.fractions, full.fractions, atol=1e-14)
        assert early.fractions[..., 2].min() > 0.1          # the product stays
