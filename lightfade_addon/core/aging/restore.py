"""Textures that are already old: the colourants before ``years`` of light, by inversion.

A photograph of a faded poster or rug already shows years of light. :func:`restore`
inverts :class:`.aging.TextureAger`'s model. A texel of original colour ``XYZ_0``
with unmixed concentrations ``c0 = unmix(XYZ_0)`` is seen, after the dose ``d``, as

    XYZ_seen = XYZ_0 · exp(change(c0, d)),    change = log XYZ_aged(c0, d) - log XYZ(c0)

with ``log XYZ_aged`` the grid's spline over the concentrations (:meth:`.grid.FadeGrid
.spline`). For a colour inside the recipe's gamut ``XYZ_0 = XYZ(c0)``, so the seen
colour is ``XYZ_aged(c0, d)``: a function of the three concentrations alone. The
inversion, per distinct seen colour and dose level, is therefore

1. **a solve on the grid alone**: bounded Gauss–Newton (:func:`.unmix.bounded_gauss_newton`)
   on ``Lab(XYZ_aged(c0, d)) - Lab_seen`` with its exact Jacobian. ``XYZ_aged`` at one
   dose per row is evaluated from the spline's coefficients directly (:class:`_AgedAt`:
   the 4³ basis weights of each row and their derivatives times one coefficient table
   per dose, linear between its two dose nodes), not along the whole dose axis as aging
   needs it, and with no Kubelka–Munk evaluation. The solve starts from an inverse table
   (the same solve on a 13³ lattice of encoded sRGB per dose, interpolated trilinearly,
   :func:`_inverse_starts`) when the texture has enough colours per dose for it to pay,
   else from the seen colour's own concentrations in the unmixer's table; a colour stops
   at a mismatch of ΔE*ab 0.05 or a step below 0.001 in concentration;
2. **a polish with the aging's own unmixing**: a fixed-point step
   ``c0 = unmix(XYZ_seen / exp(change(c0, d)))`` (:meth:`.unmix.Unmixer.unmix`, as
   :class:`.aging.TextureAger` unmixes), which also places colours outside the recipe's
   gamut, whose detail rides on the ratio.

The restored pixel is ``XYZ_seen / exp(change(c0, d))``: texture detail survives, and
aging it again by the same light and years gives the seen image back. A texture with
more distinct colours than aging unmixes one by one (:data:`.texels.UNMIX_BUDGET`:
16-bit and float photographs) is solved per 8-bit colour, each texel keeping its own
detail through the ratio.

What is lost
------------
A texel is *lost* when the seen colour no longer tells its original apart: originals
that differ visibly before the light (more than ΔE00 :data:`LOST_APART` = 2 from the
restored one) end up within the seen image's own precision of it after the light, so
that the image cannot say which of them it shows and the restoration is expected to
be off by more than ΔE00 2. Where the inversion is merely hard (many iterations, a
start far from the answer) but the forward map keeps originals apart, nothing is lost.

The seen image holds each colour to :data:`PRECISION` (half a step of 8-bit encoded
sRGB per channel, ΔE00 0.1–0.4: the rounding of the file it came from). The
originals it cannot tell apart are the image of that rounding box under the inverse
of the forward map at the restored original (:func:`_uncertainty`):

* the forward map's Jacobian ``J = d Lab_aged / d Lab_0`` (3 × 3): the colour's own
  change ``d log XYZ_0`` plus what the concentrations bring,
  ``d change / d c0 · d c0 / d Lab_0`` (the grid's spline derivative and the unmixer's
  slope, :meth:`.unmix.Unmixer.slope`), carried between Lab and ``log XYZ`` by their
  own Jacobians; where the light has erased a dye (two magentas that both fade to the
  same grey) ``J`` is (nearly) singular;
* ``spread`` is the RMS ΔE00 of ``J⁻¹ · d Lab_seen / d sRGB · δ`` over the rounding
  box ``δ`` (ΔE00 as a local metric, ``ΔE00² ≈ dLabᵀ G(Lab) dLab`` with ``G`` at
  the original from CIEDE2000 itself, :func:`_metric`): how far from the truth a
  restoration lands on average from the seen image's rounding alone;
* ``lost = spread > LOST_APART``: the originals the seen colour stands for lie, RMS,
  more than ΔE00 2 from the restored one.

The Jacobian sees the aging near the restored original only. Where it already
shrinks differences (``spread`` above ΔE00 0.5) the solve is repeated from starts
ΔE00 6 away along the most shrunk direction, both ways (:func:`_other_original`): a
displayable original more than ΔE00 2 away that aging (with its own unmixing) takes to
the seen colour as well, to the seen colour's rounding, is a fold of the forward map,
and the texel is lost too.

One unmixed colourant (bare wood: the extractive) makes the recipe's colours a curve,
and a colour off it (a sky blue) a least-squares solution that jumps from one end of
the curve to the other between nearby colours. The grid's solve then only starts the
polish, which runs to a fixed point (:func:`_polish`), and a fold need not show in
``spread`` (a sky blue with none of the extractive and a grey with all of it fade to
one colour): every such colour is probed along the whole curve (:func:`_fixed_points`).

Also lost: texels that no displayable original explains (the original the inversion
finds lies more than ΔE00 2 outside [0, 1]: a history the photograph cannot have had,
such as far more light than it received); they keep the nearest displayable colour.

Not flagged: a seen colour on the edge of [0, 1] may be an aged colour the gamut rule
(:mod:`.gamut`) pulled in, and the restoration then stays on the near side of the
truth; the photograph cannot tell by how much, and most such pixels (camera-clipped
blacks and whites, aged colours barely outside) restore within ΔE00 2, so they are
not reported as lost.

Texels no light fell on come back unchanged and are never lost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fading.cache import load_or_build
from ..colour.colorimetry import (
    checked_rgb,
    XYZ_to_Lab,
    XYZ_to_linear_srgb,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
    srgb_encode,
)
from ..fading.gridbuild import XYZ_FLOOR
from ..colour.gamut import encode_in_gamut, into_gamut, out_of_gamut
from ..fading.grid import GridSettings
from ..fading.lattice import grid_max_dose, simplex_interpolation
from ..fading.lights import Light, dose_rates, spectra_keys
from ..fading.recipes import get_recipe
from ..fading.spectra import WAVELENGTHS, light_spectrum
from . import texels
from .texels import _codes, _decode, _distinct, aging_refine
from ..fading.unmix import bounded_gauss_newton, get_unmixer, pseudo_inverse

__all__ = ["LOST_APART", "PRECISION", "Prior", "Restored", "restore"]

#: ΔE00 from the restored original within which the seen image must still pin the
#: truth: a texel whose seen colour stands for originals spread (RMS) further is lost.
LOST_APART = 2.0
#: Precision of a seen colour, encoded sRGB per channel: half a step of 8 bits.
PRECISION = 0.5 / 255
#: Gauss–Newton iterations of the inversion on the grid.
_ITERATIONS = 12
#: Mismatch (ΔE*ab) at which a colour's solve stops (the polish below refines it).
_TOLERANCE = 0.05
#: ... or at which its concentrations move less than this in a step.
_STEP_TOLERANCE = 1e-3
#: Fixed-point steps with the aging's own unmixing after it, when that unmixing is
#: square (:attr:`.unmix.Unmixer.square`) ...
_POLISH = 1
#: ... and at most this many otherwise (bare wood), to a fixed point: rows leave when
#: their concentrations move less than :data:`_FIXED_TOLERANCE`.
_FIXED_POINT = 30
_FIXED_TOLERANCE = 1e-4
#: Samples of a one-colourant curve and bisections of each crossing that look for a
#: second original (:func:`_fixed_points`).
_CURVE_PROBES = 9
_BISECTIONS = 8
#: Nodes per axis of the inverse table that starts the solves (:func:`_inverse_starts`),
#: built when there are this many times its nodes of colours per dose.
_INVERSE_NODES = 13
_INVERSE_PAYS = 2
#: Distinct (colour, dose level) rows inverted per block (bounds the temporaries:
#: about 4 kB a row).
_BLOCK = 1 << 13
#: Step (ΔE*ab, and in log XYZ) of the finite differences of the lost test.
_H_LAB = 0.05
_H_LOG = 1e-4
#: Step in concentration of the unmixer's slope (as :func:`.unmix.jacobian`).
_H_C = 1e-5
#: Texels whose spread exceeds this ΔE00 are searched for another original ...
_PROBE = 0.5
#: ... from starts this far (ΔE00 in the original) along the collapsing direction.
_PROBE_STEP = 3 * LOST_APART


@dataclass(frozen=True)
class Prior:
    """A texture's own history: it is already ``years`` old under ``lights``.

    Attributes
    ----------
    years : float
        Age of the texture as photographed, >= 0.
    lights : tuple of Light
        The light it aged under (each with its schedule).
    exposure : array_like, optional
        Relative exposure per texel (as for :class:`.aging.TextureAger`); uniform
        by default.
    """

    years: float
    lights: tuple = (Light(),)
    exposure: object = None


@dataclass
class Restored:
    """What :func:`restore` returns.

    Attributes
    ----------
    image : ndarray, shape like the input
        The estimated new texture, in [0, 1] in the input's encoding.
    lost : ndarray of bool, shape of the input without the channel axis
        Texels whose original the light made indistinguishable (``spread >``
        :data:`LOST_APART`, or another original as good found further away) or that
        no displayable original explains (the module docstring).
    spread : ndarray, shape of ``lost``
        Per texel, the RMS ΔE00 between the restored original and the originals the
        seen colour cannot tell from it (0 where no light fell).
    """

    image: np.ndarray
    lost: np.ndarray
    spread: np.ndarray

    @property
    def lost_count(self):
        """Number of lost texels."""
        return int(np.count_nonzero(self.lost))

    @property
    def lost_fraction(self):
        """Share of the texels that are lost, in [0, 1] (0 for an empty texture)."""
        return self.lost_count / max(self.lost.size, 1)


def log_initial(grid, unmixer, c):
    """``log XYZ_initial`` of unmixed concentrations ``c`` when ``grid`` wants it."""
    if grid.initial is None:
        return None
    return np.log(np.maximum(unmixer.XYZ(c), XYZ_FLOOR))


def _log_XYZ(unmixer, c):
    return np.log(np.maximum(unmixer.XYZ(c), XYZ_FLOOR))


def _basis(x, t, k):
    """B-spline basis of degree ``k`` on knots ``t`` at ``x`` (n,): the first of the
    ``k + 1`` non-zero functions' indices (n,), their values and their derivatives
    (n, k + 1) each.

    Cox–de Boor recursion (Piegl and Tiller, *The NURBS Book*, algorithms A2.2 and
    A2.3); ``x`` is clipped into the spline's base interval.
    """
    n_basis = t.size - k - 1
    x = np.clip(x, t[k], t[n_basis])
    i = np.clip(np.searchsorted(t, x, side="right") - 1, k, n_basis - 1)
    N = np.zeros((x.size, k + 1))
    N[:, 0] = 1.0
    left = np.empty((x.size, k + 1))
    right = np.empty((x.size, k + 1))
    below = N[:, :1].copy()
    for j in range(1, k + 1):
        below = N[:, :j].copy()                         # the degree j - 1 values
        left[:, j] = x - t[i + 1 - j]
        right[:, j] = t[i + j] - x
        saved = np.zeros(x.size)
        for r in range(j):
            temp = N[:, r] / (right[:, r + 1] + left[:, j - r])
            N[:, r] = saved + right[:, r + 1] * temp
            saved = left[:, j - r] * temp
        N[:, j] = saved
    dN = np.zeros_like(N)
    if k > 0:
        # dN_{m,k} = k (N_{m,k-1} / (t_{m+k} - t_m) - N_{m+1,k-1} / (t_{m+k+1} - t_{m+1}))
        for r in range(k + 1):
            m = i - k + r
            if r >= 1:
                dN[:, r] += k * below[:, r - 1] / (t[m + k] - t[m])
            if r <= k - 1:
                dN[:, r] -= k * below[:, r] / (t[m + k + 1] - t[m + 1])
    return i - k, N, dN


class _AgedAt:
    """``log XYZ_aged`` of concentrations at each row's own dose and light mix.

    The grid's spline (:meth:`.grid.FadeGrid.spline`) is linear in its values, so at
    one dose per row it is the spline basis of the row's concentrations times the
    coefficients at the row's two dose nodes (linear between them, as
    :meth:`.grid.FadeGrid.log_change`) and light-mix vertices. Below the first dose
    node the change is interpolated from exactly zero, as aging does.

    Parameters
    ----------
    grid : FadeGrid
    unmixer : Unmixer
    dose : ndarray, shape (N,)
        lux·h per row.
    mix : ndarray, shape (N, S), optional
        Dose share of each light spectrum per row.
    """

    def __init__(self, grid, unmixer, dose, mix=None):
        self.grid, self.unmixer = grid, unmixer
        M, T = grid.change.shape[:2]
        self.i, self.f = grid.dose_position(dose)
        N = self.i.size
        if mix is None:
            self.nodes, self.wm = np.zeros((N, 1), dtype=np.int64), np.ones((N, 1))
        else:
            self.nodes, self.wm = simplex_interpolation(np.asarray(mix, float), grid.q)
        self.table = None
        if not grid.axes:
            return
        spline = grid.spline()
        self.t = [np.asarray(t, dtype=float) for t in spline.t]
        self.k = [int(k) for k in np.broadcast_to(spline.k, (len(grid.axes),))]
        size = spline.c.shape[:-1]
        self.n_coef = int(np.prod(size))
        self.strides = [int(np.prod(size[a + 1:])) for a in range(len(size))]
        self.M = M
        C = np.asarray(spline.c, dtype=float).reshape(self.n_coef, M, T, 3)
        # one coefficient table per distinct dose position, linear between its two dose
        # nodes: (position, mix node, coefficient) rows of 3
        positions, self.position = np.unique(np.stack([self.i, self.f], 1), axis=0,
                                             return_inverse=True)
        self.position = self.position.reshape(-1)
        ip, fp = positions[:, 0].astype(np.int64), positions[:, 1]
        table = ((1 - fp)[:, None, None, None] * np.moveaxis(C[:, :, ip], 2, 0)
                 + fp[:, None, None, None] * np.moveaxis(C[:, :, ip + 1], 2, 0))
        self.table = np.ascontiguousarray(np.swapaxes(table, 1, 2)).reshape(-1, 3)
        self.first_node = np.ascontiguousarray(np.swapaxes(C[:, :, 0], 0, 1)).reshape(-1, 3)

    def _basis_weights(self, c, derivative):
        """Each row's coefficient indices (n, B) and basis weights (n, 1 + Cu, B) (with
        ``derivative`` their derivatives along each axis in rows 1...)."""
        n, Cu = c.shape
        flat = np.zeros((n, 1), dtype=np.int64)
        W = np.ones((n, 1 + Cu if derivative else 1, 1))
        for a, (t, k, stride) in enumerate(zip(self.t, self.k, self.strides)):
            first, values, slopes = _basis(c[:, a], t, k)
            index = (first[:, None] + np.arange(k + 1)) * stride
            flat = (flat[:, :, None] + index[:, None, :]).reshape(n, -1)
            along = np.repeat(values[:, None, :], W.shape[1], axis=1)
            if derivative:
                along[:, 1 + a] = slopes
            W = (W[:, :, :, None] * along[:, :, None, :]).reshape(n, W.shape[1], -1)
        return flat, W

    def _evaluate(self, c, rows, derivative=False):
        """``log XYZ_aged`` (n, 3) of concentrations ``c`` for ``rows``, and with
        ``derivative`` its derivative in ``c`` (n, 3, Cu), else None."""
        c = np.clip(np.asarray(c, dtype=float), 0.0, 1.0)
        n = c.shape[0]
        i, f = self.i[rows], self.f[rows]
        nodes, wm = self.nodes[rows], self.wm[rows]
        if self.table is None:                      # nothing unmixed: one change per dose
            ch = self.grid.change.astype(float)
            out = np.zeros((n, 3))
            for v in range(nodes.shape[1]):
                m = nodes[:, v]
                out += wm[:, v, None] * ((1 - f)[:, None] * ch[m, i] + f[:, None] * ch[m, i + 1])
            return out + _log_XYZ(self.unmixer, c), None
        flat, W = self._basis_weights(c, derivative)
        position = self.position[rows] * self.M
        out = np.zeros((n, W.shape[1], 3))
        for v in range(nodes.shape[1]):
            at = ((position + nodes[:, v]) * self.n_coef)[:, None] + flat
            g = np.take(self.table, at, axis=0)                              # (n, B, 3)
            out += (W if nodes.shape[1] == 1 else W * wm[:, v, None, None]) @ g
        value = out[:, 0]
        below = np.flatnonzero(i == 0)
        if below.size:
            # below the first dose node the change rises from exactly 0, as aging has it:
            # the spline's value at dose 0 is replaced by the exact unexposed colour
            at0 = flat[below]
            first = np.zeros((below.size, 3))
            for v in range(nodes.shape[1]):
                g0 = np.take(self.first_node, (nodes[below, v] * self.n_coef)[:, None] + at0,
                             axis=0)
                first += wm[below, v, None] * np.einsum("nb,nbc->nc", W[below, 0], g0)
            value[below] += (1 - f[below])[:, None] * (
                _log_XYZ(self.unmixer, c[below]) - first)
        if self.grid.initial is None:               # a spline of the change alone
            value = value + _log_XYZ(self.unmixer, c)
        return value, (np.swapaxes(out[:, 1:], 1, 2) if derivative else None)

    def with_jacobian(self, c, rows=slice(None)):
        """``log XYZ_aged`` (n, 3) and its derivative in ``c`` (n, 3, Cu)."""
        return self._evaluate(c, rows, derivative=True)

    def __call__(self, c, rows=slice(None)):
        """``log XYZ_aged`` (n, 3) of concentrations ``c`` (n, Cu) for ``rows``."""
        return self._evaluate(c, rows)[0]

    def log_ratio(self, c, rows=slice(None)):
        """``change(c, dose)`` (n, 3): ``log(XYZ_aged / XYZ_initial)`` as aging applies it."""
        c = np.clip(np.asarray(c, dtype=float), 0.0, 1.0)
        return self(c, rows) - _log_XYZ(self.unmixer, c)


def _encoded(flat, encoding):
    return flat if encoding == "srgb" else srgb_encode(np.clip(flat, 0.0, 1.0))


def _dLab_dlogXYZ(XYZ):
    """``d Lab / d log XYZ`` (n, 3, 3) by forward differences."""
    Lab = XYZ_to_Lab(XYZ)
    J = np.empty(XYZ.shape + (3,))
    for k in range(3):
        step = XYZ.copy()
        step[:, k] *= np.exp(_H_LOG)
        J[:, :, k] = (XYZ_to_Lab(step) - Lab) / _H_LOG
    return J


def _metric(Lab):
    """CIEDE2000 as a local metric: ``G`` (n, 3, 3) with ``ΔE00² ≈ dᵀ G d`` for small
    Lab differences ``d``, from CIEDE2000 itself (finite differences of step
    :data:`_H_LAB`), symmetric positive definite."""
    n = Lab.shape[0]
    h = _H_LAB
    eye = np.eye(3) * h
    sq = np.empty((n, 3))
    for k in range(3):
        sq[:, k] = delta_E_2000(Lab, Lab + eye[k]) ** 2
    G = np.empty((n, 3, 3))
    for a in range(3):
        G[:, a, a] = sq[:, a] / h ** 2
        for b in range(a + 1, 3):
            both = delta_E_2000(Lab, Lab + eye[a] + eye[b]) ** 2
            G[:, a, b] = G[:, b, a] = (both - sq[:, a] - sq[:, b]) / (2 * h ** 2)
    # symmetric; its eigenvalues floored just above 0 (rounding near the neutral axis)
    values, vectors = np.linalg.eigh(G)
    values = np.maximum(values, 1e-6 * values.max(axis=1, keepdims=True))
    return np.einsum("nij,nj,nkj->nik", vectors, values, vectors)


def _dLab_dencoded(lin):
    """``d Lab / d encoded sRGB`` (n, 3, 3) at linear sRGB colours ``lin``, by one-sided
    differences that stay inside [0, 1]."""
    e = srgb_encode(np.clip(lin, 0.0, 1.0))
    Lab = XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(e)))
    J = np.empty(e.shape + (3,))
    h = 1e-4
    for k in range(3):
        step = e.copy()
        dk = np.where(e[:, k] + h <= 1.0, h, -h)
        step[:, k] += dk
        J[:, :, k] = (XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(step))) - Lab) / dk[:, None]
    return J


def _uncertainty(aged, rows, c0, XYZ_seen, unmixer, precision):
    """How well the seen colours pin their restored originals (the module docstring).

    Parameters
    ----------
    aged : _AgedAt
    rows : ndarray of int
        The rows of ``aged`` (doses, mixes) of ``c0``.
    c0 : ndarray, shape (n, Cu)
        Restored concentrations.
    XYZ_seen : ndarray, shape (n, 3)
        The seen colours.
    precision : float
        Half a step of the seen image's values, in encoded sRGB.

    Returns
    -------
    spread : ndarray, shape (n,)
        RMS ΔE00 between the restored original and those the seen colour's rounding
        box stands for.
    log_ratio : ndarray, shape (n, 3)
        The change ``log(XYZ_aged / XYZ_initial)`` at ``c0``.
    direction : ndarray, shape (n, Cu)
        The step of concentrations of the original difference the aging shrinks most,
        ΔE00 1 in the original.
    seen : ndarray, shape (n,)
        The seen colour's rounding, RMS ΔE*ab.
    """
    n, Cu = c0.shape
    c0 = np.clip(c0, 0.0, 1.0)
    # the unexposed colour at c0 and one step along each concentration (inside [0, 1]):
    # the unmixer's slope and d log XYZ / dc from the same steps
    h = np.where(c0 + _H_C <= 1.0, _H_C, -_H_C)                            # (n, Cu)
    X = np.maximum(np.stack([unmixer.XYZ(c0)] + [unmixer.XYZ(c0 + np.eye(Cu)[k] * h[:, k:k + 1])
                                                 for k in range(Cu)]), XYZ_FLOOR)
    log_X, Lab_X = np.log(X), XYZ_to_Lab(X)
    log_aged, dlog_aged = aged.with_jacobian(c0, rows) if Cu else (aged(c0, rows), None)
    r0 = log_aged - log_X[0]                                              # (n, 3)
    XYZ1 = np.maximum(XYZ_seen, XYZ_FLOOR)              # (black has no log derivative)
    XYZ0 = XYZ1 / np.exp(r0)
    D0, D1 = _dLab_dlogXYZ(XYZ0), _dLab_dlogXYZ(XYZ1)
    E0 = np.linalg.inv(D0)                                                # d log XYZ / d Lab
    step = E0
    if Cu:
        dLab = np.stack([(Lab_X[k + 1] - Lab_X[0]) / h[:, k:k + 1] for k in range(Cu)], -1)
        dlog_X = np.stack([(log_X[k + 1] - log_X[0]) / h[:, k:k + 1] for k in range(Cu)], -1)
        step = E0 + (dlog_aged - dlog_X) @ pseudo_inverse(dLab)             # (n, 3, 3)
    J = D1 @ step                                                         # d Lab1 / d Lab0
    # the seen colour's rounding box, back through the inverse of J
    U, s, Vt = np.linalg.svd(J)
    s = np.maximum(s, 1e-12 * np.maximum(s[:, :1], 1e-30))
    T = _dLab_dencoded(XYZ_to_linear_srgb(XYZ1))                          # per encoded unit
    B = np.swapaxes(Vt, 1, 2) @ (np.swapaxes(U, 1, 2) / s[:, :, None]) @ T
    G0 = _metric(XYZ_to_Lab(XYZ0))
    spread = np.sqrt(precision ** 2 / 3.0 * np.einsum("nji,njk,nki->n", B, G0, B))
    # the original difference the aging shrinks most, as a step of concentrations
    # (ΔE00 1 in the original), and the seen colour's rounding in ΔE*ab
    v = Vt[:, -1]
    direction = np.zeros((n, Cu))
    if Cu:
        v = v / np.sqrt(np.maximum(np.einsum("ni,nij,nj->n", v, G0, v), 1e-30))[:, None]
        direction = np.einsum("nij,nj->ni", pseudo_inverse(dLab), v)
    seen = precision * np.sqrt(np.einsum("nij,nij->n", T, T) / 3.0)
    return spread, r0, direction, seen


def _other_original(aged, rows, c0, XYZ_seen, direction, seen, unmixer):
    """ΔE00 (n,) from the restored original to another that aging takes to the seen
    colour as well (to ``seen``, its own rounding, ΔE*ab), found by solving again from
    ``c0`` moved :data:`_PROBE_STEP` along the collapsing ``direction`` either way; 0
    where none.

    The Jacobian only sees the aging near ``c0``; a fold further away (two originals
    that fade onto one colour while each alone fades smoothly) shows this way. Each
    candidate is aged as :class:`.aging.TextureAger` would age it (displayable, then
    unmixed by the aging's own unmixing), so that only true alternatives count.
    """
    Lab_seen = XYZ_to_Lab(XYZ_seen)
    rows = np.asarray(rows)

    def original_and_miss(c, r=slice(None)):
        """The displayable original ``c`` stands for (seen colours ``r``), and how far
        aging it lands from the seen colour (ΔE*ab)."""
        lin = into_gamut(XYZ_to_linear_srgb(XYZ_seen[r] / np.exp(aged.log_ratio(c, rows[r]))))
        XYZ = linear_srgb_to_XYZ(lin)
        again = XYZ * np.exp(aged.log_ratio(unmixer.unmix(lin, refine=aging_refine(unmixer)),
                                            rows[r]))
        return XYZ, np.linalg.norm(XYZ_to_Lab(again) - Lab_seen[r], axis=-1)

    XYZ0, own = original_and_miss(c0)
    found = np.zeros(c0.shape[0])
    if unmixer.Cu != 1:
        probes = [(np.arange(c0.shape[0]), _solve(aged, rows, XYZ_seen, np.clip(
            c0 + sign * _PROBE_STEP * direction, 0.0, 1.0))) for sign in (1.0, -1.0)]
    else:       # a curve: every fixed point along it, attracting or not
        probes = [_fixed_points(aged, rows, XYZ_seen, unmixer)]
    for r, candidate in probes:
        other, miss = original_and_miss(candidate, r)
        apart = delta_E_2000(XYZ_to_Lab(other), XYZ_to_Lab(XYZ0[r]))
        np.maximum.at(found, r, np.where(miss <= own[r] + seen[r], apart, 0.0))
    return found


def _fixed_points(aged, rows, XYZ_seen, unmixer):
    """One unmixed colourant: the concentrations where the fixed-point map of
    :func:`_polish` crosses the diagonal, ``unmix(XYZ_seen / exp(change(c, d))) = c``.

    The map is sampled at :data:`_CURVE_PROBES` concentrations per row; each sign
    change of ``map(c) - c`` between two samples is bisected (:data:`_BISECTIONS`
    times), and samples where it is zero count as they are. Off the recipe's curve the
    unmixing jumps (a sky blue's nearest point of the curve is one end of it or the
    other), so a crossing may be a jump rather than a fixed point: the caller checks
    each candidate's round trip. Returns the rows (m,) and concentrations (m, 1).
    """
    refine = aging_refine(unmixer)

    def excess(c, r):
        lin = into_gamut(XYZ_to_linear_srgb(XYZ_seen[r] / np.exp(aged.log_ratio(c, rows[r]))))
        return unmixer.unmix(lin, refine=refine)[:, 0] - c[:, 0]

    n, m = rows.size, _CURVE_PROBES
    node = np.linspace(0.0, 1.0, m)
    h = excess(np.tile(node, n)[:, None], np.repeat(np.arange(n), m)).reshape(n, m)
    zero = np.abs(h) <= _FIXED_TOLERANCE
    r_zero, k_zero = np.nonzero(zero)
    r_cross, k_cross = np.nonzero((np.sign(h[:, :-1]) * np.sign(h[:, 1:]) < 0)
                                  & ~zero[:, :-1] & ~zero[:, 1:])
    lo, hi = node[k_cross], node[k_cross + 1]
    h_lo = h[r_cross, k_cross]
    for _ in range(_BISECTIONS if r_cross.size else 0):
        mid = 0.5 * (lo + hi)
        same = np.sign(excess(mid[:, None], r_cross)) == np.sign(h_lo)
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    c = np.concatenate([node[k_zero], 0.5 * (lo + hi)])
    return np.concatenate([r_zero, r_cross]), c[:, None]


def _solve(aged, rows, XYZ_seen, start):
    """Concentrations (n, Cu) whose aged colour at ``rows`` is nearest ``XYZ_seen``
    (n, 3) in CIELAB, from ``start`` (overwritten)."""
    Lab_seen = XYZ_to_Lab(XYZ_seen)

    def seen_of(c, r):
        return XYZ_to_Lab(np.exp(aged(c, rows[r])))

    def with_jacobian(c, r):
        log_XYZ, J = aged.with_jacobian(c, rows[r])
        XYZ = np.exp(log_XYZ)
        return XYZ_to_Lab(XYZ), _dLab_dlogXYZ(XYZ) @ J

    return bounded_gauss_newton(seen_of, start, Lab_seen, _ITERATIONS, jac=with_jacobian,
                                tol=_TOLERANCE, step_tol=_STEP_TOLERANCE)


def _polish(aged, rows, XYZ_seen, c0, unmixer):
    """Fixed-point steps ``c0 = unmix(XYZ_seen / exp(change(c0, d)))`` with the aging's
    own unmixing (:func:`.texels.aging_refine`), for an exact round trip: one
    (:data:`_POLISH`) when the unmixing is square; otherwise (one colourant: a colour
    off the recipe's curve is a least-squares solution, and the grid's solve only
    matches aged colours on the curve) to a fixed point, at most :data:`_FIXED_POINT`.
    """
    refine = aging_refine(unmixer)
    c0 = np.array(c0, dtype=float)
    rows = np.asarray(rows)
    active = np.arange(c0.shape[0])
    for _ in range(_POLISH if unmixer.square else _FIXED_POINT):
        new = into_gamut(XYZ_to_linear_srgb(
            XYZ_seen[active] / np.exp(aged.log_ratio(c0[active], rows[active]))))
        c = unmixer.unmix(new, refine=refine)
        moved = np.abs(c - c0[active]).max(axis=1, initial=0.0)
        c0[active] = c
        active = active[moved > _FIXED_TOLERANCE]
        if not active.size:
            break
    return c0


def _invert(aged, rows, XYZ_seen, start, unmixer):
    """Restored concentrations (n, Cu) of seen colours ``XYZ_seen`` (n, 3) at ``rows``."""
    return _polish(aged, rows, XYZ_seen, _solve(aged, rows, XYZ_seen, start), unmixer)


def _inverse_starts(grid, unmixer, dose, lit, encoded):
    """Starting concentrations (n, Cu) for the solves of rows ``lit`` (seen colours
    ``encoded``): the inversion solved once on a lattice of :data:`_INVERSE_NODES`³
    encoded sRGB colours per dose, interpolated trilinearly (as the unmixer's own
    table); None when there are too few colours per dose for it to pay."""
    doses, member = np.unique(dose[lit], return_inverse=True)
    m = _INVERSE_NODES
    if doses.size * m ** 3 * _INVERSE_PAYS > lit.size:
        return None
    axis = np.linspace(0.0, 1.0, m)
    nodes = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    XYZ = linear_srgb_to_XYZ(srgb_decode(nodes))
    aged = _AgedAt(grid, unmixer, np.repeat(doses, nodes.shape[0]))
    table = np.empty((doses.size * nodes.shape[0], unmixer.Cu))
    start = unmixer.unmix(nodes, encoded=True, refine=0)
    for p in range(doses.size):
        rows = np.arange(p * nodes.shape[0], (p + 1) * nodes.shape[0])
        table[rows] = _solve(aged, rows, XYZ, start.copy())
    table = table.reshape(doses.size, m, m, m, -1)
    x = np.clip(encoded, 0.0, 1.0) * (m - 1)
    i = np.minimum(x.astype(np.int64), m - 2)
    f = x - i
    out = np.zeros((lit.size, unmixer.Cu))
    member = member.reshape(-1)
    for bits in np.ndindex(2, 2, 2):
        w = np.prod([f[:, k] if b else 1.0 - f[:, k] for k, b in enumerate(bits)], axis=0)
        out += w[:, None] * table[member, i[:, 0] + bits[0], i[:, 1] + bits[1], i[:, 2] + bits[2]]
    return np.clip(out, 0.0, 1.0)


def restore(rgb, years, recipe="printed-paper", lights=(Light(),), exposure=None,
            encoding="srgb", settings=GridSettings(), cache=True, store=None, progress=None,
            levels=64, precision=PRECISION):
    """Undo ``years`` of ``lights`` on a texture: its estimated colours when new.

    Parameters
    ----------
    rgb : array_like, shape (..., 3)
        The texture as it is now, in [0, 1] (linear or encoded sRGB, ``encoding``).
    years : float
        How old it is, >= 0.
    recipe : Recipe or str
    lights : sequence of Light
        The light it aged under.
    exposure : array_like, optional
        Relative exposure per texel (default: 1 everywhere).
    encoding : {"linear", "srgb"}
    settings, cache, store, progress
        As for :class:`.aging.TextureAger`.
    levels : int
        The dose per texel is quantised to this many levels (one solve per
        distinct colour and level).
    precision : float
        Half a step of the seen image's values, in encoded sRGB (default: 8 bits;
        ``0.5 / 65535`` for a 16-bit file).

    Returns
    -------
    Restored
        ``image``, the ``lost`` mask and ``spread``.

    Raises
    ------
    ValueError
        Non-finite colours or years, negative years, no lights, bad exposure.

    Examples
    --------
    >>> back = restore(photo, 25, "printed-paper", [Light(lux=150)])   # doctest: +SKIP
    >>> back.image, back.lost_fraction                                 # doctest: +SKIP
    """
    recipe = get_recipe(recipe) if isinstance(recipe, str) else recipe
    years = float(years)
    if not np.isfinite(years) or years < 0:
        raise ValueError(f"years must be a finite number >= 0, got {years!r}")
    if encoding not in ("linear", "srgb"):
        raise ValueError(f"encoding must be 'linear' or 'srgb', got {encoding!r}")
    rgb = checked_rgb(rgb)
    if not lights:
        raise ValueError("at least one light is needed")
    say = progress or (lambda f, m: None)
    flat = np.clip(rgb.reshape(-1, 3), 0.0, 1.0)
    n = flat.shape[0]
    keys = spectra_keys(lights)
    rates = dose_rates(lights, exposure, n, keys).astype(float)          # (S, n)
    total = rates.sum(axis=0)
    doses = total * years
    dmax = float(doses.max()) if n else 0.0
    lost = np.zeros(rgb.shape[:-1], dtype=bool)
    spread = np.zeros(rgb.shape[:-1])
    if dmax <= 0:
        return Restored(rgb.copy(), lost, spread)

    spectra = np.stack([light_spectrum(s, WAVELENGTHS, uv) for s, uv in keys])
    say(0.0, "building the fading grid")
    grid = load_or_build(recipe, spectra, grid_max_dose(dmax), settings, cache=cache, store=store,
                         progress=lambda f, m: say(0.3 * f, m))
    unmixer = get_unmixer(recipe)
    colours, colour_of = _distinct(_encoded(flat, encoding))
    if colours.shape[0] > texels.UNMIX_BUDGET:
        # more colours than aging unmixes one by one (16-bit and float photographs):
        # one solve per 8-bit colour; each texel keeps its own detail through the ratio
        codes, inverse = np.unique(_codes(colours), return_inverse=True)
        colours, colour_of = _decode(codes), inverse.reshape(-1)[colour_of]

    # one solve per distinct (colour, dose level, light mix level)
    level = np.rint(doses / dmax * (levels - 1)).astype(np.int64)
    mix = rates / np.where(total > 0, total, 1.0)
    mix_level = np.rint(mix[1:] * (levels - 1)).astype(np.int64) if len(keys) > 1 else \
        np.zeros((0, n), dtype=np.int64)
    code = colour_of.astype(np.int64) * levels + level
    for row in mix_level:
        code = code * levels + row
    _, first, group = np.unique(code, return_index=True, return_inverse=True)
    group = group.reshape(-1)
    G = first.size
    dose_g = level[first] / (levels - 1) * dmax
    counts = np.bincount(group, minlength=G)
    mix_g = None
    if len(keys) > 1:
        mix_g = np.stack([np.bincount(group, mix[s], G) for s in range(len(keys))], 1)
        mix_g /= counts[:, None]
    lin = srgb_decode(flat) if encoding == "srgb" else flat
    XYZ_seen = linear_srgb_to_XYZ(lin.astype(float))
    XYZ_g = XYZ_seen[first]                    # one colour per group

    aged = _AgedAt(grid, unmixer, dose_g, mix_g)
    log_ratio = np.zeros((G, 3))
    spread_g = np.zeros(G)
    folded = np.zeros(G, dtype=bool)
    lit = np.flatnonzero(dose_g > 0)
    say(0.3, f"inverting the fade of {lit.size} colours")
    starts = _inverse_starts(grid, unmixer, dose_g, lit, colours[colour_of[first[lit]]]) \
        if unmixer.Cu and mix_g is None else None
    for b0 in range(0, lit.size, _BLOCK):
        rows = lit[b0:b0 + _BLOCK]
        if starts is not None:
            start = starts[b0:b0 + _BLOCK]
        else:
            start = (unmixer.unmix(colours[colour_of[first[rows]]], encoded=True, refine=0)
                     if unmixer.Cu else np.zeros((rows.size, 0)))
        c0 = _invert(aged, rows, XYZ_g[rows], start, unmixer) if unmixer.Cu else start
        spread_g[rows], log_ratio[rows], direction, seen = _uncertainty(
            aged, rows, c0, XYZ_g[rows], unmixer, precision)
        # with one colourant the fold need not show in the spread (a sky blue and a
        # grey of full extractive fade to one colour): every colour is probed
        probe = (np.flatnonzero((spread_g[rows] > _PROBE) | (unmixer.Cu == 1))
                 if unmixer.Cu else [])
        if len(probe):
            other = _other_original(aged, rows[probe], c0[probe], XYZ_g[rows[probe]],
                                    direction[probe], seen[probe], unmixer)
            folded[rows[probe]] = other > LOST_APART
        say(0.3 + 0.7 * min(b0 + _BLOCK, lit.size) / lit.size,
            f"inverting the fade of {lit.size} colours")
    spread = spread_g[group].reshape(spread.shape)
    XYZ = XYZ_seen / np.exp(log_ratio)[group]
    lin = XYZ_to_linear_srgb(XYZ)
    # no displayable original ages to the seen colour: the one it would take lies
    # further than LOST_APART outside [0, 1] (a history the photo cannot have had)
    outside = np.zeros(n, dtype=bool)
    out = np.flatnonzero(out_of_gamut(lin))
    if out.size:
        outside[out] = delta_E_2000(XYZ_to_Lab(np.maximum(XYZ[out], 0.0)), XYZ_to_Lab(
            linear_srgb_to_XYZ(into_gamut(lin[out])))) > LOST_APART
    lost = (spread > LOST_APART) | folded[group].reshape(spread.shape) | \
        outside.reshape(spread.shape)
    image = encode_in_gamut(lin, encoding).astype(np.float32)
    say(1.0, f"restored; {np.count_nonzero(lost)} pixels lost")
    return Restored(image.reshape(rgb.shape), lost, spread)
