"""Fitting a colour table's dose nodes to the change curves they are interpolated into.

The evaluator (:func:`.colourtable.evaluate`, and the node group) interpolates the
table linearly in the dose position ``s``. The recipe is simulated at ``sub`` points
per node interval (:func:`fine_doses`: the kinetics are stepped that finely too), and
the node values are the piecewise-linear least-squares fit in ``s`` to those points,
node 0 held at its own value (:func:`dose_fit`: 0 years stays the original colour
exactly). Two points per interval take the 25-year error on photographs from ΔE00
p99 ~1.0 to ~0.35 (``benchmarks/colour_table.py``): most of it was the kinetics'
stepping, not the interpolation.
"""

from __future__ import annotations

import numpy as np

__all__ = ["dose_fit", "fine_doses"]


def fine_doses(low_dose, per_decade, nodes, sub):
    """The dose axis with ``sub`` points per node interval (lux·h).

    Node ``t >= 1`` of the table (``low · 10 ** ((t - 1) / per_decade)``) is fine
    point ``1 + (t - 1) · sub``; point 0 is dose 0.

    Parameters
    ----------
    nodes : int
        Table dose nodes ``T`` (node 0 included).
    """
    k = np.arange((nodes - 2) * sub + 1)
    return np.concatenate([[0.0], low_dose * 10.0 ** (k / (per_decade * sub))])


def _dose_design(T, sub):
    """(fine points - 1, T - 1): the linear interpolation weights of nodes 1..T-1 at
    the fine points 1.. (``s = 1 + m / sub``)."""
    m = np.arange((T - 2) * sub + 1)
    s = m / sub
    i = np.minimum(np.floor(s).astype(np.int64), T - 3) if T > 2 else np.zeros_like(m)
    f = s - i
    B = np.zeros((m.size, T - 1))
    B[m, i] = 1.0 - f
    if T > 2:
        B[m, i + 1] += f
    return B


def dose_fit(curves, sub):
    """Node values whose linear interpolation in ``s`` best fits ``curves``.

    Parameters
    ----------
    curves : ndarray, shape (..., Tf, 3)
        The change at the :func:`fine_doses` points (point 0 at dose 0).
    sub : int
        Fine points per node interval.

    Returns
    -------
    ndarray, shape (..., T, 3), float32
        ``T = (Tf - 2) / sub + 2``; node 0 is 0 (or ``curves[..., 0, :]``, a
        history's restoration), node ``t >= 1`` the least-squares value.
    """
    Tf = curves.shape[-2]
    T = (Tf - 2) // sub + 2
    if sub == 1:
        return curves.astype(np.float32)
    B = _dose_design(T, sub)
    P = np.linalg.pinv(B)                                               # (T-1, Tf-1)
    out = np.empty(curves.shape[:-2] + (T, 3), dtype=np.float32)
    out[..., 0, :] = curves[..., 0, :]
    out[..., 1:, :] = np.swapaxes(np.swapaxes(curves[..., 1:, :], -1, -2).astype(np.float64)
                                  @ P.T, -1, -2)
    return out
