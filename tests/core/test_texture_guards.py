"""TextureAger behaviours that bugs have broken before: UV filter, many colours,
reciprocity, bad numbers, years far past 100, every output in [0, 1]."""

import numpy as np
import pytest

from lightfade_addon.core.aging import texels
from lightfade_addon.core.aging.ager import Light, TextureAger
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.exact import age_image_exact
from lightfade_addon.core.fading.grid import GridSettings

#: A coarse grid where a test is not of the grid's accuracy (reciprocity, years far past
#: 100, bad numbers, out-of-range inputs and outputs): a tenth of the default grid's
#: build time.
COARSE = GridSettings(points=5, doses=17, mix=2)


def lab(img_srgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(img_srgb, float).reshape(-1, 3))))


@pytest.fixture(scope="module")
def image():
    rng = np.random.default_rng(4)
    y, x = np.mgrid[0:16, 0:20] / 16
    rgb = np.stack([0.55 + 0.35 * np.sin(4 * x), 0.45 + 0.35 * np.cos(3 * y), 0.4 + 0.3 * x * y],
                   -1)
    return np.clip(rgb + rng.normal(0, 0.02, rgb.shape), 0, 1).astype(np.float32)


def test_uv_filter_slows_yellowing_under_daylight():
    """Lignin reacts to UV: behind a UV filter pale bare wood yellows far less."""
    wood = np.full((4, 4, 3), np.array([222, 196, 160]) / 255, dtype=np.float32)  # maple
    bare = TextureAger(wood, "bare-wood", [Light("daylight", lux=2000)], encoding="srgb",
                       max_years=1).age(1)
    filtered = TextureAger(wood, "bare-wood", [Light("daylight", True, lux=2000)],
                           encoding="srgb", max_years=1).age(1)
    yellowing_bare = (lab(bare)[:, 2] - lab(wood)[:, 2]).mean()
    yellowing_filtered = (lab(filtered)[:, 2] - lab(wood)[:, 2]).mean()
    assert yellowing_bare > 3 and yellowing_filtered < 0.5 * yellowing_bare


def test_reciprocity_at_texture_level(image):
    """Only lux × hours matters: 300 lux for 10 years = 3000 lux for 1 year = half the
    exposure for twice as long."""
    a = TextureAger(image, "dyed-fabric", [Light(lux=300)], encoding="srgb", max_years=10,
                    settings=COARSE).age(10)
    b = TextureAger(image, "dyed-fabric", [Light(lux=3000)], encoding="srgb", max_years=1,
                    settings=COARSE).age(1)
    c = TextureAger(image, "dyed-fabric", [Light(lux=3000)], np.full(image.shape[:2], 0.5),
                    encoding="srgb", max_years=2, settings=COARSE).age(2)
    assert delta_E_2000(lab(image), lab(a)).mean() > 1      # it did fade
    np.testing.assert_allclose(a, b, atol=2e-4)
    np.testing.assert_allclose(a, c, atol=2e-4)


def test_years_far_above_100(image):
    ager = TextureAger(image, "painted-wood", [Light(lux=500)], encoding="srgb", max_years=800,
                       settings=COARSE)
    d100 = delta_E_2000(lab(image), lab(ager.age(100))).mean()
    d800 = delta_E_2000(lab(image), lab(ager.age(800))).mean()
    assert d800 > d100 + 1
    with pytest.raises(ValueError, match="max_years"):
        ager.age(801)


def test_more_than_max_keys_colours_stay_close_to_the_exact_path(image, monkeypatch):
    """The binned path (more distinct colours than the table has keys) against the exact path."""
    from lightfade_addon.core.aging import table

    monkeypatch.setattr(table, "TABLE_TEXELS", 300 * 65)  # 320 colours > 300 keys of 65 doses
    light = Light(lux=1500)
    ager = TextureAger(image, "printed-paper", [light], encoding="srgb", max_years=5)
    assert ager.table.keys <= 300
    binned = ager.age(5)
    exact = age_image_exact(image, [5.0], "printed-paper", light)[0]
    err = delta_E_2000(lab(binned), lab(exact))
    assert err.max() < 1.0 and np.percentile(err, 90) < 0.3
    assert delta_E_2000(lab(image), lab(exact)).mean() > 3   # a real fade


def test_binned_keys_are_bounded_and_close_in_concentration(image):
    from lightfade_addon.core.fading.recipes import get_recipe
    from lightfade_addon.core.fading.unmix import get_unmixer

    um = get_unmixer(get_recipe("printed-paper"))
    flat = image.reshape(-1, 3)
    key, c = texels.texel_concentrations(flat, um, max_keys=300)
    assert c.shape[0] <= 300 and key.max() < c.shape[0]
    exact = um.unmix(flat, encoded=True, refine=2)
    assert np.median(np.abs(c[key] - exact)) < 0.02


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_inputs_are_refused(image, bad):
    img = image.copy()
    img[3, 4, 1] = bad
    with pytest.raises(ValueError, match="NaN or infinite"):
        TextureAger(img, "printed-paper", [Light()])
    with pytest.raises(ValueError, match="NaN or infinite"):
        age_image_exact(img, [1.0])
    expo = np.ones(image.shape[:2])
    expo[0, 0] = bad
    with pytest.raises(ValueError, match="exposure"):
        TextureAger(image, "printed-paper", [Light()], expo)
    ager = TextureAger(image, "printed-paper", [Light()], max_years=5, settings=COARSE)
    with pytest.raises(ValueError, match="years"):
        ager.age(bad)
    with pytest.raises(ValueError, match="max_years"):
        TextureAger(image, "printed-paper", [Light()], max_years=bad)


@pytest.mark.parametrize("encoding", ["srgb", "linear"])
def test_every_output_is_finite_and_in_range(encoding):
    """Saturated colours that leave the gamut when aged are mapped back, in every path."""
    hues = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0.5, 0, 1], [0, 1, 1],
                     [1, 1, 0], [0.02, 0.02, 0.02], [1, 1, 1]], np.float32)
    img = np.repeat(hues[None], 4, 0)
    lights = [Light("daylight", lux=5000)]
    ager = TextureAger(img, "dyed-fabric", lights, encoding=encoding, max_years=500,
                       settings=COARSE)
    out = np.full((img.size // 3, 4), 0.5, np.float32)
    for y in (0, 0.5, 50, 500):
        for aged in (ager.age(y), ager.age(y, out=out)[:, :3]):
            assert np.all(np.isfinite(aged)) and aged.min() >= 0 and aged.max() <= 1
    for aged in age_image_exact(img, [50.0, 500.0], "dyed-fabric", lights[0], encoding=encoding):
        assert np.all(np.isfinite(aged)) and aged.min() >= 0 and aged.max() <= 1


@pytest.mark.parametrize("encoding", ["linear", "srgb"])
def test_an_input_outside_the_range_is_mapped_in_on_construction(encoding):
    """Only the colour outside [0, 1] moves, whatever the encoding of the texture."""
    img = np.array([[[1.3, 0.5, -0.2], [0.2, 0.4, 0.6]]], np.float32)
    ager = TextureAger(img, "printed-paper", [Light()], encoding=encoding, max_years=1,
                       settings=COARSE)
    zero = ager.age(0)
    assert zero.min() >= 0 and zero.max() <= 1
    np.testing.assert_allclose(zero[0, 1], img[0, 1], rtol=0,
                               atol=0 if encoding == "linear" else 1e-6)
