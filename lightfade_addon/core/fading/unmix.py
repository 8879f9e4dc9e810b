"""Unmixing: texel colours to colourant concentrations, by inverting the forward model.

Before exposure the medium is homogeneous, so its reflectance is Kubelka's single
layer over the substrate, exactly (:func:`forward_reflectance`). :class:`Unmixer`
inverts it: for a colour it finds the concentrations of the recipe's unmixed
colourants whose colour is nearest in CIELAB. The inversion is a projected
Gauss–Newton solve in CIELAB within [0, 1], started from the nearest of a table of
forward samples, then continued past the box on the forward model extended to first
order (:func:`extended_newton`):

    Lab_ext(c) = Lab(ĉ) + J(ĉ) · (c − ĉ),        ĉ = clip(c, 0, 1)            (U1)
    Φ(x) solves Lab_ext(Φ) = Lab(x),              c(x) = clip(Φ(x), 0, 1)     (U2)

Inside the gamut ``c = Φ``, the exact inverse. A colour outside it (darker than the
recipe's densest mixture, brighter than its paper) gets the concentrations it would
need, clipped: ``Φ`` is smooth (``Lab_ext`` is C¹ across the box's faces), so every
kink of ``c`` lies on the planes ``Φ_k = 0`` and ``Φ_k = 1``, which the colour table
resolves exactly (:mod:`..aging.colourtable`: it tabulates ``Φ`` over the colour cube
and the change over the concentrations). For one or two unmixed colourants ``Φ`` is
the least-squares solution of (U2). For images, a coarse 17³ table over encoded sRGB gives each unique colour
its starting point and Gauss–Newton steps make it exact: by default
(``refine=None``) every colour is solved to convergence (:data:`CONVERGED`), which
is what ``age-image --exact`` and the colour tables use, so the reference and the
tables are the same model; a fixed small ``refine`` is a cheaper approximation.
"""

from __future__ import annotations

import functools

import numpy as np

from ..colour.colorimetry import (XYZ_to_Lab, linear_srgb_to_XYZ, srgb_decode, srgb_encode,
                                  xyz_weights)
from .kubelka import kubelka_layer, over_ground
from .layered import kubelka_into
from .recipes import Recipe
from .spectra import WAVELENGTHS

__all__ = ["CONVERGED", "EXTENSION_STEPS", "STEP_TOLERANCE", "Unmixer", "bounded_gauss_newton",
           "continued_newton", "extended_newton", "forward_reflectance", "get_unmixer", "jacobian", "pseudo_inverse"]


#: Most Gauss–Newton steps of a converged solve (``refine=None``); rows leave as soon
#: as their step is below :data:`STEP_TOLERANCE` or the line search finds no descent.
CONVERGED = 80
#: Concentration step (volume fraction) below which a row counts as converged.
STEP_TOLERANCE = 1e-6
#: Most Newton steps past the box (:func:`extended_newton`).
EXTENSION_STEPS = 30
#: Nodes of the forward model's table for one unmixed colourant (:meth:`Unmixer.XYZ`),
#: spaced as ``(k / (n - 1))**2`` (denser near 0, where Kubelka–Munk is steepest):
#: within 5e-10 relative of the exact forward model, 3e-9 in CIELAB, twenty times faster.
CURVE_NODES = 513
#: Rows of the forward model evaluated at a time (:meth:`Unmixer.forward_XYZ`): the
#: block's seven (rows, W) arrays stay in cache, where whole-array temporaries of a
#: large solve went to memory (ten times slower).
FORWARD_ROWS = 1024


def forward_reflectance(recipe, c, wavelengths=WAVELENGTHS):
    """Reflectance of the unexposed medium for unmixed concentrations ``c``.

    Parameters
    ----------
    recipe : Recipe
    c : array_like, shape (N, Cu)
        Concentrations of ``recipe.unmixed`` (the fixed colourants are added).

    Returns
    -------
    ndarray, shape (N, W)
        ``over_ground(kubelka_layer(K, S, thickness), substrate)`` with ``K = f @ A``.
    """
    A, S, ground = recipe.optics(wavelengths)
    c = np.asarray(c, dtype=float)
    c = c.reshape(c.shape[0] if c.ndim > 1 else 1, len(recipe.unmixed))
    f = np.tile(recipe.base_concentrations(), (c.shape[0], 1))
    for k, name in enumerate(recipe.unmixed):
        f[:, recipe.index(name)] = c[:, k]
    return over_ground(*kubelka_layer(f @ A, f @ S, recipe.thickness), ground)


def jacobian(F, c, F_c=None, h=1e-5):
    """``dF / dc`` (N, K, Cu) of a row-wise ``F`` (N, Cu) -> (N, K), one-sided
    differences that stay inside [0, 1]."""
    c = np.asarray(c, dtype=float)
    F_c = F(c) if F_c is None else F_c
    J = np.empty(F_c.shape + (c.shape[1],))
    for k in range(c.shape[1]):
        step = np.where(c[:, k] + h <= 1.0, h, -h)
        ck = c.copy()
        ck[:, k] += step
        J[:, :, k] = (F(ck) - F_c) / step[:, None]
    return J


def pseudo_inverse(J):
    """``(J^T J + 1e-6 I)^-1 J^T`` (N, Cu, K): the damped Gauss–Newton step matrix."""
    Cu = J.shape[2]
    JtJ = np.einsum("nik,nil->nkl", J, J) + 1e-6 * np.eye(Cu)
    return np.linalg.solve(JtJ, np.swapaxes(J, 1, 2))


def bounded_gauss_newton(F, c, target, iterations, h=1e-5, jac=None, tol=0.0, step_tol=0.0):
    """Least squares ``|F(c) - target|^2`` per row over the box [0, 1], in place.

    Projected Gauss–Newton with an active set and a backtracking line search:
    variables held at a bound by the step are frozen for that step (their columns
    of the Jacobian dropped), and the step is halved up to three times until the
    residual drops, so solutions with colourants at 0 or 1 (out-of-gamut colours)
    converge instead of stalling at the start. Rows are independent: a row whose
    step fails is solved (from the same point the next step would be the same), so
    each step works on the rows that moved in the one before.

    Parameters
    ----------
    F : callable, F(x, rows): (n, Cu) -> (n, K)
        Row-wise; ``rows`` are the indices among ``c``'s N rows of ``x``'s n rows,
        for row-specific parameters.
    c : ndarray, shape (N, Cu)
        Start, in [0, 1]; overwritten with the solution.
    target : ndarray, shape (N, K)
    iterations : int
    jac : callable, jac(x, rows) -> (F(x, rows), dF/dx (n, K, Cu)), optional
        ``F`` with its Jacobian, instead of one-sided differences of step ``h``.
    tol : float
        Rows whose residual norm is at most ``tol`` are solved and leave the active set.
    step_tol : float
        Rows whose Gauss–Newton step changes no variable by more than ``step_tol`` take
        it without a line search and leave (least-squares solutions that do not reach
        ``tol``).

    Returns
    -------
    ndarray, shape (N, Cu)
        ``c``.
    """
    active = np.arange(c.shape[0])                              # rows still moving
    for _ in range(iterations):
        if active.size == 0:
            break
        ca, ta = c[active], target[active]

        if jac is None:
            F_c = F(ca, active)
        else:
            F_c, J = jac(ca, active)
        r = F_c - ta                                            # (n, K) residual
        cost = np.sum(r * r, axis=1)
        if tol > 0:                                             # solved rows leave
            keep = cost > tol * tol
            if not keep.all():
                active, ca, ta, F_c, r, cost = (a[keep] for a in (active, ca, ta, F_c, r, cost))
                J = J[keep] if jac is not None else None
                if active.size == 0:
                    break

        def Fa(x, rows=None, active=active):
            return F(x, active if rows is None else active[rows])

        if jac is None:
            J = jacobian(Fa, ca, F_c, h)
        delta = np.einsum("nki,ni->nk", pseudo_inverse(J), r)
        held = ((ca <= 0.0) & (delta > 0)) | ((ca >= 1.0) & (delta < 0))
        if held.any():
            J = np.where(held[:, None, :], 0.0, J)
            delta = np.einsum("nki,ni->nk", pseudo_inverse(J), r)
            delta[held] = 0.0
        moved = np.zeros(active.size, dtype=bool)
        settled = np.zeros(active.size, dtype=bool)             # converged: leave after this
        if step_tol > 0:
            settled = np.abs(delta).max(axis=1) <= step_tol     # a full step, no search
            ca[settled] = np.clip(ca[settled] - delta[settled], 0.0, 1.0)
        for alpha in (1.0, 0.5, 0.25, 0.125):
            todo = np.flatnonzero(~moved & ~settled)
            if todo.size == 0:
                break
            trial = np.clip(ca[todo] - alpha * delta[todo], 0.0, 1.0)
            better = np.sum((Fa(trial, todo) - ta[todo]) ** 2, axis=1) < cost[todo]
            ca[todo[better]] = trial[better]
            moved[todo[better]] = True
        c[active] = ca
        active = active[moved & ~settled]
    return c


def extended_newton(F, c, target, steps=EXTENSION_STEPS, h=1e-5, step_tol=STEP_TOLERANCE):
    """Solve ``Lab_ext(c) = target`` (Eq. U1; least squares for fewer than three
    colourants) by Gauss–Newton steps with ``J(ĉ)``, from ``c``, in place.

    Parameters
    ----------
    F : callable, F(x) -> (n, K)
        Row-wise forward model on [0, 1] (CIELAB of concentrations).
    c : ndarray, shape (N, Cu)
        Start (the bounded solution); overwritten with ``Φ``, unbounded.
    target : ndarray, shape (N, K)
    steps : int
        Most steps; rows leave once their step is below ``step_tol``.

    Returns
    -------
    ndarray, shape (N, Cu)
        ``c``.
    """
    active = np.arange(c.shape[0])
    for _ in range(steps):
        if active.size == 0:
            break
        ca = c[active]
        inner = np.clip(ca, 0.0, 1.0)
        F_c = F(inner)
        J = jacobian(F, inner, F_c, h)
        r = F_c + np.einsum("nki,ni->nk", J, ca - inner) - target[active]
        delta = np.einsum("nik,nk->ni", pseudo_inverse(J), r)
        c[active] = ca - delta
        active = active[np.abs(delta).max(axis=1) > step_tol]
    return c


def continued_newton(F, c, target, J, steps=EXTENSION_STEPS, h=1e-5, step_tol=STEP_TOLERANCE):
    """:func:`extended_newton`'s solution of Eq. U1 from a close start ``c`` and a close
    Jacobian ``J`` (a neighbour's): the same residual, cheaper steps, in place.

    The residual is :func:`extended_newton`'s: ``Lab(ĉ) + J(ĉ) · (c − ĉ) − target``
    with ``J(ĉ)``'s one-sided differences (:func:`jacobian`), needed only in the
    columns of the coordinates outside the box (``c − ĉ`` is 0 in the others), so a
    step evaluates the forward model once per row plus once per coordinate outside.
    Only the step's matrix differs: ``J`` with those exact columns (a chord method,
    which converges at the rate of ``J``'s error, about 1e-3 for a neighbour's at
    the colour cube's spacing), replaced by ``jacobian`` at ``ĉ`` for a row whose step
    did not shrink fourfold. Rows leave once their step is below ``step_tol``, as in
    :func:`extended_newton`: the solution is the same within that tolerance.

    Parameters
    ----------
    F : callable, F(x) -> (n, K)
        Row-wise forward model on [0, 1] (CIELAB of concentrations).
    c : ndarray, shape (N, Cu)
        Start; overwritten with ``Φ``, unbounded.
    target : ndarray, shape (N, K)
    J : ndarray, shape (N, K, Cu)
        Approximate Jacobians at the solution (not changed).
    steps : int
        Most steps.

    Returns
    -------
    ndarray, shape (N, Cu)
        ``c``.
    """
    J = np.array(J, dtype=float)
    active = np.arange(c.shape[0])
    last = np.full(c.shape[0], np.inf)                  # each row's previous step size
    fresh = np.zeros(c.shape[0], dtype=bool)            # rows taking jacobian() this step
    for _ in range(steps):
        if active.size == 0:
            break
        ca = c[active]
        inner = np.clip(ca, 0.0, 1.0)
        off = ca - inner                                # 0 inside the box
        F_c = F(inner)
        Ja = J[active]
        new = fresh[active]
        if new.any():
            Ja[new] = jacobian(F, inner[new], F_c[new], h)
        for k in range(c.shape[1]):                     # exact columns where outside
            rows = np.flatnonzero((off[:, k] != 0.0) & ~new)
            if rows.size:
                x = inner[rows]
                step = np.where(x[:, k] + h <= 1.0, h, -h)
                x[:, k] += step
                Ja[rows, :, k] = (F(x) - F_c[rows]) / step[:, None]
        J[active] = Ja
        r = F_c + np.einsum("nki,ni->nk", Ja, off) - target[active]
        delta = np.einsum("nik,nk->ni", pseudo_inverse(Ja), r)
        c[active] = ca - delta
        size = np.abs(delta).max(axis=1)
        fresh[active] = size > 0.25 * last[active]
        last[active] = size
        active = active[size > step_tol]
    return c


class Unmixer:
    """Inverse of the forward model for one recipe.

    Parameters
    ----------
    recipe : Recipe
        Its ``unmixed`` colourants are solved for.
    wavelengths : array_like
        Spectral grid.
    lut_size : int
        Nodes per axis of the encoded-sRGB lookup table.
    """

    def __init__(self, recipe, wavelengths=WAVELENGTHS, lut_size=17):
        self.recipe = recipe
        self.wavelengths = np.asarray(wavelengths, dtype=float)
        self.Cu = len(recipe.unmixed)
        self.M = xyz_weights(self.wavelengths)
        self._optics = _visible_optics(recipe, self.wavelengths, self.M)
        self.lut_size = lut_size
        self._lut = None
        # forward samples for the starting guesses
        axis = np.linspace(0.0, 1.0, 13) ** 1.5
        self._seeds = (np.stack(np.meshgrid(*[axis] * self.Cu, indexing="ij"), -1)
                       .reshape(-1, self.Cu) if self.Cu else np.zeros((1, 0)))
        self._curve = None
        if self.Cu == 1:            # a curve in colour space: tabulated once, exactly
            from scipy.interpolate import make_interp_spline

            nodes = np.linspace(0.0, 1.0, CURVE_NODES) ** 2
            self._curve = make_interp_spline(nodes, self._forward_XYZ(nodes[:, None]), k=3)
        self._seed_Lab = self.Lab(self._seeds)

    @property
    def square(self):
        """Whether Eq. U1 is a square system (three unmixed colourants, three CIELAB
        coordinates): Newton's steps then converge quadratically, and a few from the
        table (``refine``) are as good as converged. With fewer, a colour off the
        recipe's reach is a least-squares solution, where Gauss–Newton converges only
        linearly: only the converged solve (``refine=None``) agrees with it."""
        return self.Cu == 3

    def _forward_XYZ(self, c):
        """``forward_reflectance(recipe, c) @ M`` (N, 3), the same layer over the
        substrate evaluated fused, in blocks of :data:`FORWARD_ROWS` rows
        (:func:`.layered.kubelka_into`, its closed form), at the wavelengths the
        colour-matching functions weigh (the others add 0 to XYZ)."""
        Ad, Sd, K0, S0, ground, M = self._optics
        c = np.asarray(c, dtype=float)
        c = c.reshape(c.shape[0] if c.ndim > 1 else 1, self.Cu)
        n, W = c.shape[0], M.shape[0]
        out = np.empty((n, 3))
        rows = min(n, FORWARD_ROWS)
        Kd, Sd_, rho, tau, x, m, g = (np.empty((rows, W)) for _ in range(7))
        for s0 in range(0, n, rows):
            k = min(n, s0 + rows) - s0
            K, S, r, t, xk = Kd[:k], Sd_[:k], rho[:k], tau[:k], x[:k]
            np.matmul(c[s0:s0 + k], Ad, out=K)
            K += K0
            np.matmul(c[s0:s0 + k], Sd, out=S)
            S += S0
            kubelka_into(K, S, r, t, xk, m[:k], g[:k], thin=False)
            np.multiply(r, ground, out=xk)          # R = rho + tau² g / (1 - rho g)
            np.subtract(1.0, xk, out=xk)
            t *= t
            t *= ground
            t /= xk
            r += t
            np.matmul(r, M, out=out[s0:s0 + k])
        return out

    def XYZ(self, c):
        """XYZ (D65, Y of white = 1) of unmixed concentrations ``c`` (N, Cu).

        With one unmixed colourant, concentrations in [0, 1] read a cubic spline
        through :data:`CURVE_NODES` exact samples (within 5e-10 of the forward
        model): the many solver steps of colours off the recipe's curve stay cheap.
        """
        if self._curve is not None:
            c = np.asarray(c, dtype=float)
            col = c.reshape(-1)
            if col.size and col.min() >= 0.0 and col.max() <= 1.0:
                return self._curve(col)
        return self._forward_XYZ(c)

    def Lab(self, c):
        return XYZ_to_Lab(self.XYZ(c))

    def solve_Lab(self, Lab, iterations=12):
        """Concentrations (N, Cu) whose colour is nearest to ``Lab`` (N, 3)."""
        Lab = np.asarray(Lab, dtype=float).reshape(-1, 3)
        N = Lab.shape[0]
        if self.Cu == 0:
            return np.zeros((N, 0))
        from scipy.spatial import cKDTree

        _, nearest = cKDTree(self._seed_Lab).query(Lab)
        return self._gauss_newton(self._seeds[nearest].copy(), Lab, iterations)

    def jacobian(self, c, Lab_c=None, h=1e-5):
        """``d Lab / d c`` (N, 3, Cu) by one-sided differences inside [0, 1]."""
        return jacobian(self.Lab, c, Lab_c, h)

    def slope(self, c):
        """How the solution moves with the target colour: ``dc / dLab`` (N, Cu, 3).

        At a solution ``c`` of :meth:`solve_Lab` inside the gamut this is the
        inverse of :meth:`jacobian`; outside, the least-squares (projected) step.
        """
        return pseudo_inverse(self.jacobian(c))

    def _gauss_newton(self, c, Lab, iterations, h=1e-5):
        """``iterations`` steps, or to convergence (:data:`CONVERGED`) when None."""
        if iterations is None:
            return bounded_gauss_newton(lambda x, rows=None: self.Lab(x), c, Lab, CONVERGED,
                                        h, step_tol=STEP_TOLERANCE)
        return bounded_gauss_newton(lambda x, rows=None: self.Lab(x), c, Lab, iterations, h)

    def extended(self, rgb, encoded=False, steps=None):
        """``Φ`` (Eq. U2) of colours (N, 3), unbounded: the concentrations a colour
        needs on the forward model extended past [0, 1] (what the colour table
        tabulates; :meth:`unmix` is its clip).

        ``steps`` None: the bounded solve, then Newton steps past the box (as
        :meth:`unmix` converges); an int: at most that many Newton steps of Eq. U1 from
        the table of ``Φ`` (:attr:`lut`), each row stopping once converged: ``Φ`` is
        smooth, so its interpolation is a close start (the same solution, faster).
        """
        rgb = np.asarray(rgb, dtype=float).reshape(-1, 3)
        if self.Cu == 0:
            return np.zeros((rgb.shape[0], 0))
        return self._solve(rgb, encoded, steps, clip=False)

    def continued(self, rgb, start, J, encoded=False, steps=EXTENSION_STEPS):
        """:meth:`extended` (``steps`` an int) of colours (N, 3) from a close ``start``
        (N, Cu) and close Jacobians ``J`` (N, 3, Cu), a neighbouring colour's: the same
        solution of the square system (:attr:`square`) within :data:`STEP_TOLERANCE`,
        in fewer and cheaper steps (:func:`continued_newton`)."""
        rgb = np.asarray(rgb, dtype=float).reshape(-1, 3)
        e = np.clip(rgb if encoded else srgb_encode(np.clip(rgb, 0.0, 1.0)), 0.0, 1.0)
        target = XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(e)))
        c = np.array(start, dtype=float).reshape(rgb.shape[0], self.Cu)
        return continued_newton(self.Lab, c, target, J, steps)

    def solve_linear_srgb(self, rgb, iterations=12):
        """Concentrations for linear sRGB colours (N, 3) (exact solve, no table)."""
        return self.solve_Lab(XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float))), iterations)

    @property
    def lut(self):
        """The (n, n, n, Cu) table of ``Φ`` (Eq. U2, unbounded) over encoded sRGB, built
        on first use: ``Φ`` is smooth, so its trilinear interpolation is a close start
        inside the gamut and out."""
        if self._lut is None:
            n = self.lut_size
            axis = np.linspace(0.0, 1.0, n)
            enc = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
            phi = self._direct(XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(enc))))
            self._lut = phi.reshape(n, n, n, self.Cu)
        return self._lut

    def _direct(self, Lab):
        """``Φ`` of colours ``Lab`` (N, 3) without :attr:`lut`: the bounded solve from the
        nearest forward sample (:meth:`solve_Lab`), then Newton steps past the box."""
        return extended_newton(self.Lab, self.solve_Lab(Lab), Lab)

    def direct(self, rgb, encoded=False):
        """:meth:`extended` of colours (N, 3) solved as :attr:`lut`'s nodes are, without
        it (a few colours: cheaper than building it). For a square system
        (:attr:`square`, one solution per colour) the same ``Φ`` within
        :data:`STEP_TOLERANCE`."""
        rgb = np.asarray(rgb, dtype=float).reshape(-1, 3)
        if self.Cu == 0:
            return np.zeros((rgb.shape[0], 0))
        e = np.clip(rgb if encoded else srgb_encode(np.clip(rgb, 0.0, 1.0)), 0.0, 1.0)
        return self._direct(XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(e))))

    def _estimate(self, e):
        """The trilinear interpolation of :attr:`lut` at encoded colours ``e`` (N, 3)."""
        n = self.lut_size
        x = e * (n - 1)
        i = np.minimum(x.astype(np.int64), n - 2)
        f = x - i
        lut = self.lut
        out = np.zeros((e.shape[0], self.Cu))
        for bits in np.ndindex(2, 2, 2):
            w = np.ones(e.shape[0])
            for k, b in enumerate(bits):
                w = w * (f[:, k] if b else 1.0 - f[:, k])
            out += w[:, None] * lut[i[:, 0] + bits[0], i[:, 1] + bits[1], i[:, 2] + bits[2]]
        return out

    def unmix(self, rgb, encoded=False, refine=None):
        """Concentrations for colours (N, 3): ``clip(Φ, 0, 1)`` (Eq. U2).

        A table lookup, then solver steps and the clip.

        Parameters
        ----------
        rgb : array_like, shape (N, 3)
            Linear sRGB (or encoded sRGB with ``encoded=True``), clipped to [0, 1].
        refine : int or None
            None (the default): to convergence, the solution ``age-image --exact`` and
            the colour tables use (bounded Gauss–Newton steps, at most
            :data:`CONVERGED`, then Newton steps past the box, :func:`extended_newton`);
            an int: that many Newton steps of Eq. U1 from the table's trilinear
            estimate, a cheaper approximation (0: the estimate itself, a starting
            guess).
        """
        rgb = np.asarray(rgb, dtype=float).reshape(-1, 3)
        if self.Cu == 0:
            return np.zeros((rgb.shape[0], 0))
        return self._solve(rgb, encoded, refine, clip=True)

    def _solve(self, rgb, encoded, refine, clip):
        e = np.clip(rgb if encoded else srgb_encode(np.clip(rgb, 0.0, 1.0)), 0.0, 1.0)
        out = self._estimate(e)
        if refine is None or refine:
            target = XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(e)))
            if refine is None:                  # converged: bounded, then past the box
                bounded = self._gauss_newton(np.clip(out, 0.0, 1.0), target, None)
                out = extended_newton(self.Lab, bounded, target)
            else:                               # ``refine`` Newton steps of Eq. U1
                out = extended_newton(self.Lab, out, target, steps=refine)
        if clip:
            np.clip(out, 0.0, 1.0, out=out)
        return out


def _visible_optics(recipe, wavelengths, M):
    """``(A_u d, S_u d, K_0 d, S_0 d, ground, M)`` of :func:`forward_reflectance` at
    the wavelengths where the weights ``M`` (W, 3) are not all 0: the unmixed
    colourants' optical depths (Cu, W'), the fixed colourants' (W',), the substrate
    (W',) and ``M`` (W', 3)."""
    A, S, ground = recipe.optics(wavelengths)
    seen = np.flatnonzero(np.any(M != 0.0, axis=1))
    d = recipe.thickness
    unmixed = [recipe.index(name) for name in recipe.unmixed]
    base = recipe.base_concentrations()
    return (A[unmixed][:, seen] * d, S[unmixed][:, seen] * d, (base @ A)[seen] * d,
            (base @ S)[seen] * d, ground[seen], np.ascontiguousarray(M[seen]))


def get_unmixer(recipe, wavelengths=tuple(WAVELENGTHS)):
    """A cached :class:`Unmixer` per recipe's unexposed optics.

    Unmixing depends only on what :func:`forward_reflectance` reads (colourants,
    substrate, which are unmixed, the fixed concentrations, thickness): recipes that
    differ in sensitivity (Blue Wool class, beta), kinetics, yields or solver settings
    share one Unmixer, whose table is built once per process.
    """
    optics = (recipe.colourants, recipe.substrate, recipe.unmixed, recipe.fixed,
              recipe.thickness)
    return _unmixer(optics, tuple(wavelengths))


@functools.lru_cache(maxsize=16)
def _unmixer(optics, wavelengths):
    colourants, substrate, unmixed, fixed, thickness = optics
    recipe = Recipe(name="optics", colourants=colourants, substrate=substrate,
                    blue_wool=(None,) * len(colourants), unmixed=unmixed, fixed=fixed,
                    thickness=thickness)
    return Unmixer(recipe, np.asarray(wavelengths))
