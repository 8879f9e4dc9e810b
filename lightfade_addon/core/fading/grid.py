"""The mixture grid: selective interpolation of simulated fading (paper, Section 5).

Fading is simulated once at the nodes of a grid over

* the concentration of each *unmixed* colourant (``m`` points per axis, spaced as
  ``(k / (m - 1)) ** power`` so that they are denser near zero, where reflectance is
  most nonlinear in concentration),
* the spectral composition of the light (a simplex lattice over the scene's ``S``
  light spectra, resolution ``q``; one node when there is one spectrum), and
* the dose in lux·h (``T`` points spaced cubically from 0 to ``max_dose``; one
  simulation per concentration and mix gives the whole dose axis through
  ``record``, thanks to reciprocity).

What is stored and interpolated is the *change*: ``log(XYZ_aged / XYZ_initial)``
per node, which varies smoothly where the reflectance itself does not, and which is
exactly zero at zero dose. A texel's aged colour is its original colour times the
interpolated change (``docs/grid.md`` has the accuracy study).

The lattice lives in :mod:`.lattice`, building in :mod:`.gridbuild`, bytes in
:mod:`.gridfile` and the on-disk cache in :mod:`.cache`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import NdBSpline, make_interp_spline

from .lattice import dose_index, simplex_interpolation

__all__ = ["FadeGrid", "GridSettings"]

#: Colours per call of the spline evaluation (bounds its temporaries).
_CURVE_BLOCK = 1 << 14


@dataclass(frozen=True)
class GridSettings:
    """Resolution of a grid.

    Attributes
    ----------
    points : int
        Nodes per concentration axis (``m``; the paper's 6 gives 6^3 = 216).
    power : float
        Spacing exponent of the concentration axes (1 = uniform; 2 = quadratic).
    doses : int
        Nodes on the dose axis (``T``), spaced as ``(k / (T - 1))**3``.
    mix : int
        Resolution ``q`` of the light-mixture simplex lattice.
    """

    points: int = 10
    power: float = 1.6
    doses: int = 65
    mix: int = 4


def cubic_spline(axes, values):
    """Interpolating tensor-product cubic spline through ``values`` on ``axes``.

    Not-a-knot ends, built by :func:`scipy.interpolate.make_interp_spline` along
    each axis in turn, evaluated by :class:`scipy.interpolate.NdBSpline`.

    Parameters
    ----------
    axes : list of ndarray
        Node coordinates, strictly increasing, at least 2 each.
    values : ndarray, shape (len(a) for a in axes) + trailing
    """
    coef = values
    knots = []
    degree = min(3, min(a.size for a in axes) - 1)
    for k, axis in enumerate(axes):
        b = make_interp_spline(axis, coef, k=degree, axis=k)
        knots.append(b.t)
        coef = np.moveaxis(b.c, 0, k)           # b.c has the spline's axis first
    return NdBSpline(tuple(knots), coef, degree, extrapolate=False)


@dataclass
class FadeGrid:
    """Simulated change of colour over concentrations × light mixture × dose.

    Attributes
    ----------
    key : str
        Hash of everything the grid depends on (the cache key).
    recipe : str
        Recipe name, for messages.
    axes : list of ndarray
        One concentration axis per unmixed colourant.
    mixes : ndarray, shape (M, S)
        The light-mixture lattice (weights of the S spectra).
    doses : ndarray, shape (T,)
        Dose axis, lux·h.
    change : ndarray, shape (M, T, m, ..., m, 3), float32
        ``log(XYZ_aged / XYZ_initial)`` at every node (zero at dose 0).
    q : int
        Lattice resolution of ``mixes``.
    initial : ndarray, shape (m, ..., m, 3), float32, optional
        ``log XYZ_initial`` at the concentration nodes (see :meth:`curves`).
    """

    key: str
    recipe: str
    axes: list
    mixes: np.ndarray
    doses: np.ndarray
    change: np.ndarray
    q: int
    initial: np.ndarray | None = None
    _spline: object = field(default=None, repr=False, compare=False)

    @property
    def max_dose(self):
        return float(self.doses[-1])

    # -- interpolation -------------------------------------------------------------

    def spline(self):
        """The aged colour's interpolant over the concentration axes (built once).

        A tensor-product cubic spline (:func:`cubic_spline`) of ``log XYZ_aged``
        (``change + initial``; the change alone when the grid has no ``initial``),
        values flattened to M × T × 3 per node.
        """
        if self._spline is None:
            M, T = self.change.shape[:2]
            values = np.moveaxis(self.change.astype(float), (0, 1), (-3, -2))   # (m.., M, T, 3)
            if self.initial is not None:
                values = values + self.initial.astype(float)[..., None, None, :]
            self._spline = cubic_spline(self.axes, values.reshape(
                values.shape[:len(self.axes)] + (M * T * 3,)))
        return self._spline

    def _initial_spline(self):
        return cubic_spline(self.axes, self.initial.astype(float))

    def curves(self, c, initial=None):
        """Change along the dose axis for each concentration, for every mix node.

        Parameters
        ----------
        c : ndarray, shape (U, Cu)
            Concentrations of the unmixed colourants (Cu may be 0), clipped to [0, 1].
        initial : ndarray, shape (U, 3), optional
            ``log XYZ_initial`` of ``c``, computed exactly by the caller (e.g.
            :meth:`.unmix.Unmixer.XYZ`); interpolated from :attr:`initial` when not
            given (less exact).

        Returns
        -------
        ndarray, shape (U, M, T, 3), float32
            ``log(XYZ_aged / XYZ_initial)``: with :attr:`initial`, ``log XYZ_aged``
            interpolated in concentration by :meth:`spline` (exact at the nodes,
            third order between them) minus the exact ``initial``. Only the aged
            colour is interpolated: the unexposed colour's own steep dependence on
            concentration (Kubelka–Munk saturation) is then exact.
        """
        M, T = self.change.shape[:2]
        c = np.asarray(c, dtype=float)
        c = np.clip(c.reshape(c.shape[0] if c.ndim > 1 else 1, len(self.axes)), 0.0, 1.0)
        if not self.axes:
            return np.broadcast_to(self.change[None], (c.shape[0], M, T, 3)).astype(np.float32)
        if self.initial is not None and initial is None:    # interpolated too: less exact
            initial = self._initial_spline()(c)
        out = np.empty((c.shape[0], M, T, 3), dtype=np.float32)
        spline = self.spline()
        for s0 in range(0, c.shape[0], _CURVE_BLOCK):
            v = spline(c[s0:s0 + _CURVE_BLOCK]).reshape(-1, M, T, 3)
            if initial is not None:
                v -= np.asarray(initial, dtype=float)[s0:s0 + _CURVE_BLOCK, None, None, :]
            out[s0:s0 + _CURVE_BLOCK] = v
        # the dose-0 node is exactly zero (the spline reproduces it to rounding)
        out[:, :, 0] = 0.0
        return out

    def dose_position(self, dose):
        """Fractional index on the dose axis (clipped to the axis), (N,) -> (i, frac)."""
        T = self.doses.size
        s = dose_index(np.asarray(dose, dtype=float) / self.max_dose, T)
        i = np.minimum(s.astype(np.int64), T - 2)
        return i, s - i

    def log_change(self, c, dose, mix=None, initial=None):
        """``log(XYZ_aged / XYZ_initial)`` for samples, (N, 3).

        Parameters
        ----------
        c : array_like, shape (N, Cu)
            Concentrations of the unmixed colourants.
        dose : array_like, shape (N,)
            Total dose, lux·h (clipped to the grid's ``max_dose``).
        mix : array_like, shape (N, S), optional
            Dose share of each light spectrum (default: all from the first).
        initial : array_like, shape (N, 3), optional
            ``log XYZ_initial`` of ``c`` (see :meth:`curves`).
        """
        dose = np.asarray(dose, dtype=float).reshape(-1)
        N = dose.size
        S = self.mixes.shape[1]
        if mix is None:
            mix = np.zeros((N, S))
            mix[:, 0] = 1.0
        nodes, wm = simplex_interpolation(np.asarray(mix, dtype=float).reshape(N, S), self.q)
        curves = self.curves(np.asarray(c, dtype=float).reshape(N, -1), initial)  # (N, M, T, 3)
        i, f = self.dose_position(dose)
        out = np.zeros((N, 3))
        rows = np.arange(N)
        for k in range(nodes.shape[1]):
            cv = curves[rows, nodes[:, k]]                                     # (N, T, 3)
            v = (1 - f)[:, None] * cv[rows, i] + f[:, None] * cv[rows, i + 1]
            out += wm[:, k, None] * v
        return out
