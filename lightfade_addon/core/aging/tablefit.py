"""Fitting a colour table's node values to the change they are interpolated into.

The evaluator (:func:`.colourtable.evaluate`, and the node group) interpolates the
table linearly: trilinearly over the colour cube, linearly over the dose position
``s``. Node values sampled at the nodes make that interpolant exact at the nodes
and wrong between them wherever the change curves (Kubelka–Munk darks, the gamut's
faces where an unmixed colourant reaches 0 or 1, the steep end of the dose axis).
Here the node values are instead the least-squares fit (lattice regression) of the
interpolant, exactly as the evaluator computes it, to the modelled change at many
more points than there are nodes:

* along the dose: at ``sub`` points per node interval (:func:`fine_doses`), a
  piecewise-linear least-squares fit in ``s`` with node 0 held at 0
  (:func:`dose_fit`: 0 years stays the original colour exactly);
* over the colour: at every node and ``per_cell`` stratified random points in every
  cell of the cube (:func:`cell_samples`), the normal equations of the trilinear
  weights (:func:`interpolation_matrix`) solved once for all light mixes, doses and
  channels (:func:`lattice_solve`).

Both are linear least squares on a tensor-product basis sampled on a tensor product
(every colour sample at every fine dose), so fitting the dose first and the colour
second gives the joint least-squares solution.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cell_samples", "kinked_cells", "dose_fit", "fine_doses", "interpolation_matrix", "lattice_solve"]


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


def cell_samples(side, per_cell, seed=0, cells=None):
    """Fitting points in node units ``u · (N - 1)``, (n, 3) as (r, g, b).

    Every node (in :func:`.colourtable.cube_colours` order), then ``per_cell``
    uniform random points in every cell (a fixed ``seed``: the same table every
    build), and the same density on the cube's faces and edges: each point of a cell
    at the cube's boundary also snapped onto that boundary, along every subset of its
    boundary axes (photographs clip: many of their colours lie on the faces).

    Parameters
    ----------
    cells : ndarray of bool, shape (N - 1,) * 3, optional
        Which cells (indexed b, g, r) get points; all by default.
    """
    axis = np.arange(side, dtype=float)
    b, g, r = np.meshgrid(axis, axis, axis, indexing="ij")
    nodes = np.stack([r, g, b], -1).reshape(-1, 3)
    if per_cell <= 0:
        return nodes
    rng = np.random.default_rng(seed)
    corners = nodes[np.all(nodes < side - 1, axis=1)]               # cells, r fastest
    if cells is not None:
        corners = corners[np.asarray(cells, dtype=bool).reshape(-1)]
    corners = np.repeat(corners, per_cell, axis=0)
    inner = corners + rng.random(corners.shape)
    edge = np.where(corners == 0, 0.0, np.where(corners == side - 2, side - 1.0, np.nan))
    snapped = []
    for axes in np.ndindex(2, 2, 2):
        on = np.array(axes, dtype=bool)
        if on.any():
            hit = np.all(~np.isnan(edge[:, on]), axis=1)
            p = inner[hit].copy()
            p[:, on] = edge[hit][:, on]
            snapped.append(p)
    return np.concatenate([nodes, inner] + snapped)


def kinked_cells(c, side):
    """Cells (N - 1,) * 3 (b, g, r) whose corner nodes' unmixed concentrations ``c``
    (N³, Cu) do not all hold the same colourants at 0 or 1: the gamut's faces cross
    them, and the change has a kink there that the nodes alone do not place. In the
    other cells the change is smooth and the nodes' own values serve."""
    code = np.zeros(c.shape[0], dtype=np.int64)
    for k in range(c.shape[1]):
        code = code * 3 + (c[:, k] <= 1e-6) + 2 * (c[:, k] >= 1.0 - 1e-6)
    code = code.reshape((side,) * 3)
    first = code[:-1, :-1, :-1]
    mixed = np.zeros(first.shape, dtype=bool)
    for b, g, r in np.ndindex(2, 2, 2):
        mixed |= code[b:side - 1 + b, g:side - 1 + g, r:side - 1 + r] != first
    return mixed


def interpolation_matrix(u, side):
    """Sparse (n, N³) trilinear weights of points ``u`` (n, 3) in node units, column
    ``(b · N + g) · N + r``: what the evaluator computes (cells clipped at N - 2)."""
    from scipy import sparse

    u = np.asarray(u, dtype=float)
    i = np.minimum(np.floor(u).astype(np.int64), side - 2)
    f = u - i
    rows, cols, vals = [], [], []
    for bits in np.ndindex(2, 2, 2):
        w = np.ones(u.shape[0])
        for k, on in enumerate(bits):
            w = w * (f[:, k] if on else 1.0 - f[:, k])
        cols.append(((i[:, 2] + bits[2]) * side + i[:, 1] + bits[1]) * side + i[:, 0] + bits[0])
        rows.append(np.arange(u.shape[0]))
        vals.append(w)
    return sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(u.shape[0], side ** 3))


def lattice_solve(W, rhs, ridge=1e-9):
    """Node values ``v`` minimising ``|W v - y|²`` given ``rhs = Wᵀ y``.

    Parameters
    ----------
    W : sparse matrix, shape (n, N³)
        :func:`interpolation_matrix` of the samples.
    rhs : ndarray, shape (N³, k)
        ``Wᵀ y`` for ``k`` right-hand sides (accumulated block by block).
    ridge : float
        Relative Tikhonov term (only guards empty columns; every node is a sample).
        Nodes whose only sample is their own (cells without fitting points all
        around them) are their sample; the others are solved together.

    Returns
    -------
    ndarray, shape (N³, k)
    """
    from scipy import sparse

    WtW = (W.T @ W).tocsr()
    WtW.eliminate_zeros()
    rhs = np.ascontiguousarray(rhs, dtype=np.float64)
    diag = WtW.diagonal()
    scale = float(diag.mean()) if diag.size else 1.0
    out = rhs / np.maximum(diag + ridge * scale, 1e-300)[:, None]   # nodes alone in their rows
    coupled = np.flatnonzero(np.diff(WtW.indptr) > 1)
    if coupled.size:
        sub = WtW[coupled][:, coupled] + ridge * scale * sparse.eye(coupled.size)
        out[coupled] = _conjugate_gradients(sub.tocsr(), rhs[coupled])
    return out


def _conjugate_gradients(A, B, tol=1e-10, iterations=1000):
    """``A⁻¹ B`` column by column, vectorised over the columns (Jacobi-preconditioned
    conjugate gradients; ``A`` is a normal matrix of interpolation weights, well
    conditioned: a few tens of iterations)."""
    inv_diag = 1.0 / A.diagonal()[:, None]
    X = np.zeros_like(B)
    R = B.copy()
    Z = R * inv_diag
    P = Z.copy()
    rz = np.sum(R * Z, axis=0)
    limit = tol * np.sqrt(np.sum(B * B, axis=0)) + 1e-300
    for _ in range(iterations):
        AP = A @ P
        alpha = rz / np.maximum(np.sum(P * AP, axis=0), 1e-300)
        X += alpha * P
        R -= alpha * AP
        if np.all(np.sqrt(np.sum(R * R, axis=0)) <= limit):
            break
        Z = R * inv_diag
        rz_new = np.sum(R * Z, axis=0)
        P = Z + (rz_new / np.maximum(rz, 1e-300)) * P
        rz = rz_new
    return X
