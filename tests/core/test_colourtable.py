"""The colour-cube aging table: building it (core/aging/tablebuild.py), its numpy evaluator and
the atlas image the node group reads (core/aging/colourtable.py)."""

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_linear_srgb,
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_encode,
)
from lightfade_addon.core.fading.unmix import get_unmixer
from lightfade_addon.core.aging.colourtable import (
    ColourTable,
    atlas_layout,
    atlas_pixels,
    coordinates,
    cube_colours,
    dose_nodes,
    dose_position,
    evaluate,
    table_from_atlas,
)
from lightfade_addon.core.fading.exact import age_image_exact
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.fading.lights import Light
from lightfade_addon.core.fading.recipes import get_recipe
from lightfade_addon.core.aging.restore import Prior
from lightfade_addon.core.aging.tablebuild import TableSettings, build_table, load_or_build

SMALL = TableSettings(side=5, unmix_side=9, per_decade=4, grid=GridSettings(points=5))
LIGHT = Light("daylight", False, 3000.0, 8.9, 365.0)
KEY = [(LIGHT.spectrum, LIGHT.uv_filter)]


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))


@pytest.fixture(scope="module")
def paper():
    return build_table(get_recipe("printed-paper"), KEY, SMALL)


def _colours(n=300, seed=1):
    return np.random.default_rng(seed).uniform(0, 1, (n, 3)).astype(np.float32) ** 2.2


class TestDoseAxis:
    def test_nodes_sit_at_whole_positions(self):
        doses = dose_nodes(1e3, 4, 9)
        np.testing.assert_allclose(dose_position(doses, 1e3, 4, 9), np.arange(9), atol=2e-5)

    def test_linear_below_node_one_and_saturating_past_the_end(self):
        assert dose_position(500.0, 1e3, 4, 9) == pytest.approx(0.5)
        assert dose_position(1e30, 1e3, 4, 9) == 8.0

    def test_the_axis_is_cut_where_the_recipe_stops_changing(self, paper):
        assert 3 < paper.T < len(dose_nodes(1e3, 4, 50))
        assert paper.max_dose < SMALL.ceiling
        change = paper.values.astype(np.float32)
        assert np.abs(change[:, -1] - change[:, -2]).max() < 0.05


class TestEvaluate:
    def test_zero_years_is_the_colour_itself(self, paper):
        rgb = _colours()
        rates = np.full((1, len(rgb)), 1e6, np.float32)
        np.testing.assert_array_equal(evaluate(paper, rgb, rates, 0.0), rgb)

    def test_no_light_no_change(self, paper):
        rgb = _colours()
        out = evaluate(paper, rgb, np.zeros((1, len(rgb)), np.float32), 30.0)
        np.testing.assert_allclose(out, np.clip(rgb, 0, 1), atol=2e-6)

    def test_reciprocity(self, paper):
        """Only rate × years counts: twice the light for half the years."""
        rgb = _colours()
        one = evaluate(paper, rgb, np.full((1, len(rgb)), 2e6, np.float32), 5.0)
        two = evaluate(paper, rgb, np.full((1, len(rgb)), 1e6, np.float32), 10.0)
        np.testing.assert_allclose(one, two, atol=1e-5)

    def test_huge_years_saturate_and_ordinary_years_do_not_move(self, paper):
        rgb = _colours()
        rates = np.full((1, len(rgb)), 1e6, np.float32)
        np.testing.assert_array_equal(evaluate(paper, rgb, rates, 1e9),
                                      evaluate(paper, rgb, rates, 1e15))
        assert np.abs(evaluate(paper, rgb, rates, 20.0) - evaluate(paper, rgb, rates, 1e9)
                      ).max() > 0.05

    @pytest.mark.parametrize("substeps,limit", [(1, 1.5), (2, 1.0)])
    def test_at_the_concentration_nodes_it_is_the_simulation(self, substeps, limit):
        """The colours of the change table's concentration nodes land on those nodes
        (the unmixing table is their inverse), and there the table is the simulation:
        within ΔE00 ``limit`` of the exact path at 5 and 25 years of a sunlit poster,
        closer with the kinetics stepped twice per dose node (the fit, :mod:`.tablefit`)."""
        recipe = get_recipe("printed-paper")
        table = build_table(recipe, KEY, TableSettings(side=5, unmix_side=33,
                                                       substeps=substeps))
        k = np.stack(np.meshgrid(*[np.arange(5)] * 3, indexing="ij"), -1).reshape(-1, 3)
        rgb = XYZ_to_linear_srgb(get_unmixer(recipe).XYZ((k / 4.0) ** table.power))
        inside = np.all((rgb > 1e-3) & (rgb < 1), axis=1)
        rgb, k = rgb[inside].astype(np.float32), k[inside]
        assert len(rgb) > 40
        np.testing.assert_allclose(coordinates(table, rgb), k, atol=0.05)
        rates = np.full((1, len(rgb)), LIGHT.annual_dose, np.float32)
        exact = age_image_exact(srgb_encode(rgb)[None], [5, 25], recipe, LIGHT)
        for years, ref in zip((5, 25), exact):
            ours = srgb_encode(evaluate(table, rgb, rates, years))
            from lightfade_addon.core.colour.colorimetry import srgb_decode
            assert delta_E_2000(lab(srgb_decode(ours)), lab(srgb_decode(ref[0]))).max() < limit

    def test_two_spectra_all_from_one_is_that_spectrum_alone(self):
        recipe = get_recipe("printed-paper")
        both = build_table(recipe, KEY + [("incandescent", False)], SMALL)
        alone = build_table(recipe, KEY, SMALL)
        rgb = _colours()
        rates = np.zeros((2, len(rgb)), np.float32)
        rates[0] = 1e6
        np.testing.assert_allclose(evaluate(both, rgb, rates, 8.0),
                                   evaluate(alone, rgb, rates[:1], 8.0), atol=2e-3)
        rates[[0, 1]] = rates[[1, 0]]
        assert np.abs(evaluate(both, rgb, rates, 8.0) - evaluate(alone, rgb, rates[1:], 8.0)
                      ).max() > 0.01


class TestHistory:
    def test_zero_years_shows_it_new_and_the_prior_light_gives_the_seen_colour_back(self):
        recipe = get_recipe("printed-paper")
        prior = Prior(10.0, (Light("daylight", False, 3000.0, 8.9, 365.0),))
        table = build_table(recipe, KEY, SMALL, prior=prior,
                            restore_kw=dict(settings=GridSettings(points=5, doses=17)))
        assert table.history and table.lost is not None and table.lost.shape == (5, 5, 5)
        seen = cube_colours(5, table.gamma)[::7].astype(np.float32)
        rates = np.zeros((1, len(seen)), np.float32)
        new = evaluate(table, seen, rates, 0.0)
        assert delta_E_2000(lab(new), lab(seen)).mean() > 1
        # under two spectra, an unlit texel reads the first spectrum's slot (its change
        # at no dose is the restoration, not nothing)
        two = build_table(recipe, KEY + [("incandescent", False)], SMALL, prior=prior,
                          restore_kw=dict(settings=GridSettings(points=5, doses=17)))
        np.testing.assert_allclose(evaluate(two, seen, np.zeros((2, len(seen)), np.float32),
                                            0.0), new, atol=2e-3)


class TestAtlas:
    def test_round_trip(self, paper):
        back = table_from_atlas(atlas_pixels(paper), paper.info())
        np.testing.assert_array_equal(back.values, paper.values)
        np.testing.assert_array_equal(back.unmix, paper.unmix)
        assert back.power == paper.power
        np.testing.assert_allclose(back.doses, paper.doses)

    def test_tiles_hold_one_blue_node_dose_and_slot_each(self, paper):
        L = atlas_layout(paper)
        P = L.P
        img = atlas_pixels(paper)
        slot, t, b, g, r = 0, paper.T - 1, 3, 2, 4
        np.testing.assert_array_equal(img[(slot * paper.T + t) * P + 1 + g, b * P + 1 + r, :3],
                                      paper.values[slot, t, b, g, r].astype(np.float32))
        # padding copies the edge: bilinear lookups at the tile's border stay inside it
        np.testing.assert_array_equal(img[(slot * paper.T + t) * P, b * P + 1 + r, :3],
                                      paper.values[slot, t, b, 0, r].astype(np.float32))
        # the unmixing's tiles, above the change's: blue node b at (b mod per_row, b div per_row)
        A = paper.unmix_side
        assert L.unmix_y == paper.slots * paper.T * P and L.height <= L.unmix_y + A * L.PA
        b = A - 1
        y0 = L.unmix_y + (b // L.per_row) * L.PA + 1
        x0 = (b % L.per_row) * L.PA + 1
        np.testing.assert_array_equal(img[y0 + g, x0 + r, :3],
                                      paper.unmix[b, g, r].astype(np.float32))


def test_tables_are_kept_on_disk(tmp_path, monkeypatch):
    from lightfade_addon.core.fading import cache
    from lightfade_addon.core.aging import tablebuild

    monkeypatch.setattr(cache, "_directory", tmp_path)
    recipe = get_recipe("dyed-fabric")
    first = load_or_build(recipe, KEY, SMALL)
    monkeypatch.setattr(tablebuild, "build_table", lambda *a, **k: pytest.fail("rebuilt"))
    again = load_or_build(recipe, KEY, SMALL)
    assert isinstance(again, ColourTable) and again.key == first.key
    np.testing.assert_array_equal(again.values, first.values)
