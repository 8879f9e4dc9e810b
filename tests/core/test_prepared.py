"""The numpy evaluator with per-texel preparation (core/aging/prepared.py) against the
plain evaluator it stands for (core/aging/colourtable.evaluate)."""

import numpy as np
import pytest

from lightfade_addon.core.aging import prepared as prep_module
from lightfade_addon.core.aging.colourtable import ColourTable, dose_nodes, evaluate, mix_resolution
from lightfade_addon.core.aging.prepared import (
    evaluate_prepared,
    prepare_texels,
    table_cells,
)


def random_table(S=1, T=12, N=5, A=7, history=False, seed=0):
    """A table of random (smooth enough) values: the evaluators' arithmetic, not physics."""
    rng = np.random.default_rng(seed)
    q = mix_resolution(S)
    slots = (q + 1) ** (S - 1)
    values = (rng.normal(0, 0.3, (slots, T, N, N, N, 3))).astype(np.float16)
    unmix = rng.uniform(-0.2, 1.2, (A, A, A, 3)).astype(np.float16)
    return ColourTable(values, dose_nodes(1e3, 4, T), 2.2, 4.0, 1e3, q, S, history, "k",
                       unmix, 1.6)


def texels(S, n=5000, seed=3):
    rng = np.random.default_rng(seed)
    rgb = rng.uniform(0, 1, (n, 3)).astype(np.float32) ** 2.2
    rates = np.exp(rng.normal(8, 2, (S, n))).astype(np.float32)
    rates[:, :50] = 0.0                                          # unlit texels
    return rgb, rates


@pytest.mark.parametrize("S", [1, 2, 3])
class TestAgainstEvaluate:
    def test_a_sequence_of_years_matches_each_time(self, S):
        """Years up and down, small and large steps: the band is reused where the dose
        node stays and evaluated again where it moved."""
        table = random_table(S)
        rgb, rates = texels(S)
        prep = prepare_texels(table, rates)
        cells = table_cells(table)
        for years in (25.0, 25.0, 25.3, 24.0, 3.0, 1e9, 0.01, 40.0):
            got = evaluate_prepared(table, prep, rgb, years, cells=cells)
            want = evaluate(table, rgb, rates, years)
            np.testing.assert_allclose(got, want, atol=2e-5, err_msg=f"{years} years")

    def test_zero_years_is_the_colour_itself(self, S):
        table = random_table(S)
        rgb, rates = texels(S)
        got = evaluate_prepared(table, prepare_texels(table, rates), rgb, 0.0)
        assert np.array_equal(got, rgb)

    def test_a_history_ages_at_zero_years(self, S):
        table = random_table(S, history=True)
        rgb, rates = texels(S)
        got = evaluate_prepared(table, prepare_texels(table, rates), rgb, 0.0)
        np.testing.assert_allclose(got, evaluate(table, rgb, rates, 0.0), atol=2e-5)
        assert not np.allclose(got, rgb)


class TestBand:
    def test_new_colours_need_a_reset_band(self):
        """The band belongs to the colours it was evaluated at: after a reset (t0 = -1)
        new colours match; a stale band does not (what the Blender cache guards)."""
        table = random_table(1)
        rgb, rates = texels(1)
        prep = prepare_texels(table, rates)
        evaluate_prepared(table, prep, rgb, 10.0)
        other = rgb[::-1].copy()
        stale = evaluate_prepared(table, prep, other, 10.0)
        assert not np.allclose(stale, evaluate(table, other, rates, 10.0), atol=1e-3)
        prep.t0[:] = -1
        np.testing.assert_allclose(evaluate_prepared(table, prep, other, 10.0),
                                   evaluate(table, other, rates, 10.0), atol=2e-5)

    def test_only_texels_whose_node_moved_are_evaluated_again(self, monkeypatch):
        """Nodes evaluated: none at the same years; one per texel whose node moved by
        one (the band's other end is kept); two per texel that jumped further."""
        table = random_table(1)
        rgb, rates = texels(1)
        prep = prepare_texels(table, rates)
        evaluate_prepared(table, prep, rgb, 10.0)
        counted = []
        real = prep_module._node

        def node(table, cells, cube, *args):
            counted.append(len(cube[0]))                 # texels of the cells looked up
            return real(table, cells, cube, *args)

        monkeypatch.setattr(prep_module, "_node", node)
        evaluate_prepared(table, prep, rgb, 10.0)
        assert counted == []
        before = prep.t0.copy()
        evaluate_prepared(table, prep, rgb, 10.5)
        moved = np.abs(prep.t0.astype(int) - before)
        assert 0 < sum(counted) < len(rgb) // 2
        assert sum(counted) == np.count_nonzero(moved == 1) + 2 * np.count_nonzero(moved > 1)
        counted.clear()
        before = prep.t0.copy()
        evaluate_prepared(table, prep, rgb, 10.0)                # back down
        moved = np.abs(prep.t0.astype(int) - before)
        assert sum(counted) == np.count_nonzero(moved == 1) + 2 * np.count_nonzero(moved > 1)
        np.testing.assert_allclose(evaluate_prepared(table, prep, rgb, 10.0),
                                   evaluate(table, rgb, rates, 10.0), atol=2e-5)

    @pytest.mark.parametrize("S", [1, 2])
    def test_blocks_where_every_texel_moved_match(self, monkeypatch, S):
        """Blocks whose every texel moved are refreshed as one slice: in blocks past
        the first, with some texels new (no band yet) among them, the result still
        matches."""
        monkeypatch.setattr(prep_module, "_BLOCK", 700)
        table = random_table(S)
        rgb, rates = texels(S)
        prep = prepare_texels(table, rates)
        cells = table_cells(table)
        evaluate_prepared(table, prep, rgb, 0.01, cells=cells)
        other = rgb.copy()
        other[::3] = rgb[::-3]                                   # new colours, no band yet
        prep.t0[::3] = -1
        before = prep.t0.copy()
        got = evaluate_prepared(table, prep, other, 1e9, cells=cells)
        np.testing.assert_allclose(got, evaluate(table, other, rates, 1e9), atol=2e-5)
        assert (prep.t0 != before)[700:].all()                   # past the first block

    def test_colour_count_must_match(self):
        table = random_table(1)
        rgb, rates = texels(1)
        with pytest.raises(ValueError, match="prepared texels"):
            evaluate_prepared(table, prepare_texels(table, rates), rgb[:10], 1.0)
