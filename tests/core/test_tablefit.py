"""Fitting a colour table's dose nodes to the change they are interpolated into
(core/aging/tablefit.py), and the table against the exact path."""

import numpy as np
import pytest

from lightfade_addon.core.aging.colourtable import evaluate
from lightfade_addon.core.aging.tablebuild import TableSettings, build_table
from lightfade_addon.core.aging.tablefit import dose_fit, fine_doses
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    XYZ_to_linear_srgb,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
    srgb_encode,
)
from lightfade_addon.core.fading.exact import age_image_exact
from lightfade_addon.core.fading.lights import Light
from lightfade_addon.core.fading.recipes import get_recipe
from lightfade_addon.core.fading.unmix import get_unmixer

LIGHT = Light("daylight", False, 3000.0, 8.9, 365.0)


class TestDose:
    def test_the_fine_axis_holds_the_nodes(self):
        fine = fine_doses(1e4, 8, 10, 4)
        nodes = np.concatenate([[0.0], 1e4 * 10.0 ** (np.arange(9) / 8)])
        np.testing.assert_allclose(fine[1::4], nodes[1:])
        assert fine[0] == 0.0 and fine.size == 8 * 4 + 2

    def test_a_piecewise_linear_curve_is_its_nodes(self):
        nodes = np.random.default_rng(0).normal(size=(2, 7, 3))
        nodes[:, 0] = 0.0
        s = np.concatenate([[0.0], 1 + np.arange(5 * 3 + 1) / 3])
        curve = np.stack([np.stack([np.interp(s, np.arange(7), nodes[k, :, ch])
                                    for ch in range(3)], -1) for k in range(2)])
        np.testing.assert_allclose(dose_fit(curve, 3), nodes, atol=1e-6)

    def test_a_curved_curve_is_fitted_better_than_sampled(self):
        s = np.concatenate([[0.0], 1 + np.arange(6 * 4 + 1) / 4])
        curve = np.repeat(np.exp(s / 2)[:, None], 3, axis=1) - 1
        fitted = dose_fit(curve, 4)[:, 0]
        sampled = np.concatenate([curve[:1], curve[1::4]])[:, 0]     # the nodes' own values
        def worst(nodes):
            return np.abs(np.interp(s, np.arange(nodes.size), nodes) - curve[:, 0]).max()
        assert fitted[0] == 0.0
        assert worst(fitted) < 0.6 * worst(sampled)


def _lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float)))


@pytest.fixture(scope="module")
def poster():
    """Printed Paper's default table, and colours across the whole cube: mixtures inside
    the gamut, and colours outside it (darker than its densest mixture, brighter or
    more saturated than its paper allows) where the gamut's faces cut the cube."""
    recipe = get_recipe("printed-paper")
    rng = np.random.default_rng(3)
    c = rng.uniform(0.03, 0.5, (120, 3))
    inside = XYZ_to_linear_srgb(get_unmixer(recipe).XYZ(c))
    inside = inside[np.all((inside > 0) & (inside < 1), axis=1)]
    dark = rng.uniform(0.0, 0.12, (120, 3)) ** 2.2                  # shadows of photos
    anywhere = rng.uniform(0.0, 1.0, (200, 3)) ** 2.2
    rgb = np.concatenate([inside, dark, anywhere]).astype(np.float32)
    c = get_unmixer(recipe).unmix(rgb)
    faces = np.any((c <= 1e-9) | (c >= 1 - 1e-9), axis=1)
    assert faces.sum() > 100 and (~faces).sum() > 100               # both kinds tested
    table = build_table(recipe, [(LIGHT.spectrum, LIGHT.uv_filter)], TableSettings())
    return recipe, table, rgb


def test_across_the_cube_the_table_is_within_the_bound_of_the_exact_path(poster):
    """Within ΔE00 0.6 (p99) and 1.5 (max) of ``age-image --exact`` at 5 and 25 years of
    a sunlit poster (issue 27's bound), out of the gamut too: the clip of ``Φ`` follows
    the interpolation, so the gamut's faces are exact (docs/blender.md)."""
    recipe, table, rgb = poster
    rates = np.full((1, len(rgb)), LIGHT.annual_dose, np.float32)
    exact = age_image_exact(srgb_encode(rgb)[None], [5, 25], recipe, LIGHT)
    for years, ref in zip((5, 25), exact):
        d = delta_E_2000(_lab(evaluate(table, rgb, rates, years)), _lab(srgb_decode(ref[0])))
        assert np.percentile(d, 99) < 0.6 and d.max() < 1.5, (years, np.percentile(d, 99), d.max())


def test_the_unmixing_table_is_the_extended_solution_at_its_nodes():
    """``Φ`` solved by Newton steps from the unmixer's own table of ``Φ`` is the full
    solve at every node of the cube, outside the gamut too."""
    from lightfade_addon.core.aging.colourtable import cube_colours

    recipe = get_recipe("dyed-fabric")
    table = build_table(recipe, [(LIGHT.spectrum, LIGHT.uv_filter)],
                        TableSettings(side=5, unmix_side=17, per_decade=2))
    full = get_unmixer(recipe).extended(cube_colours(17, table.gamma))
    assert np.any(full < 0) and np.any(full > 1)
    np.testing.assert_allclose(table.unmix.reshape(-1, 3).astype(float),
                               np.clip(full, -1, 2), atol=2e-3)
