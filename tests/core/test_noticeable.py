"""Years until a just-noticeable fade (ΔE00 = 1), per texel."""

import numpy as np
import pytest

from lightfade_addon.core.aging.ager import Light, TextureAger
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
)
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.aging.noticeable import years_to_noticeable

COARSE = GridSettings(points=5, doses=17, mix=2)


@pytest.fixture(scope="module")
def ager():
    rgb = np.tile(np.float32([0.2, 0.1, 0.5]), (1, 4, 1))
    exposure = np.array([[1.0, 2.0, 0.5, 0.0]])
    light = Light("daylight-glass", False, 1000.0, 8.0, 365.0)
    return TextureAger(rgb, "dyed-fabric", [light], exposure, max_years=200.0,
                       encoding="linear", settings=COARSE, cache=False)


class TestYearsToNoticeable:
    def test_reciprocity_twice_the_dose_half_the_years(self, ager):
        years = years_to_noticeable(ager)
        assert years.shape == (1, 4) and years.dtype == np.float32
        y1, y2, y05 = years[0, :3]
        assert y2 == pytest.approx(y1 / 2, rel=0.03)
        assert y05 == pytest.approx(2 * y1, rel=0.03)

    def test_the_colour_is_one_delta_e00_away_at_those_years(self, ager):
        years = years_to_noticeable(ager)[0, 0]
        lab = XYZ_to_Lab(linear_srgb_to_XYZ(np.stack([ager.original[0, 0],
                                                      ager.age(years)[0, 0]]).astype(float)))
        assert float(delta_E_2000(lab[0], lab[1])) == pytest.approx(1.0, abs=0.05)

    def test_an_unlit_texel_never_fades(self, ager):
        assert np.isinf(years_to_noticeable(ager)[0, 3])

    def test_a_larger_threshold_takes_longer(self, ager):
        assert years_to_noticeable(ager, 3.0)[0, 0] > years_to_noticeable(ager, 1.0)[0, 0]

    @pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
    def test_bad_thresholds_are_refused(self, ager, bad):
        with pytest.raises(ValueError, match="threshold"):
            years_to_noticeable(ager, bad)
