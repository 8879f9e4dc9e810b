"""Recipes and the Blue Wool calibration."""

from dataclasses import replace

import numpy as np
import pytest

from lightfade_addon.core.colorimetry import delta_E_ab, reflectance_to_Lab
from lightfade_addon.core.spectra import WAVELENGTHS, light_spectrum
from lightfade_addon.core.recipes import (
    JND_DELTA_E, RECIPES, _calibration_fade, blue_wool_dose, get_recipe)


class TestBlueWoolDose:
    def test_class_1_and_geometric_steps(self):
        assert blue_wool_dose(1) == pytest.approx(0.4e6)
        assert blue_wool_dose(8) / blue_wool_dose(7) == pytest.approx(3.0)
        assert 800e6 < blue_wool_dose(8) < 900e6

    @pytest.mark.parametrize("bad", [0, 8.5, float("nan")])
    def test_out_of_range(self, bad):
        with pytest.raises(ValueError, match="Blue Wool"):
            blue_wool_dose(bad)


class TestCalibration:
    def test_calibrated_beta_gives_a_just_noticeable_fade_at_the_class_dose(self):
        r = RECIPES["printed-paper"]
        beta = r.sensitivity()
        for j, k in enumerate(r.blue_wool):
            fade = _calibration_fade(r, j, beta[j], blue_wool_dose(k), WAVELENGTHS)
            assert fade == pytest.approx(JND_DELTA_E, rel=1e-6)

    def test_a_full_strength_dye_alone_fades_just_noticeably_at_its_class_dose(self):
        """The calibration's definition, run through the recipe's own simulation: magenta
        alone at full concentration on paper, under UV-filtered daylight."""
        r = RECIPES["printed-paper"]
        j = r.index("magenta")
        c, beta = np.zeros(3), np.zeros(3)
        c[j], beta[j] = 1.0, r.sensitivity()[j]
        light = light_spectrum("daylight", WAVELENGTHS, uv_filter=True)
        run = r.simulate(c, light, blue_wool_dose(r.blue_wool[j]), sensitivity=beta)
        fade = delta_E_ab(reflectance_to_Lab(run.initial, WAVELENGTHS),
                          reflectance_to_Lab(run.reflectance, WAVELENGTHS))
        assert fade == pytest.approx(JND_DELTA_E, rel=1e-6)

    def test_higher_class_is_less_sensitive(self):
        r = RECIPES["dyed-fabric"]
        b3 = r.with_blue_wool(3).sensitivity()
        b5 = r.with_blue_wool(5).sensitivity()
        assert np.all(b5 < b3)

    def test_magenta_is_the_weakest_dye_of_a_print(self):
        beta = RECIPES["printed-paper"].sensitivity()
        assert np.argmax(beta) == RECIPES["printed-paper"].index("magenta")

    def test_with_blue_wool_keeps_class_differences(self):
        r = RECIPES["printed-paper"].with_blue_wool(1)
        assert r.blue_wool == (3.0, 1.0, 2.0)

    def test_with_blue_wool_clips_classes_to_1_8(self):
        r = RECIPES["printed-paper"].with_blue_wool(8)     # (4, 2, 3) shifted by 6
        assert r.blue_wool == (8.0, 8.0, 8.0)

    def test_first_order_is_the_default_and_recalibrated(self):
        r = RECIPES["printed-paper"]
        assert r.kinetics == "first-order" and r.solver()["kinetics"] == "first-order"
        paper = replace(r, kinetics="paper")
        b1, b2 = r.sensitivity(), paper.sensitivity()
        assert not np.allclose(b1, b2)                  # each law calibrated on its own
        for recipe, beta in ((r, b1), (paper, b2)):
            for j, k in enumerate(recipe.blue_wool):
                fade = _calibration_fade(recipe, j, beta[j], blue_wool_dose(k), WAVELENGTHS)
                assert fade == pytest.approx(JND_DELTA_E, rel=1e-6)

    def test_unknown_kinetics_is_refused(self):
        with pytest.raises(ValueError, match="kinetics"):
            replace(RECIPES["printed-paper"], kinetics="zeroth")

    def test_lignin_yellowing_is_driven_by_uv(self):
        with_uv = RECIPES["bare-wood"].sensitivity()[0]
        without_uv = replace(RECIPES["bare-wood"], calibration_uv_filter=True).sensitivity()[0]
        assert without_uv > 3 * with_uv        # behind a UV filter it needs far more beta

    def test_a_colourant_that_cannot_fade_is_refused(self, monkeypatch):
        from lightfade_addon.core import recipes

        monkeypatch.setattr(recipes, "_calibration_fade", lambda *a: 0.0)
        r = replace(RECIPES["printed-paper"], name="inert-test")
        with pytest.raises(ValueError, match="does not fade"):
            r.sensitivity()

    def test_bare_wood_yellows(self):
        r = RECIPES["bare-wood"]
        beta = r.sensitivity()
        assert beta[r.index("lignin")] > 0 and beta[r.index("quinone")] == 0

    def test_with_beta_scales_all_colourants(self):
        r = RECIPES["printed-paper"]
        b = r.sensitivity()
        b2 = r.with_beta(2 * b.max()).sensitivity()
        np.testing.assert_allclose(b2, 2 * b)


def test_unknown_recipe_lists_the_valid_ones():
    with pytest.raises(ValueError, match="printed-paper"):
        get_recipe("velvet")
