"""The colour table's unmixing ``Φ`` solved coarse to fine (core/aging/tablebuild.py
``_cube_solution``, core/fading/unmix.py ``continued_newton``): the plain solve's
solution, for much less work."""

import numpy as np
import pytest

from lightfade_addon.core.aging import tablebuild
from lightfade_addon.core.aging.colourtable import cube_colours
from lightfade_addon.core.colour.colorimetry import srgb_encode
from lightfade_addon.core.fading.recipes import get_recipe
from lightfade_addon.core.fading.unmix import Unmixer, get_unmixer


def _cube(side):
    return srgb_encode(cube_colours(side, 2.2)).reshape(side, side, side, 3)


def test_the_midpoints_are_the_cubic_through_four_nodes():
    """Exact on a cubic, at the ends (one-sided) and inside, along any axis."""
    x = np.linspace(0.0, 1.0, 7)
    cubic = lambda t: 2.0 - 3.0 * t + 5.0 * t ** 2 - 4.0 * t ** 3      # noqa: E731
    values = np.broadcast_to(cubic(x)[None, :, None], (2, 7, 3))
    fine = tablebuild._midpoints(values, 1)
    assert fine.shape == (2, 13, 3)
    np.testing.assert_allclose(fine[0, :, 0], cubic(np.linspace(0.0, 1.0, 13)), atol=1e-12)


@pytest.fixture(scope="module")
def fabric():
    """Dyed Fabric's unmixer (three colourants: a square system), a 25³ cube (solved
    as 7, 13, 25), and ``Φ`` there by the plain solve from the unmixer's table."""
    unmixer = get_unmixer(get_recipe("dyed-fabric"))
    cube = _cube(25)
    plain = tablebuild._solve(unmixer, cube.reshape(-1, 3), extended=True)
    return unmixer, cube, plain


def test_coarse_to_fine_is_the_plain_solve_at_every_node(fabric):
    """Every node within 1e-5 of the plain solve (both stop once their step is below
    1e-6; outside the gamut, where the steps shrink linearly, each lies within 2e-6 of
    the solution), inside the gamut and out, and in the cube's corners."""
    unmixer, cube, plain = fabric
    fast = tablebuild._cube_solution(unmixer, cube).reshape(-1, 3)
    assert np.any(plain < 0) and np.any(plain > 1) and np.any(np.all((plain > 0) & (plain < 1), 1))
    np.testing.assert_allclose(fast, plain, atol=1e-5, rtol=0)


def test_coarse_to_fine_evaluates_the_forward_model_far_less(fabric, monkeypatch):
    """From a fresh unmixer, the forward model is evaluated for at most 0.22 of the rows
    of the plain solve on this 25³ cube (0.17; the plain solve builds the unmixer's 17³
    table first; 0.29 with the exact Jacobian at every step), and the unmixer's table
    is not built."""
    _unmixer, cube, _plain = fabric
    rows = []

    def fresh():
        unmixer = Unmixer(get_recipe("dyed-fabric"))
        lab = unmixer.Lab

        def counted(c):
            rows[-1] += np.shape(c)[0]
            return lab(c)

        monkeypatch.setattr(unmixer, "Lab", counted)
        rows.append(0)
        return unmixer

    tablebuild._solve(fresh(), cube.reshape(-1, 3), extended=True)
    unmixer = fresh()
    tablebuild._cube_solution(unmixer, cube)
    assert unmixer._lut is None
    assert rows[1] < 0.22 * rows[0], rows


def test_fewer_colourants_keep_the_plain_solve(monkeypatch):
    """Bare Wood (one unmixed colourant: least squares, whose local minima depend on the
    start) is solved from the unmixer's table at every node, as the exact path is."""
    unmixer = get_unmixer(get_recipe("bare-wood"))
    assert not unmixer.square
    calls = []
    monkeypatch.setattr(type(unmixer), "continued",
                        lambda *a, **k: calls.append(1) or pytest.fail("continued"))
    cube = _cube(13)
    phi = tablebuild._cube_solution(unmixer, cube)
    np.testing.assert_array_equal(
        phi.reshape(-1, 1), tablebuild._solve(unmixer, cube.reshape(-1, 3), extended=True))
    assert not calls


def test_a_poor_jacobian_still_reaches_the_solution(fabric):
    """``continued_newton`` from a Jacobian of the wrong sign (each chord step would
    move away) takes the exact Jacobian once a step fails to shrink, and reaches
    ``extended_newton``'s solution."""
    from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, linear_srgb_to_XYZ, srgb_decode
    from lightfade_addon.core.fading.unmix import continued_newton, extended_newton

    unmixer, cube, plain = fabric
    rows = np.random.default_rng(3).choice(plain.shape[0], 300, replace=False)
    target = XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(cube.reshape(-1, 3)[rows])))
    start = plain[rows] + 0.01
    J = -unmixer.jacobian(np.clip(plain[rows], 0.0, 1.0))
    fast = continued_newton(unmixer.Lab, start.copy(), target, J)
    exact = extended_newton(unmixer.Lab, start.copy(), target)
    np.testing.assert_allclose(fast, exact, atol=1e-5, rtol=0)
