"""Unmixing colours into colourant concentrations."""

from dataclasses import replace

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    XYZ_to_linear_srgb,
    linear_srgb_to_XYZ,
    delta_E_2000,
    srgb_encode,
)
from lightfade_addon.core.fading.recipes import RECIPES
from lightfade_addon.core.fading.unmix import Unmixer, forward_reflectance, get_unmixer


@pytest.fixture(scope="module")
def unmixer():
    return get_unmixer(RECIPES["printed-paper"])


class TestUnmixer:
    def test_exact_solve_inverts_the_forward_model(self, unmixer):
        c = np.random.default_rng(0).uniform(0, 1, (300, 3))
        c2 = unmixer.solve_Lab(unmixer.Lab(c))
        assert delta_E_2000(unmixer.Lab(c2), unmixer.Lab(c)).max() < 1e-6
        np.testing.assert_allclose(c2, c, atol=1e-6)

    def test_table_plus_refinement_is_close(self, unmixer):
        c = np.random.default_rng(1).uniform(0, 1, (500, 3))
        rgb = XYZ_to_linear_srgb(unmixer.XYZ(c))
        inside = np.all((rgb >= 0) & (rgb <= 1), axis=1)
        c2 = unmixer.unmix(rgb[inside])
        assert delta_E_2000(unmixer.Lab(c2), unmixer.Lab(c[inside])).max() < 0.1
        enc = unmixer.unmix(srgb_encode(rgb[inside]), encoded=True)
        np.testing.assert_allclose(enc, c2, atol=1e-9)

    def test_table_alone_interpolates_between_its_nodes(self, unmixer):
        """Without refinement a colour gets the trilinear blend of the table's eight nodes
        around it (of ``Φ``, clipped): on a node exactly that node, between nodes close
        to the solution."""
        n = unmixer.lut_size
        nodes = np.array([[3, 7, 11], [0, 16, 5], [15, 1, 9]])
        np.testing.assert_allclose(unmixer.unmix(nodes / (n - 1), encoded=True, refine=0),
                                   np.clip(unmixer.lut[tuple(nodes.T)], 0, 1), atol=1e-12)
        c = np.random.default_rng(2).uniform(0, 1, (300, 3))
        rgb = XYZ_to_linear_srgb(unmixer.XYZ(c))
        inside = np.all((rgb >= 0) & (rgb <= 1), axis=1)
        table = unmixer.unmix(rgb[inside], refine=0)
        assert np.median(delta_E_2000(unmixer.Lab(table), unmixer.Lab(c[inside]))) < 1.0

    def test_out_of_gamut_gets_the_nearest_reachable_mixture(self, unmixer):
        green = np.array([[0.0, 1.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])
        c = unmixer.unmix(green)
        assert np.all((c >= 0) & (c <= 1))
        np.testing.assert_allclose(c[1], 0.0, atol=1e-3)       # white: bare paper
        assert np.all(c[2] > 0.9)                               # black: the dyes near full
        # no mixture is closer to pure green than the one found
        grid = np.stack(np.meshgrid(*[np.linspace(0, 1, 9)] * 3, indexing="ij"), -1).reshape(-1, 3)
        from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, linear_srgb_to_XYZ

        target = XYZ_to_Lab(linear_srgb_to_XYZ(green[:1]))
        best = np.sqrt(np.min(np.sum((unmixer.Lab(grid) - target) ** 2, axis=1)))
        found = np.sqrt(np.sum((unmixer.Lab(c[:1]) - target) ** 2))
        assert found <= best + 0.1          # ΔE*ab to pure green, within 0.1 of a 9³ search

    def test_the_default_solve_is_converged(self, unmixer):
        """``refine=None`` (what ``--exact`` and the colour tables use) is the solution a
        far longer solve finds, inside the gamut and out, to 1e-3 in concentration; a
        few steps from the table of ``Φ`` come near it, the table alone does not."""
        enc = np.random.default_rng(4).uniform(0, 1, (400, 3))
        long = unmixer.unmix(enc, encoded=True, refine=400)
        assert np.abs(unmixer.unmix(enc, encoded=True) - long).max() < 1e-3
        assert np.abs(unmixer.unmix(enc, encoded=True, refine=2) - long).max() < 5e-3
        assert np.abs(unmixer.unmix(enc, encoded=True, refine=0) - long).max() > 2e-3

    def test_out_of_the_gamut_it_is_the_clip_of_the_extended_solution(self, unmixer):
        """Eq. U1–U2: ``Φ`` solves the first-order extension exactly, inside the gamut
        it is the exact inverse (no clip needed), and ``unmix`` is its clip."""
        from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, linear_srgb_to_XYZ
        from lightfade_addon.core.fading.unmix import jacobian

        rng = np.random.default_rng(8)
        rgb = np.concatenate([rng.uniform(0, 0.01, (50, 3)),          # darker than the ink
                              rng.uniform(0, 1, (150, 3)) ** 2.2])
        phi = unmixer.extended(rgb)
        out = np.any((phi < 0) | (phi > 1), axis=1)
        assert out.sum() > 50 and (~out).sum() > 20
        np.testing.assert_array_equal(unmixer.unmix(rgb), np.clip(phi, 0, 1))
        inner = np.clip(phi, 0, 1)
        L = unmixer.Lab(inner)
        ext = L + np.einsum("nki,ni->nk", jacobian(unmixer.Lab, inner, L), phi - inner)
        target = XYZ_to_Lab(linear_srgb_to_XYZ(rgb))
        assert np.abs(ext - target).max() < 1e-3                      # ΔE*ab
        assert np.abs(unmixer.Lab(phi[~out]) - target[~out]).max() < 1e-3

    def test_the_extended_solution_is_smooth_across_the_faces(self, unmixer):
        """Along a line through a gamut face ``Φ`` keeps its slope (C¹: second
        differences stay at the size of the interior's), where the bounded solution
        (the nearest reachable mixture) turns a corner."""
        from lightfade_addon.core.colour.colorimetry import linear_srgb_to_XYZ, XYZ_to_Lab

        s = np.linspace(0.0, 1.0, 81)[:, None]
        rgb = (1 - s) * np.array([0.05, 0.05, 0.05]) + s * np.array([0.0015, 0.002, 0.001])
        phi = unmixer.extended(rgb)
        bounded = np.clip(phi, 0, 1)
        assert np.any(phi > 1) and np.any(phi < 1)                   # the line crosses a face
        curvature = np.abs(np.diff(phi, 2, axis=0)).max()
        assert curvature < 0.25 * np.abs(np.diff(bounded, 2, axis=0)).max()

    def test_continuous_across_the_gamut_boundary(self, unmixer):
        """Along lines from inside the gamut far out of it the solution moves in steps
        of the size of the colour's: no jump to another mixture at the boundary."""
        from lightfade_addon.core.colour.colorimetry import srgb_decode

        t = np.linspace(0.0, 1.0, 201)[:, None]
        for start, end in (([0.5, 0.45, 0.4], [0.0, 1.0, 0.0]),      # to pure green
                           ([0.5, 0.45, 0.4], [0.0, 0.05, 0.9]),     # to a deep blue
                           ([0.3, 0.25, 0.2], [0.0, 0.0, 0.0])):     # to black
            enc = np.array(start) + t * (np.array(end) - np.array(start))
            c = unmixer.unmix(enc, encoded=True)
            inside = np.linalg.norm(unmixer.Lab(c) - XYZ_to_Lab(
                linear_srgb_to_XYZ(srgb_decode(enc))), axis=1) < 0.5
            assert inside[0] and not inside[-1]
            assert np.abs(np.diff(c, axis=0)).max() < 0.05, (start, end)

    def test_recipe_with_nothing_to_unmix(self):
        u = Unmixer(replace(RECIPES["bare-wood"], colourants=("lignin", "quinone"),
                            unmixed=(), blue_wool=(1.0, None)))
        assert u.unmix(np.full((4, 3), 0.5)).shape == (4, 0)


def test_forward_reflectance_of_nothing_is_the_substrate():
    r = RECIPES["dyed-fabric"]
    _, _, ground = r.optics()
    np.testing.assert_allclose(forward_reflectance(r, np.zeros((1, 3)))[0], ground, atol=1e-12)


@pytest.mark.parametrize("name", ["printed-paper", "bare-wood"])
def test_the_fused_forward_model_is_the_plain_one_in_every_block(name):
    """The blocked, visible-wavelength evaluation equals ``forward_reflectance @ M``
    on rows across several blocks (the last one short), fixed colourants included
    (bare wood's lignin), inside the box and past its top."""
    from lightfade_addon.core.fading.unmix import FORWARD_ROWS

    u = get_unmixer(RECIPES[name])
    c = np.random.default_rng(4).uniform(0.0, 1.3, (2 * FORWARD_ROWS + 37, u.Cu))
    c[:2] = [[0.0], [1.0]]
    exact = forward_reflectance(u.recipe, c) @ u.M
    np.testing.assert_allclose(u._forward_XYZ(c), exact, rtol=1e-12, atol=1e-15)


def test_recipes_of_the_same_optics_share_one_unmixer_and_others_do_not():
    """Sensitivity, kinetics and solver settings do not change unmixing: one table."""
    paper = RECIPES["printed-paper"]
    assert get_unmixer(replace(paper, name="x", blue_wool=(1, 1, 1), kinetics="paper",
                               layers=64)) is get_unmixer(paper)
    assert get_unmixer(replace(paper, thickness=0.5)) is not get_unmixer(paper)
    assert get_unmixer(replace(paper, substrate=RECIPES["bare-wood"].substrate)) \
        is not get_unmixer(paper)


@pytest.fixture(scope="module")
def wood():
    return get_unmixer(RECIPES["bare-wood"])


class TestOneColourant:
    """Bare wood unmixes one colourant: its colours lie on a curve in CIELAB."""

    def test_the_tabulated_curve_is_the_forward_model(self, wood):
        c = np.concatenate([np.linspace(0, 1e-3, 50), np.random.default_rng(3).uniform(
            0, 1, 500)])[:, None]
        exact = forward_reflectance(wood.recipe, c) @ wood.M
        np.testing.assert_allclose(wood.XYZ(c), exact, rtol=1e-8)
        outside = np.array([[-0.2], [1.3]])          # past the box: the model itself
        np.testing.assert_allclose(wood.XYZ(outside),
                                   forward_reflectance(wood.recipe, outside) @ wood.M)

    def test_it_is_not_square_and_cmy_is(self, wood):
        assert not wood.square and get_unmixer(RECIPES["printed-paper"]).square
