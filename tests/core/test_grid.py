"""The mixture grid: axes, simplex lattice, accuracy against direct simulation, cache."""

import os
import sys
from dataclasses import replace
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    reflectance_to_XYZ,
)
from lightfade_addon.core.fading import cache
from lightfade_addon.core.fading.cache import load_or_build
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.fading.gridbuild import build_grid
from lightfade_addon.core.fading.gridfile import grid_from_bytes, grid_to_bytes
from lightfade_addon.core.aging.ager import TextureAger
from lightfade_addon.core.fading.lattice import (
    concentration_axis,
    dose_axis,
    dose_index,
    grid_max_dose,
    mix_lattice,
    simplex_interpolation,
)
from lightfade_addon.core.fading.lights import Light
from lightfade_addon.core.fading.recipes import RECIPES
from lightfade_addon.core.fading.spectra import WAVELENGTHS as LAM, light_spectrum
from lightfade_addon.core.fading.unmix import get_unmixer

PAPER = RECIPES["printed-paper"]
DAYLIGHT = light_spectrum("daylight-glass")[None]
HEAVY = 2000 * 8 * 365 * 20          # 20 years of 2000 lux, 8 h a day: a heavy fade


@pytest.fixture(scope="module")
def grid():
    return build_grid(PAPER, DAYLIGHT, HEAVY)


def log_initial(c, recipe=PAPER):
    return np.log(get_unmixer(recipe).XYZ(c))


def direct(c, doses, E=DAYLIGHT[0], recipe=PAPER):
    r = recipe.simulate(recipe.concentrations(c), E, max(doses), record=doses)
    return reflectance_to_XYZ(r.initial, LAM), reflectance_to_XYZ(r.history, LAM)


class TestAxes:
    def test_concentration_axis_is_denser_near_zero(self):
        a = concentration_axis(10, 1.6)
        assert a[0] == 0 and a[-1] == 1 and np.all(np.diff(np.diff(a)) > 0)

    def test_dose_axis(self):
        d = dose_axis(5, 64.0)
        np.testing.assert_allclose(d, [0, 1, 8, 27, 64])
        np.testing.assert_allclose(dose_index(d / 64.0, 5), [0, 1, 2, 3, 4])
        with pytest.raises(ValueError):
            dose_axis(5, 0.0)

    @pytest.mark.parametrize("dose", [0.2, 1.0, 1.0001, 3e6, 5.88e9, 5.985e9, 2.0 ** 30])
    def test_grid_dose_is_the_next_quarter_octave(self, dose):
        top = grid_max_dose(dose)
        rung = 4 * np.log2(top)
        assert rung == pytest.approx(round(rung), abs=1e-9)
        assert max(dose, 1.0) <= top * (1 + 1e-9) and top < max(dose, 1.0) * 2 ** 0.25

    def test_textures_of_nearly_the_same_peak_dose_share_a_grid(self):
        """Brightest texels within a quarter octave: one grid; twice the dose: another."""
        rgb = np.full((2, 2, 3), 0.5)
        coarse = GridSettings(points=3, doses=5)

        def key(peak):
            exposure = np.array([[peak, 0.5], [0.1, 0.0]])
            return TextureAger(rgb, PAPER, [Light(lux=1000.0)], exposure, settings=coarse,
                               cache=False).grid.key

        assert key(0.8) == key(0.82)         # 234 and 239 Mlx·h in 100 years: rung 2**28
        assert key(0.8) != key(1.6)

    @pytest.mark.parametrize("S, q, count", [(1, 4, 1), (2, 4, 5), (3, 2, 6), (3, 4, 15)])
    def test_mix_lattice(self, S, q, count):
        L = mix_lattice(S, q)
        assert L.shape == (count, S)
        np.testing.assert_allclose(L.sum(axis=1), 1.0)

    @pytest.mark.parametrize("S, q", [(2, 2), (3, 4), (4, 3)])
    def test_simplex_interpolation_reproduces_the_weights(self, S, q):
        w = np.random.default_rng(S).dirichlet(np.ones(S), 500)
        w[:3] = mix_lattice(S, q)[:3]                      # exactly on nodes too
        nodes, bary = simplex_interpolation(w, q)
        assert np.all(bary >= -1e-12)
        np.testing.assert_allclose(bary.sum(axis=1), 1.0)
        np.testing.assert_allclose((bary[..., None] * mix_lattice(S, q)[nodes]).sum(1), w,
                                   atol=1e-12)


class TestAccuracy:
    def test_no_change_at_zero_dose(self, grid):
        assert np.all(grid.change[:, 0] == 0)
        c = np.random.default_rng(0).uniform(0, 1, (20, 3))
        np.testing.assert_array_equal(grid.log_change(c, np.zeros(20)), 0.0)

    def test_exact_at_the_nodes(self, grid):
        c = np.array([[grid.axes[0][3], grid.axes[1][7], grid.axes[2][0]]])
        X0, X = direct(c, grid.doses[1:])              # the grid's own time steps
        d = grid.doses[[5, 20]]
        np.testing.assert_allclose(grid.log_change(np.repeat(c, 2, 0), d),
                                   np.log(X[[4, 19], 0] / X0[0]), atol=1e-5)

    def test_held_out_mixtures_within_one_delta_e00(self, grid):
        c = np.random.default_rng(11).uniform(0, 1, (120, 3))
        doses = np.array([0.05, 0.37, 0.81]) * HEAVY
        X0, X = direct(c, doses)
        for k, d in enumerate(doses):
            aged = X0 * np.exp(grid.log_change(c, np.full(len(c), d), initial=log_initial(c)))
            err = delta_E_2000(XYZ_to_Lab(aged), XYZ_to_Lab(X[k]))
            assert err.max() < 1.0, (d, err.max())
        fade = delta_E_2000(XYZ_to_Lab(X0), XYZ_to_Lab(X[-1]))
        assert fade.mean() > 15                          # the test is of a heavy fade

    def test_mixed_spectra_within_one_delta_e00(self):
        """The light-mix axis at its shipped resolution (q = 4: max ΔE00 0.22 here; q = 2
        gives 0.91, q = 1 gives 3.3); 6 concentration nodes (10 are tested above) build
        it in a third of the time."""
        E = np.stack([light_spectrum("daylight-glass"), light_spectrum("incandescent")])
        g = build_grid(PAPER, E, HEAVY, GridSettings(points=6))
        c = np.random.default_rng(3).uniform(0, 1, (60, 3))
        for w in (0.2, 0.5, 0.9):
            X0, X = direct(c, [0.6 * HEAVY], E=(1 - w) * E[0] + w * E[1])
            mix = np.tile([1 - w, w], (len(c), 1))
            aged = X0 * np.exp(g.log_change(c, np.full(len(c), 0.6 * HEAVY), mix,
                                            initial=log_initial(c)))
            assert delta_E_2000(XYZ_to_Lab(aged), XYZ_to_Lab(X[0])).max() < 1.0

    def test_recipe_without_unmixed_colourants(self):
        wood = replace(RECIPES["bare-wood"], name="lignin-only", unmixed=(),
                       colourants=("lignin", "quinone"), blue_wool=(1.0, None))
        g = build_grid(wood, light_spectrum("daylight")[None], 5e6, GridSettings(doses=9))
        assert g.axes == [] and g.change.shape == (1, 9, 3)
        lc = g.log_change(np.zeros((2, 0)), [0.0, 5e6])
        assert np.all(lc[0] == 0) and lc[1, 2] < lc[1, 1]   # blue drops most: yellowing


class TestSerialisation:
    def test_bytes_round_trip(self, grid):
        g2 = grid_from_bytes(grid_to_bytes(grid))
        assert g2.key == grid.key
        np.testing.assert_array_equal(g2.change, grid.change)
        np.testing.assert_array_equal(g2.doses, grid.doses)

    @pytest.mark.parametrize("damage", ["truncate", "flip"])
    def test_corrupt_bytes_are_detected(self, grid, damage):
        data = bytearray(grid_to_bytes(grid))
        if damage == "truncate":
            data = data[: len(data) // 2]
        else:
            data[len(data) // 2] ^= 0xFF
        with pytest.raises(ValueError):
            grid_from_bytes(bytes(data))


class TestCache:
    def test_second_call_loads_and_corrupt_file_is_rebuilt(self, tmp_path, monkeypatch):
        monkeypatch.setenv("LIGHTFADE_CACHE", str(tmp_path))
        settings = GridSettings(points=3, doses=5)
        g1 = load_or_build(PAPER, DAYLIGHT, 1e6, settings)
        files = list(tmp_path.glob("grid-*.npz"))
        assert len(files) == 1 and cache.directory() == tmp_path
        mtime = files[0].stat().st_mtime_ns
        g2 = load_or_build(PAPER, DAYLIGHT, 1e6, settings)
        assert files[0].stat().st_mtime_ns == mtime          # loaded, not rebuilt
        np.testing.assert_array_equal(g1.change, g2.change)
        files[0].write_bytes(files[0].read_bytes()[:100])    # a partial file
        g3 = load_or_build(PAPER, DAYLIGHT, 1e6, settings)
        np.testing.assert_array_equal(g1.change, g3.change)
        grid_from_bytes(files[0].read_bytes())           # valid again

    def test_two_processes_building_the_same_grid(self, early):
        codes, files, leftovers = early("two processes build one grid")
        assert codes == [0, 0]
        assert len(files) == 1 and not leftovers
        grid_from_bytes(files[0].read_bytes())


def two_processes_build_one_grid(jobs, folder):
    """Two processes build the same grid into one cache folder at the same time.  An
    early job (tests/conftest.py): it runs beside the tests before this one."""
    code = ("from lightfade_addon.core.fading.cache import load_or_build;"
            "from lightfade_addon.core.fading.grid import GridSettings;"
            "from lightfade_addon.core.fading.recipes import RECIPES;"
            "from lightfade_addon.core.fading.spectra import light_spectrum;"
            "load_or_build(RECIPES['printed-paper'], light_spectrum('daylight')[None], 2e6,"
            " GridSettings(points=4, doses=9))")
    env = dict(os.environ, LIGHTFADE_CACHE=str(folder))
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with ThreadPoolExecutor(2) as pool:
        procs = list(pool.map(lambda _: jobs.run([sys.executable, "-c", code], cwd=root, env=env,
                                                 timeout=300), range(2)))
    for proc in procs:
        assert proc.returncode == 0, proc.stderr[-2000:]
    return ([p.returncode for p in procs], list(folder.glob("grid-*.npz")),
            list(folder.glob(".grid-*")))


EARLY = {"two processes build one grid": two_processes_build_one_grid}


def test_store_is_used_before_building(tmp_path, monkeypatch):
    monkeypatch.setenv("LIGHTFADE_CACHE", str(tmp_path))
    store = {}
    settings = GridSettings(points=3, doses=5)
    g = load_or_build(PAPER, DAYLIGHT, 3e6, settings, cache=False, store=store)
    assert list(store) == [g.key]
    from lightfade_addon.core.fading import gridbuild

    monkeypatch.setattr(gridbuild, "build_grid", lambda *a, **k: pytest.fail("rebuilt"))
    g2 = load_or_build(PAPER, DAYLIGHT, 3e6, settings, cache=False, store=store)
    np.testing.assert_array_equal(g2.change, g.change)
