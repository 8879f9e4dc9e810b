"""Each bundled recipe fades like its material (issue 25): the key criteria, pinned.

Colours are aged on the reference path (one direct simulation per colour, as
``age-image --exact``) under daylight through window glass, 2,000 lux for 8 h a day;
``benchmarks/recipes.py`` measures the same on the grid path and on broader palettes.
"""

from dataclasses import replace

import numpy as np
import pytest

from lightfade_addon.core.aging.ager import Light, age_image_exact
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    delta_E_ab,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.recipes import RECIPES

LIGHT = Light("daylight-glass", False, 2000.0, 8.0, 365.0)
YEARS = np.concatenate([[0.0], np.geomspace(0.05, 1500.0, 70)])

NEUTRALS = {"black": (28, 28, 30), "charcoal": (58, 58, 60), "mid grey": (128, 128, 128),
            "light grey": (196, 196, 196), "greige": (186, 178, 165),
            "beige grey": (165, 158, 146), "dark warm grey": (55, 56, 50)}
CHROMATIC = {"red": (180, 30, 35), "navy": (30, 40, 90), "sky blue": (120, 170, 220),
             "olive": (110, 110, 50), "rust": (170, 80, 40), "teal": (30, 120, 120),
             "mustard": (205, 165, 50), "pink": (230, 160, 170)}
PALE_WOODS = {"maple": (222, 196, 160), "birch": (228, 195, 157), "beech": (205, 170, 140),
              "pine": (225, 190, 140), "oak": (196, 161, 124)}
DARK_WOODS = {"walnut": (118, 94, 78), "steamed beech": (170, 131, 108),
              "cherry": (160, 115, 83), "mahogany": (128, 86, 68)}


def lab(rgb255):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(rgb255, float) / 255.0)))


def aged_lab(colours, recipe, years=YEARS):
    """CIELAB (T, N, 3) of the colours at each of ``years``."""
    rgb = (np.array(list(colours.values()), float) / 255.0).reshape(1, -1, 3)
    out = age_image_exact(rgb, years, recipe, LIGHT)
    return np.stack([lab(255.0 * a.reshape(-1, 3)) for a in out])


def chroma(L):
    return np.hypot(L[..., 1], L[..., 2])


def hue_turn(a, b):
    h = np.arctan2(b[..., 2], b[..., 1]) - np.arctan2(a[..., 2], a[..., 1])
    return np.degrees(np.abs((h + np.pi) % (2 * np.pi) - np.pi))


def worst_before(labs, values, limit):
    """Per colour, the largest of ``values`` (T, N) before ΔE00 first reaches ``limit``
    (over the whole run for a light colour that never fades that far from its ground)."""
    dE = delta_E_2000(np.broadcast_to(labs[0], labs.shape), labs)
    out = []
    for n in range(labs.shape[1]):
        over = np.nonzero(dE[:, n] >= limit)[0]
        end = over[0] + 1 if over.size else labs.shape[0]
        out.append(values[:end, n].max())
    return np.array(out)


@pytest.fixture(scope="module", params=["dyed-fabric", "painted-wood"])
def on_tone(request):
    recipe = RECIPES[request.param]
    return recipe, aged_lab(NEUTRALS, recipe), aged_lab(CHROMATIC, recipe)


class TestOnTone:
    def test_neutrals_barely_gain_chroma(self, on_tone):
        _, labs, _ = on_tone
        gain = chroma(labs) - chroma(labs[:1])
        assert worst_before(labs, gain, 5).max() <= 4          # measured: 1.4
        assert worst_before(labs, gain, 12).max() <= 6         # measured: 2.8

    def test_chromatic_colours_keep_their_hue(self, on_tone):
        _, _, labs = on_tone
        turn = hue_turn(np.broadcast_to(labs[0], labs.shape), labs)
        assert worst_before(labs, turn, 5).max() <= 20         # measured: 3.7
        assert worst_before(labs, turn, 12).max() <= 30        # measured: 8.6

    def test_every_colour_gets_lighter(self, on_tone):
        _, neutrals, chromatic = on_tone
        for labs in (neutrals, chromatic):
            assert np.all(np.diff(labs[:, :, 0], axis=0) >= -1e-6)
            assert np.all(labs[-1, :, 0] > labs[0, :, 0] + 5)


def years_to(labs, limit):
    dE = delta_E_2000(np.broadcast_to(labs[0], labs.shape), labs)
    return np.array([YEARS[np.nonzero(dE[:, n] >= limit)[0][0]] for n in range(dE.shape[1])])


def test_paint_takes_at_least_three_times_the_dose_of_fabric():
    colours = {**NEUTRALS, **CHROMATIC}
    fabric = years_to(aged_lab(colours, RECIPES["dyed-fabric"]), 5)
    paint = years_to(aged_lab(colours, RECIPES["painted-wood"]), 5)
    assert np.all(paint >= 3 * fabric)                         # measured: 7.7-9.3x


def test_mismatched_dyes_turn_a_grey_as_the_issue_saw():
    """The old fabric (cyan Blue Wool 5, magenta 3, yellow 4, each on its own colour):
    a mid grey gains chroma; what the new recipe must not do (the test can fail)."""
    old = replace(RECIPES["dyed-fabric"], blue_wool=(5.0, 3.0, 4.0), calibration="colour",
                  kinetics="first-order")
    labs = aged_lab({"mid grey": (128, 128, 128)}, old)
    gain = chroma(labs) - chroma(labs[:1])
    assert worst_before(labs, gain, 12).max() > 6


def test_printed_greys_go_blue():
    greys = {k: NEUTRALS[k] for k in ("black", "charcoal", "mid grey", "light grey")}
    labs = aged_lab(greys, RECIPES["printed-paper"])
    dE = delta_E_2000(np.broadcast_to(labs[0], labs.shape), labs)
    for n in range(labs.shape[1]):
        i = np.nonzero(dE[:, n] >= 5)[0][0]
        assert labs[i, n, 2] < labs[0, n, 2] - 2                 # measured: -4.2 to -4.7


@pytest.fixture(scope="module")
def woods():
    """Pale and dark woods at 0, 2.75 and 22 Mlx·h (the issue's interior daylight)."""
    years = np.array([0.0, 1 / 8, 1.0]) * 22e6 / LIGHT.annual_dose
    return (aged_lab(PALE_WOODS, RECIPES["bare-wood"], years),
            aged_lab(DARK_WOODS, RECIPES["bare-wood"], years))


class TestBareWood:
    def test_pale_woods_darken_redden_and_yellow(self, woods):
        pale, _ = woods
        d = pale[-1] - pale[0]
        assert np.all((d[:, 0] >= -13) & (d[:, 0] <= -2))
        assert np.all((d[:, 1] >= 1) & (d[:, 1] <= 8))
        assert np.all((d[:, 2] >= 5) & (d[:, 2] <= 14))
        e = delta_E_ab(pale[0], pale[-1])
        assert np.all((e >= 7) & (e <= 22))

    def test_most_of_it_early(self, woods):
        pale, _ = woods
        early = delta_E_ab(pale[0], pale[1]) / delta_E_ab(pale[0], pale[-1])
        assert np.all(early > 0.3)                               # an eighth of the dose: 43 %

    def test_dark_woods_do_not_darken(self, woods):
        _, dark = woods
        assert np.all(dark[0, :, 0] < 60)
        assert np.all(dark[1:, :, 0] >= dark[0, :, 0] - 0.3)     # an eighth: -0.1 to +1.9
        assert np.all(dark[-1, :, 0] >= dark[0, :, 0] + 2)       # measured: +3.7 to +8.5
