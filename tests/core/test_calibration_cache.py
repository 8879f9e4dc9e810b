"""The calibrated ``beta`` of a Blue Wool class is kept on disk: a new process reads it."""

import numpy as np
import pytest

from lightfade_addon.core.fading import cache, calibration
from lightfade_addon.core.fading.recipes import get_recipe
from lightfade_addon.core.fading.spectra import WAVELENGTHS


@pytest.fixture
def private_disk(tmp_path):
    """An empty cache folder and an empty in-memory cache, both restored afterwards."""
    cache.set_directory(tmp_path)
    calibration._beta_cached.cache_clear()
    yield tmp_path
    cache.set_directory(None)
    calibration._beta_cached.cache_clear()


def _beta(recipe, j, k):
    return calibration.beta_from_blue_wool(recipe, j, k, WAVELENGTHS)


def test_a_new_process_reads_the_solved_beta_from_disk(private_disk, monkeypatch):
    recipe = get_recipe("dyed-fabric")
    solved = _beta(recipe, 0, 4.0)
    assert len(list(private_disk.glob("beta-*.json"))) == 1
    calibration._beta_cached.cache_clear()                 # as in a new process

    def no_solve(*args):
        raise AssertionError("solved again although the disk held it")

    monkeypatch.setattr(calibration, "_solve_beta", no_solve)
    assert _beta(recipe, 0, 4.0) == solved                  # bit for bit


def test_another_class_or_recipe_is_not_a_stale_hit(private_disk):
    recipe = get_recipe("dyed-fabric")
    b4, b6 = _beta(recipe, 0, 4.0), _beta(recipe, 0, 6.0)
    assert b6 < b4 / 3                                      # two classes: 3x the dose each
    paper = _beta(get_recipe("printed-paper"), 0, 4.0)
    assert paper != b4
    assert len(list(private_disk.glob("beta-*.json"))) == 3


def test_a_corrupt_file_is_solved_again(private_disk):
    recipe = get_recipe("dyed-fabric")
    solved = _beta(recipe, 0, 4.0)
    (path,) = private_disk.glob("beta-*.json")
    path.write_text("{not json")
    calibration._beta_cached.cache_clear()
    assert _beta(recipe, 0, 4.0) == solved
    assert np.isfinite(calibration._load_beta(path))


def test_the_solve_simulates_each_trial_beta_once(private_disk, monkeypatch):
    """Brent's method starts at the bracket's ends, already simulated while bracketing:
    no trial beta is simulated twice; the secant steps bracket the root in a few."""
    real, trials = calibration._calibration_fade, []

    def counted(recipe, j, beta, dose, lam):
        trials.append(beta)
        return real(recipe, j, beta, dose, lam)

    monkeypatch.setattr(calibration, "_calibration_fade", counted)
    _beta(get_recipe("dyed-fabric"), 0, 4.0)
    assert 3 <= len(trials) <= 10 and len(set(trials)) == len(trials)


@pytest.mark.parametrize("name, j, blue_wool", [("dyed-fabric", 0, 4.0), ("bare-wood", 0, 1.0),
                                                 ("printed-paper", 2, 3.0)])
def test_the_secant_bracket_finds_the_stepped_brackets_root(private_disk, monkeypatch, name,
                                                             j, blue_wool):
    """The secant steps and the plain steps of 4 from log beta = -30 (the fallback)
    reach the same beta, and its fade is the JND; the secant in at most 10 simulations
    (Bare Wood's lignin converges from below: a step across brackets it)."""
    recipe, lam = get_recipe(name), np.asarray(calibration.WAVELENGTHS)
    real, trials = calibration._calibration_fade, []
    monkeypatch.setattr(calibration, "_calibration_fade",
                        lambda *a: trials.append(a[2]) or real(*a))
    fast = calibration._solve_beta(recipe, j, blue_wool, lam)
    assert len(trials) <= 10
    monkeypatch.setattr(calibration, "_SECANT_STEPS", 0)
    stepped = calibration._solve_beta(recipe, j, blue_wool, lam)
    assert np.log(fast) == pytest.approx(np.log(stepped), abs=1e-9)
    fade = calibration._calibration_fade(recipe, j, fast, calibration.blue_wool_dose(blue_wool), lam)
    assert fade == pytest.approx(calibration.JND_DELTA_E, rel=1e-9)
