"""The aging table and its numpy evaluator (core/aging/table.py)."""

import numpy as np
import pytest

from lightfade_addon.core.fading.lattice import mix_lattice, simplex_interpolation
from lightfade_addon.core.aging.table import (
    AgingTable,
    Texels,
    evaluate,
    evaluate_change,
    key_pixels,
    mix_slots,
    simplex_slots,
    table_layout,
    table_pixels,
    texel_positions,
)


class TestSimplexSlots:
    @pytest.mark.parametrize("S,q", [(2, 4), (3, 2), (3, 4), (4, 2)])
    def test_same_vertices_and_weights_as_the_lattice(self, S, q):
        """Slots name the lattice rows of :func:`simplex_interpolation`'s vertices."""
        rng = np.random.default_rng(S * 10 + q)
        w = rng.dirichlet(np.ones(S), 500)
        slots, weights = simplex_slots(w, q)
        nodes, ref = simplex_interpolation(w, q)
        rows = mix_slots(S, q)
        np.testing.assert_array_equal(rows[slots], nodes)
        np.testing.assert_allclose(weights, ref, atol=1e-5)

    def test_interpolates_the_mixture_exactly(self):
        """Σ weight · lattice point is the mixture itself (barycentric, linear precision)."""
        w = np.random.default_rng(3).dirichlet(np.ones(3), 200)
        slots, weights = simplex_slots(w, 4)
        points = mix_lattice(3, 4)[mix_slots(3, 4)[slots]]          # (N, S, S)
        np.testing.assert_allclose((weights[..., None] * points).sum(1), w, atol=1e-5)

    def test_one_spectrum_is_slot_zero(self):
        slots, weights = simplex_slots(np.ones((4, 1)), 4)
        assert (slots == 0).all() and (weights == 1).all()


def _table(K=6, S=2, q=2, T=5, seed=0):
    rng = np.random.default_rng(seed)
    curves = rng.normal(0, 0.2, (K, mix_lattice(S, q).shape[0], T, 3)).astype(np.float32)
    curves[:, :, 0] = 0.0                                      # no change at zero dose
    # the table holds half-precision values (as a GPU may): compare with those
    return AgingTable.from_curves(curves, 1e6, S, q), curves.astype(np.float16).astype(
        np.float32)


class TestEvaluate:
    def test_dose_nodes_and_lerp(self):
        """At a node the table's value; halfway, the mean of the two nodes (linear in
        the node index, which is (dose / max)**(1/3) · (T - 1))."""
        table, curves = _table(S=1, q=2)
        T = table.T
        texels = Texels(np.array([2, 2], np.int32), np.array([[1e6, 1e6]], np.float32),
                        np.ones((3, 2), np.float32))
        pos = texel_positions(table, texels)
        at_node = evaluate_change(table, pos, (2 / (T - 1)) ** 3)           # node 2
        np.testing.assert_allclose(at_node[:, 0], curves[2, 0, 2], atol=1e-5)
        half = evaluate_change(table, pos, (2.5 / (T - 1)) ** 3)
        np.testing.assert_allclose(half[:, 0], 0.5 * (curves[2, 0, 2] + curves[2, 0, 3]),
                                   atol=1e-5)

    def test_mixture_weights_the_lattice_rows(self):
        """A texel lit half by each spectrum (q = 2) sits on the middle lattice row."""
        table, curves = _table(S=2, q=2)
        rate = np.array([[5e5], [5e5]], np.float32)
        texels = Texels(np.array([1], np.int32), rate, np.ones((3, 1), np.float32))
        change = evaluate_change(table, texel_positions(table, texels), 1.0)
        middle = [i for i, r in enumerate(mix_lattice(2, 2)) if abs(r[0] - 0.5) < 1e-9][0]
        np.testing.assert_allclose(change[:, 0], curves[1, middle, -1], atol=1e-5)

    def test_zero_change_returns_the_colour_and_alpha_is_kept(self):
        table, _ = _table(S=1)
        rgb = np.random.default_rng(1).uniform(0.1, 0.9, (10, 3)).astype(np.float32)
        texels = Texels.from_linear(np.zeros(10), np.zeros((1, 10)), rgb)   # unlit
        out = np.full((10, 4), 0.25, np.float32)
        evaluate(table, texels, 50.0, out=out)
        np.testing.assert_allclose(out[:, :3], rgb, atol=1e-5)
        assert (out[:, 3] == 0.25).all()

    def test_threaded_blocks_match_one_block(self, monkeypatch):
        from lightfade_addon.core.aging import table as mod

        table, _ = _table(S=2, q=2)
        rng = np.random.default_rng(2)
        n = 5000
        texels = Texels.from_linear(rng.integers(0, 6, n), rng.uniform(0, 1e5, (2, n)),
                                    rng.uniform(0.05, 0.95, (n, 3)))
        whole = evaluate(table, texels, 7.0)
        monkeypatch.setattr(mod, "_BLOCK", 333)
        np.testing.assert_array_equal(evaluate(table, texels, 7.0), whole)


def test_the_table_holds_half_precision_values():
    """Both evaluators read the same numbers: half precision, as a GPU may hold them."""
    curves = np.random.default_rng(4).normal(0, 1, (3, 1, 4, 3)).astype(np.float32)
    table = AgingTable.from_curves(curves, 1.0, 1, 2)
    np.testing.assert_array_equal(table.values, curves.astype(np.float16).astype(np.float32))
    assert np.abs(table.values - curves).max() > 0


class TestImages:
    def test_table_pixels_layout(self):
        """Run ``k · slots + s`` starts at row ``run // per_row``, column
        ``(run % per_row) · T`` (what the node group computes)."""
        table, _ = _table(K=200, S=2, q=2, T=5)
        W, H = table_layout(table)
        px = table_pixels(table)
        assert px.shape == (H, W, 4) and W % table.T == 0
        per_row = W // table.T
        for k, s, t in [(0, 0, 0), (13, 2, 4), (199, 1, 3)]:
            run = k * table.slots + s
            np.testing.assert_array_equal(
                px[run // per_row, (run % per_row) * table.T + t, :3], table.values[k, s, t])

    def test_keys_round_trip_through_8_bit_channels(self):
        key = np.array([0, 1, 255, 256, 65535, 65536, (1 << 24) - 1])
        px = key_pixels(key, (1, key.size)).astype(np.int64)
        np.testing.assert_array_equal((px[..., 0] << 16) | (px[..., 1] << 8) | px[..., 2],
                                      key[None])
        with pytest.raises(ValueError):
            key_pixels(np.array([1 << 24]), (1, 1))
