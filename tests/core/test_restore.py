"""restore(): an aged texture brought back to new, and the pixels that cannot be."""

import re
from dataclasses import replace

import numpy as np
import pytest

from lightfade_addon.core.aging.ager import Light, Prior, TextureAger
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.recipes import RECIPES
from lightfade_addon.core.aging.restore import restore

LIGHT = Light("daylight-glass", lux=1000)
#: A fugitive print (yellow Blue Wool 2, magenta 2.5, cyan 4): fades enough in a few
#: years of 1,000 lux for the round trips to have something to undo.
PRINT = RECIPES["printed-paper"].with_blue_wool(2)
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


def ager_out_of_range(image, years):
    return TextureAger(image, PRINT, [LIGHT], encoding="srgb", max_years=years,
                       settings=COARSE).out_of_range(years)


@pytest.mark.parametrize("years", [1.0, 3.0])
def test_round_trip_where_information_survives(image, years):
    aged = TextureAger(image, PRINT, [LIGHT], encoding="srgb",
                       max_years=years, settings=COARSE).age(years)
    fade = delta_E_2000(lab(image), lab(aged)).reshape(image.shape[:2])
    back = restore(aged, years, PRINT, [LIGHT], encoding="srgb", settings=COARSE)
    err = delta_E_2000(lab(image), lab(back.image)).reshape(image.shape[:2])
    # aged colours the gamut rule pulled into [0, 1] come back on the near side of
    # the truth (not lost: the photograph cannot say how far); the rest exactly
    kept = ~back.lost & ~ager_out_of_range(image, years)
    assert fade.mean() > 2                              # a visible fade to undo
    assert kept.mean() > 0.5                            # most of it survives
    assert err[kept].max() < 1.0
    assert back.lost_count == np.count_nonzero(back.lost)


def test_lost_pixels_are_reported_after_a_total_fade(image):
    years = 200.0
    aged = TextureAger(image, PRINT, [Light(lux=5000)], encoding="srgb",
                       max_years=years, settings=COARSE).age(years)
    back = restore(aged, years, PRINT, [Light(lux=5000)], encoding="srgb",
                   settings=COARSE)
    assert back.lost.shape == image.shape[:2]
    assert back.lost.mean() > 0.9                        # the dyes are gone: nothing to recover
    assert back.lost_fraction == back.lost.mean()


def magentas(recipe=PRINT):
    """Two magenta inks of the recipe, ΔE00 > 10 apart when new (encoded sRGB, (1, 2, 3))."""
    from lightfade_addon.core.colour.colorimetry import XYZ_to_linear_srgb, srgb_encode
    from lightfade_addon.core.fading.unmix import get_unmixer

    unmixer = get_unmixer(recipe)
    XYZ = unmixer.XYZ(np.array([[0.02, 0.35, 0.02], [0.02, 0.7, 0.02]]))
    rgb = srgb_encode(np.clip(XYZ_to_linear_srgb(XYZ), 0, 1))
    return np.asarray(rgb, np.float32)[None]


class TestLost:
    """``lost`` marks texels whose originals the light made indistinguishable, and only them."""

    def test_two_magentas_faded_to_one_grey_are_lost(self):
        img = magentas()
        light, years = Light("daylight", lux=5000), 60.0
        aged = TextureAger(img, PRINT, [light], encoding="srgb", max_years=years,
                           settings=COARSE).age(years)
        assert delta_E_2000(*lab(img)) > 10                 # different magentas when new
        assert delta_E_2000(*lab(aged)) < 1                 # the same colour now
        back = restore(aged, years, PRINT, [light], encoding="srgb",
                       settings=COARSE)
        assert back.lost.all()
        assert back.lost_count == 2 and back.lost_fraction == 1.0

    def test_a_mild_age_loses_nothing(self):
        img = magentas()
        years = 1.0
        aged = TextureAger(img, PRINT, [LIGHT], encoding="srgb", max_years=years,
                           settings=COARSE).age(years)
        assert delta_E_2000(*lab(img)) > 10
        assert delta_E_2000(*lab(aged)) > 5                 # still told apart
        assert delta_E_2000(lab(img), lab(aged)).max() > 2  # yet visibly faded
        back = restore(aged, years, PRINT, [LIGHT], encoding="srgb",
                       settings=COARSE)
        assert not back.lost.any()
        assert back.spread.max() < 1.0
        assert delta_E_2000(lab(img), lab(back.image)).max() < 0.5

    def test_a_history_the_photo_cannot_have_had_is_lost(self, image):
        """Colours no displayable original fades to under the claimed light (far more
        than the texture received) are lost; under a plausible history they are not."""
        light = Light("daylight", lux=5000)
        back = restore(image, 10.0, PRINT, [light], encoding="srgb",
                       settings=COARSE)
        assert back.lost.mean() > 0.4                        # measured: half (cyans survive)
        assert (back.lost & (back.spread < 2.0)).mean() > 0.3  # not for want of precision
        mild = restore(image, 0.2, PRINT, [LIGHT], encoding="srgb",
                       settings=COARSE)
        assert not mild.lost.any()

    def test_the_spread_grows_with_the_images_precision(self):
        """A 16-bit photo pins its original 257 times tighter than an 8-bit one."""
        img = magentas()
        light, years = Light("daylight", lux=5000), 60.0
        aged = TextureAger(img, PRINT, [light], encoding="srgb", max_years=years,
                           settings=COARSE).age(years)
        coarse = restore(aged, years, PRINT, [light], encoding="srgb",
                         settings=COARSE)
        fine = restore(aged, years, PRINT, [light], encoding="srgb",
                       settings=COARSE, precision=0.5 / 65535)
        np.testing.assert_allclose(fine.spread * 257, coarse.spread, rtol=1e-6)


def test_more_colours_than_the_budget_are_solved_per_8_bit_colour(monkeypatch):
    """A float photograph with more distinct colours than aging unmixes one by one is
    solved once per 8-bit colour (as many solves as those), each texel keeping its own
    detail: the same restoration as solving every colour."""
    from lightfade_addon.core.aging import texels

    rng = np.random.default_rng(3)
    img = np.clip(hopper() + rng.normal(0, 0.004, (100, 86, 3)), 0, 1).astype(np.float32)
    years = 1.0
    aged = TextureAger(img, PRINT, [LIGHT], encoding="srgb", max_years=years,
                       settings=COARSE).age(years)

    def solves(budget):
        monkeypatch.setattr(texels, "UNMIX_BUDGET", budget)
        said = []
        back = restore(aged, years, PRINT, [LIGHT], encoding="srgb",
                       settings=COARSE, progress=lambda f, m: said.append(m))
        return back, int(re.search(r"inverting the fade of (\d+)", said[-2]).group(1))

    every, n_every = solves(1 << 20)
    binned, n_binned = solves(1000)
    eight_bit = np.unique(np.rint(aged.reshape(-1, 3) * 255), axis=0).shape[0]
    assert n_every == np.unique(aged.reshape(-1, 3), axis=0).shape[0] > n_binned
    assert n_binned == eight_bit
    err = delta_E_2000(lab(every.image), lab(binned.image))
    assert np.percentile(err, 99) < 0.1 and np.median(err) < 0.01     # measured: 0.07, 0
    truth = delta_E_2000(lab(img), lab(binned.image))
    assert np.percentile(truth, 99) < 0.2                             # measured: 0.13


def test_zero_years_or_no_light_changes_nothing(image):
    for years, light in ((0.0, LIGHT), (5.0, Light(lux=0.0))):
        back = restore(image, years, PRINT, [light], encoding="srgb")
        np.testing.assert_array_equal(back.image, image)
        assert back.lost_count == 0


def test_texture_ager_with_a_prior_starts_from_new(image):
    years = 2.0
    aged = TextureAger(image, PRINT, [LIGHT], encoding="srgb",
                       max_years=years, settings=COARSE).age(years)
    ager = TextureAger(aged, PRINT, [LIGHT], encoding="srgb", max_years=years,
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
    back = restore(img, 3.0, PRINT, [LIGHT], exposure, encoding="srgb",
                   settings=COARSE)
    np.testing.assert_allclose(back.image[2:], img[2:], atol=1e-5)
    assert np.abs(back.image[:2] - img[:2]).max() > 0.01  # the lit half was restored
    assert not back.lost[2:].any() and not back.spread[2:].any()
    assert back.spread[:2].all()


@pytest.mark.parametrize("bad, word", [(float("nan"), "years"), (-1.0, "years")])
def test_bad_years(image, bad, word):
    with pytest.raises(ValueError, match=word):
        restore(image, bad, PRINT, [LIGHT])


def test_non_finite_colours_are_refused(image):
    img = image.copy()
    img[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        restore(img, 1.0, PRINT, [LIGHT])


def hopper():
    """Grace Hopper's portrait (matplotlib's sample data, a US Navy photograph), 100 × 86."""
    cbook = pytest.importorskip("matplotlib.cbook")
    from PIL import Image

    return np.asarray(Image.open(cbook.get_sample_data("grace_hopper.jpg")).convert("RGB"),
                      np.float32)[::6, ::6] / 255


def test_a_second_original_as_good_marks_a_fold(monkeypatch):
    """Where the Jacobian alone sees no loss, a second original further away that fades
    to the same colour does: the texels it adds restore worse than ΔE00 2."""
    import lightfade_addon.core.aging.restore as module

    img = hopper()
    fugitive = replace(PRINT, blue_wool=(5.0, 1.0, 3.0))    # a magenta of Blue Wool 1
    years, light = 100.0, Light()                         # 44 Mlx·h: magenta mostly gone
    aged = TextureAger(img, fugitive, [light], encoding="srgb", max_years=years,
                       settings=COARSE).age(years)
    aged = np.rint(aged * 255) / 255
    back = restore(aged, years, fugitive, [light], encoding="srgb", settings=COARSE)
    monkeypatch.setattr(module, "_PROBE", np.inf)          # the Jacobian alone
    local = restore(aged, years, fugitive, [light], encoding="srgb", settings=COARSE)
    added = back.lost & ~local.lost
    assert not (local.lost & ~back.lost).any()
    assert added.sum() > 50                                 # measured: 108 of 8600
    err = delta_E_2000(lab(img), lab(back.image)).reshape(img.shape[:2])
    assert np.mean(err[added] > 2) > 0.9


def test_a_real_photograph_flags_at_most_what_restores_badly():
    """The portrait aged 25 years of the default living-room light, written at 8 bits
    and restored: the lost flag is on at most as many pixels as restore worse than
    ΔE00 2."""
    img = hopper()
    years, light = 25.0, Light()
    aged = TextureAger(img, PRINT, [light], encoding="srgb", max_years=years,
                       settings=COARSE).age(years)
    aged = np.rint(aged * 255) / 255
    back = restore(aged, years, PRINT, [light], encoding="srgb", settings=COARSE)
    fade = delta_E_2000(lab(img), lab(aged))
    err = delta_E_2000(lab(img), lab(back.image))
    assert np.median(fade) > 5                            # a strong fade
    assert np.median(err) < 0.5
    assert back.lost_fraction <= np.mean(err > 2)
    assert back.lost_fraction == back.lost.mean()


def test_bare_wood_colours_off_its_curve_restore_or_are_lost():
    """Bare wood unmixes one colourant (the extractive): a sky blue lies off its curve,
    and a grey of full extractive can fade to the very colour the sky blue does (a
    fold the spread does not see). Every restored pixel that is not lost is its
    original (measured: all but one within ΔE00 0.05; two solver steps left a third of
    them, the sky, 24 away unflagged), and aging the restored image again gives the
    photo back there."""
    from benchmarks.problem import synthetic_photo

    img = synthetic_photo(24, 24).astype(np.float32)
    years, light = 15.0, Light("fluorescent", lux=1000)
    ager = TextureAger(img, "bare-wood", [light], encoding="srgb", max_years=years,
                       settings=COARSE)
    aged = ager.age(years)
    back = restore(aged, years, "bare-wood", [light], encoding="srgb", settings=COARSE)
    kept = ~back.lost & ~ager.out_of_range(years)
    err = delta_E_2000(lab(img), lab(back.image)).reshape(img.shape[:2])
    again = TextureAger(back.image, "bare-wood", [light], encoding="srgb", max_years=years,
                        settings=COARSE).age(years)
    trip = delta_E_2000(lab(aged), lab(again)).reshape(img.shape[:2])
    assert delta_E_2000(lab(img), lab(aged)).mean() > 2          # a visible fade
    assert kept.mean() > 0.3
    # one sky blue of 576 sits where its nearest point of the curve flips from one end
    # to the other (the unmixing jumps between colours 1e-4 apart): it restores 23 away
    assert np.mean(err[kept] > 1.0) < 0.01, np.mean(err[kept] > 1.0)
    assert np.mean(trip[kept] > 0.5) < 0.01, np.mean(trip[kept] > 0.5)
