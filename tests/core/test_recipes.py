"""Recipes and the Blue Wool calibration."""

from dataclasses import replace

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import delta_E_ab, reflectance_to_Lab
from lightfade_addon.core.fading.spectra import WAVELENGTHS, light_spectrum
from lightfade_addon.core.fading.calibration import (
    MATCHING_LIGHT,
    RATE_REFERENCE,
    _calibration_fade,
)
from lightfade_addon.core.fading.recipes import (
    JND_DELTA_E,
    RECIPES,
    Recipe,
    blue_wool_dose,
    fastness_text,
    get_recipe,
    matched_rates,
)


class TestBlueWoolDose:
    def test_class_1_and_geometric_steps(self):
        assert blue_wool_dose(1) == pytest.approx(0.4e6)
        assert blue_wool_dose(8) / blue_wool_dose(7) == pytest.approx(3.0)
        assert 800e6 < blue_wool_dose(8) < 900e6

    @pytest.mark.parametrize("bad", [0, 8.5, float("nan")])
    def test_out_of_range(self, bad):
        with pytest.raises(ValueError, match="Blue Wool"):
            blue_wool_dose(bad)


#: A recipe whose classes fix each colourant's own colour change (the "colour" rule).
OWN_COLOUR = replace(RECIPES["printed-paper"], name="own-colour", calibration="colour",
                     kinetics="first-order")


class TestCalibration:
    def test_calibrated_beta_gives_a_just_noticeable_fade_at_the_class_dose(self):
        r = OWN_COLOUR
        beta = r.sensitivity()
        for j, k in enumerate(r.blue_wool):
            fade = _calibration_fade(r, j, beta[j], blue_wool_dose(k), WAVELENGTHS)
            assert fade == pytest.approx(JND_DELTA_E, rel=1e-6)

    def test_a_full_strength_dye_alone_fades_just_noticeably_at_its_class_dose(self):
        """The calibration's definition, run through the recipe's own simulation: magenta
        alone at full concentration on paper, under UV-filtered daylight."""
        r = OWN_COLOUR
        j = r.index("magenta")
        c, beta = np.zeros(3), np.zeros(3)
        c[j], beta[j] = 1.0, r.sensitivity()[j]
        light = light_spectrum("daylight", WAVELENGTHS, uv_filter=True)
        run = r.simulate(c, light, blue_wool_dose(r.blue_wool[j]), sensitivity=beta)
        fade = delta_E_ab(reflectance_to_Lab(run.initial, WAVELENGTHS),
                          reflectance_to_Lab(run.reflectance, WAVELENGTHS))
        assert fade == pytest.approx(JND_DELTA_E, rel=1e-6)

    def test_the_reference_colourant_keeps_its_own_colour_calibration(self):
        r = RECIPES["dyed-fabric"]
        beta = r.sensitivity()
        fade = _calibration_fade(r, 0, beta[0], blue_wool_dose(r.blue_wool[0]), WAVELENGTHS)
        assert fade == pytest.approx(JND_DELTA_E, rel=1e-6)

    @pytest.mark.parametrize("kinetics", ["first-order", "shared"])
    def test_equal_classes_lose_equal_fractions_in_the_reference_neutral(self, kinetics):
        """The "rate" rule: colourants of one class fade together in a mid-dark neutral
        under daylight through glass (what makes a dyer's trichromat fade on tone)."""
        r = replace(RECIPES["dyed-fabric"], kinetics=kinetics)
        assert len(set(r.blue_wool)) == 1
        c = np.full(3, RATE_REFERENCE)
        run = r.simulate(c, light_spectrum(MATCHING_LIGHT[0], WAVELENGTHS, MATCHING_LIGHT[1]), 1e5)
        lost = 1.0 - run.fractions.mean(axis=0) / c
        np.testing.assert_allclose(lost, lost.mean(), rtol=0.02)

    def test_rate_rule_is_the_reference_class_times_the_rate_ratio(self):
        r = replace(RECIPES["dyed-fabric"], kinetics="first-order")
        rates = matched_rates(r)
        beta = r.sensitivity()
        assert not np.allclose(beta, beta[0])           # first-order: the bands differ
        np.testing.assert_allclose(beta * rates, beta[0] * rates[0], rtol=1e-9)

    def test_shared_kinetics_needs_one_beta_per_class(self):
        beta = RECIPES["dyed-fabric"].sensitivity()
        np.testing.assert_allclose(beta, beta[0], rtol=1e-9)

    def test_matched_classes_are_not_matched_under_the_colour_rule(self):
        """Without the rate rule, three dyes of one class fade at different rates in a
        neutral (each calibrated on its own colour change): what turned greys teal."""
        r = replace(RECIPES["dyed-fabric"], calibration="colour", kinetics="first-order")
        c = np.full(3, RATE_REFERENCE)
        light = light_spectrum(MATCHING_LIGHT[0], WAVELENGTHS, MATCHING_LIGHT[1])
        lost = 1.0 - r.simulate(c, light, 1e5).fractions.mean(axis=0) / c
        assert lost.max() / lost.min() > 1.15

    def test_higher_class_is_less_sensitive(self):
        r = RECIPES["dyed-fabric"]
        b3 = r.with_blue_wool(3).sensitivity()
        b5 = r.with_blue_wool(5).sensitivity()
        assert np.all(b5 < b3)

    def test_a_print_loses_yellow_then_magenta_then_cyan(self):
        r = RECIPES["printed-paper"]
        beta = r.sensitivity()
        assert beta[r.index("yellow")] > beta[r.index("magenta")] > 2 * beta[r.index("cyan")]

    def test_with_blue_wool_keeps_class_differences(self):
        r = RECIPES["printed-paper"].with_blue_wool(1)
        assert r.blue_wool == (3.0, 1.5, 1.0)

    def test_with_blue_wool_clips_classes_to_1_8(self):
        r = RECIPES["printed-paper"].with_blue_wool(8)     # (5, 3.5, 3) shifted by 5
        assert r.blue_wool == (8.0, 8.0, 8.0)

    def test_first_order_is_the_default_and_recalibrated(self):
        r = OWN_COLOUR
        assert Recipe.__dataclass_fields__["kinetics"].default == "first-order"
        assert r.solver()["kinetics"] == "first-order"
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
        from lightfade_addon.core.fading import calibration

        monkeypatch.setattr(calibration, "_calibration_fade", lambda *a: 0.0)
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


class TestWithClasses:
    def test_one_dye_made_fugitive(self):
        r = RECIPES["dyed-fabric"].with_classes({"yellow": 2})
        assert r.blue_wool == (4.0, 4.0, 2.0)
        beta = r.sensitivity()
        assert beta[2] > 5 * beta[0] and beta[0] == pytest.approx(beta[1])
        assert fastness_text(r) == "cyan 4 · magenta 4 · yellow 2"

    def test_products_and_unknown_names_are_refused(self):
        with pytest.raises(ValueError, match="formed by light"):
            RECIPES["bare-wood"].with_classes({"quinone": 3})
        with pytest.raises(ValueError, match="no colourant 'green'"):
            RECIPES["dyed-fabric"].with_classes({"green": 3})
        with pytest.raises(ValueError, match="Blue Wool"):
            RECIPES["dyed-fabric"].with_classes({"cyan": 9})

    def test_fastness_text_leaves_out_products(self):
        assert fastness_text(RECIPES["bare-wood"]) == "lignin 1 · extractive 2.7"


def test_unknown_recipe_lists_the_valid_ones():
    with pytest.raises(ValueError, match="printed-paper"):
        get_recipe("velvet")
