"""restore(): an aged texture brought back to new, and the pixels that cannot be."""

import numpy as np
import pytest

from lightfade_addon.core.aging import Light, Prior, TextureAger
from lightfade_addon.core.grid import GridSettings
from lightfade_addon.core.colorimetry import (
    XYZ_to_Lab, delta_E_2000, linear_srgb_to_XYZ, srgb_decode)
from lightfade_addon.core.restore import restore

LIGHT = Light("daylight-glass", lux=1000)
#: Restoring inverts the aging on the same grid, so the round trips hold on a coarse
#: one (a tenth of the shipped grid's build time); test_grid checks the grid itself.
COARSE = GridSettings(points=5, doses=17, mix=2)


def lab(img_srgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(img_srgb, float).reshape(-1, 3))))


@pytest.fixture(scope="module")
def image():
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:16, 0:24] / 16
    rgb = np.stack([0.6 + 0.3 * np.sin(4 * x), 0.5 + 0.3 * np.cos(3 * y), 0.45 + 0.3 * x * y], -1)
    return np.clip(rgb + rng.normal(0, 0.02, rgb.shape), 0.02, 0.98).astype(np.float32)


@pytest.mark.parametrize("years", [1.0, 3.0])
def test_round_trip_where_information_survives(image, years):
    aged = TextureAger(image, "printed-paper", [LIGHT], encoding="srgb",
                       max_years=years, settings=COARSE).age(years)
    fade = delta_E_2000(lab(image), lab(aged)).reshape(image.shape[:2])
    back = restore(aged, years, "printed-paper", [LIGHT], encoding="srgb", settings=COARSE)
    err = delta_E_2000(lab(image), lab(back.image)).reshape(image.shape[:2])
    kept = ~back.lost
    assert fade.mean() > 2                              # a visible fade to undo
    assert kept.mean() > 0.5                            # most of it survives
    assert err[kept].max() < 1.0
    assert back.lost_count == np.count_nonzero(back.lost)


def test_lost_pixels_are_reported_after_a_total_fade(image):
    years = 200.0
    aged = TextureAger(image, "printed-paper", [Light(lux=5000)], encoding="srgb",
                       max_years=years, settings=COARSE).age(years)
    back = restore(aged, years, "printed-paper", [Light(lux=5000)], encoding="srgb",
                   settings=COARSE)
    assert back.lost.shape == image.shape[:2]
    assert back.lost.mean() > 0.9                        # the dyes are gone: nothing to recover


def test_zero_years_or_no_light_changes_nothing(image):
    for years, light in ((0.0, LIGHT), (5.0, Light(lux=0.0))):
        back = restore(image, years, "printed-paper", [light], encoding="srgb")
        np.testing.assert_array_equal(back.image, image)
        assert back.lost_count == 0


def test_texture_ager_with_a_prior_starts_from_new(image):
    years = 2.0
    aged = TextureAger(image, "printed-paper", [LIGHT], encoding="srgb",
                       max_years=years, settings=COARSE).age(years)
    ager = TextureAger(aged, "printed-paper", [LIGHT], encoding="srgb", max_years=years,
                       prior=Prior(years, (LIGHT,)), settings=COARSE)
    kept = ~ager.lost
    new = ager.age(0)
    assert delta_E_2000(lab(image), lab(new)).reshape(kept.shape)[kept].max() < 1.0
    again = delta_E_2000(lab(aged), lab(ager.age(years))).reshape(kept.shape)
    assert again[kept].max() < 1.0                       # back to how it was photographed


def test_unlit_pixels_come_back_as_they_are_and_are_never_lost(image):
    """With an exposure map, texels no light fell on are not restored, and a shadowed
    white (at the edge of the range, where a lit one may have been clipped) is not lost."""
    img = image[:4, :6].copy()
    img[:, 0] = 1.0                                      # a white column, lit and unlit
    exposure = np.ones(img.shape[:2])
    exposure[2:] = 0.0
    back = restore(img, 3.0, "printed-paper", [LIGHT], exposure, encoding="srgb",
                   settings=COARSE)
    np.testing.assert_allclose(back.image[2:], img[2:], atol=1e-5)
    assert np.abs(back.image[:2] - img[:2]).max() > 0.01  # the lit half was restored
    assert back.lost[:2, 0].all() and not back.lost[2:].any()


@pytest.mark.parametrize("bad, word", [(float("nan"), "years"), (-1.0, "years")])
def test_bad_years(image, bad, word):
    with pytest.raises(ValueError, match=word):
        restore(image, bad, "printed-paper", [LIGHT])


def test_non_finite_colours_are_refused(image):
    img = image.copy()
    img[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        restore(img, 1.0, "printed-paper", [LIGHT])
