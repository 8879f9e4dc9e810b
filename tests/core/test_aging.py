"""TextureAger and age_image: zero years exact, shadows keep their colour, errors."""

import numpy as np
import pytest

from lightfade_addon.core.aging.ager import Light, TextureAger, age_image, age_image_exact
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.grid import GridSettings

SUN = Light("daylight-glass", lux=3000, hours_per_day=8)
LAMP = Light("incandescent", lux=300, hours_per_day=5)
#: A coarse grid for the tests of what an ager does with its grid (zero years, shadows,
#: doses, alpha, errors), not of the grid's accuracy (test_small_years_..., test_matches_
#: the_exact_path and test_grid.py keep the default): a tenth of its build time.
COARSE = GridSettings(points=5, doses=17, mix=2)


def lab(img_srgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(img_srgb, float).reshape(-1, 3))))


@pytest.fixture(scope="module")
def image():
    rng = np.random.default_rng(0)
    y, x = np.mgrid[0:24, 0:32] / 24
    rgb = np.stack([0.5 + 0.4 * np.sin(5 * x), 0.4 + 0.4 * np.cos(4 * y), 0.3 + 0.3 * x * y], -1)
    return np.clip(rgb + rng.normal(0, 0.02, rgb.shape), 0, 1).astype(np.float32)


@pytest.fixture(scope="module")
def shadow():
    e = np.ones((24, 32))
    e[8:16, 10:20] = 0.0                      # an occluder: no light at all
    return e


class TestLight:
    def test_annual_dose_is_lux_times_hours_times_days(self):
        assert Light(lux=200, hours_per_day=6, days_per_year=100).annual_dose == 200 * 6 * 100

    def test_a_whole_day_every_day_of_a_leap_year_is_allowed_no_more(self):
        assert Light(lux=10, hours_per_day=24, days_per_year=366).annual_dose == 10 * 24 * 366
        for more in (dict(hours_per_day=24.5), dict(days_per_year=367)):
            with pytest.raises(ValueError, match="24 h a day or 366 days"):
                Light(**more)


class TestTextureAger:
    def test_zero_years_returns_the_original_exactly(self, image):
        ager = TextureAger(image, "printed-paper", [SUN], encoding="srgb", max_years=10,
                           settings=COARSE)
        np.testing.assert_array_equal(ager.age(0), image)
        q = np.round(image * 255) / 255
        ager8 = TextureAger(q.astype(np.float32), "printed-paper", [SUN], encoding="srgb",
                            max_years=10, settings=COARSE)
        np.testing.assert_array_equal(np.round(ager8.age(0) * 255), np.round(q * 255))

    def test_fades_with_years_and_shadow_keeps_its_colour(self, image, shadow):
        ager = TextureAger(image, "dyed-fabric", [SUN], shadow, encoding="srgb", max_years=20,
                           settings=COARSE)
        d = [delta_E_2000(lab(image), lab(ager.age(y))).reshape(24, 32) for y in (2, 10, 20)]
        lit = shadow > 0
        assert d[0][lit].mean() < d[1][lit].mean() < d[2][lit].mean()
        assert d[2][lit].mean() > 3
        assert d[2][~lit].max() < 1e-3

    def test_small_years_are_close_to_the_original(self, image):
        # the default grid: how close it stays to the original at a tiny dose
        ager = TextureAger(image, "printed-paper", [SUN], encoding="srgb", max_years=10)
        assert delta_E_2000(lab(image), lab(ager.age(1e-6))).max() < 0.01

    def test_two_lights_and_per_light_exposure(self, image):
        e = np.stack([np.linspace(0, 1, 32)[None].repeat(24, 0),
                      np.linspace(1, 0, 32)[None].repeat(24, 0)])
        ager = TextureAger(image, "printed-paper", [SUN, LAMP], e, encoding="srgb", max_years=5,
                           settings=COARSE)
        dose = ager.dose(5)
        expected = 5 * (e[0] * 3000 * 8 * 365 + e[1] * 300 * 5 * 365)    # lux × h/day × days
        np.testing.assert_allclose(dose, expected, rtol=1e-6)
        assert ager.grid.mixes.shape[1] == 2
        assert ager.age(5).shape == image.shape

    def test_lights_of_one_spectrum_add_up(self, image):
        e = np.stack([np.linspace(0, 1, 32)[None].repeat(24, 0), np.full((24, 32), 0.5)])
        twin = Light("daylight-glass", lux=300, hours_per_day=5)
        ager = TextureAger(image, "printed-paper", [SUN, twin], e, encoding="srgb",
                           max_years=5, settings=COARSE)
        np.testing.assert_allclose(ager.dose(5), 5 * (e[0] * 3000 * 8 + e[1] * 300 * 5) * 365,
                                   rtol=1e-6)
        assert ager.grid.mixes.shape[1] == 1                  # one spectrum: one light group

    def test_rgba_output_leaves_alpha_alone(self, image):
        ager = TextureAger(image, "printed-paper", [SUN], encoding="linear", max_years=5,
                           settings=COARSE)
        out = np.full((24 * 32, 4), 0.25, dtype=np.float32)
        ager.age(3, out=out)
        np.testing.assert_array_equal(out[:, 3], 0.25)
        np.testing.assert_allclose(out[:, :3], ager.age(3).reshape(-1, 3), rtol=1e-6)

    def test_linear_and_srgb_inputs_age_alike(self, image):
        """The encoding is only how colours are stored: the same texture given in linear
        sRGB is unmixed from the same colours and ages to the same colours."""
        kw = dict(max_years=5, settings=COARSE)
        srgb = TextureAger(image, "printed-paper", [SUN], encoding="srgb", **kw).age(5)
        linear = TextureAger(srgb_decode(image).astype(np.float32), "printed-paper", [SUN],
                             encoding="linear", **kw).age(5)
        assert delta_E_2000(lab(image), lab(srgb)).mean() > 1          # a real fade
        np.testing.assert_allclose(linear, srgb_decode(srgb), atol=2e-4)   # gamut-edge rounding

    def test_matches_the_exact_path(self, image):
        a = age_image(image, [4.0], "printed-paper", [SUN])[0]
        b = age_image_exact(image, [4.0], "printed-paper", SUN)[0]
        assert delta_E_2000(lab(a), lab(b)).max() < 1.0

    def test_bare_wood_yellows(self, image):
        wood = np.full((4, 4, 3), [0.75, 0.6, 0.45], dtype=np.float32)
        aged = age_image(wood, [10.0], "bare-wood", [Light("daylight", lux=5000)])[0]
        Lab0, Lab1 = lab(wood), lab(aged)
        assert np.all(Lab1[:, 2] > Lab0[:, 2] + 1)       # b* rises: yellower

    @pytest.mark.parametrize("years", [-1.0, float("nan"), 11.0])
    def test_bad_years(self, image, years):
        ager = TextureAger(image, "printed-paper", [SUN], encoding="srgb", max_years=10,
                           settings=COARSE)
        with pytest.raises(ValueError, match="years"):
            ager.age(years)

    def test_bad_inputs(self, image):
        with pytest.raises(ValueError, match="channels"):
            TextureAger(image[..., :2], "printed-paper", [SUN])
        with pytest.raises(ValueError, match="light"):
            TextureAger(image, "printed-paper", [])
        with pytest.raises(ValueError, match="exposure"):
            TextureAger(image, "printed-paper", [SUN], -np.ones((24, 32)))
        with pytest.raises(ValueError, match="lux"):
            Light(lux=-5)
        with pytest.raises(ValueError, match="recipe"):
            TextureAger(image, "velvet", [SUN])
