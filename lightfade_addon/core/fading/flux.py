"""Radiant flux densities in a stack of layers (paper, Section 3.1, equations 1–2).

Layer ``i`` (``0 <= i < N``, top first) lies between boundaries ``i`` and ``i + 1``
and has reflectance ``rho_i`` and transmittance ``tau_i`` (the same from above and
below). The downward and upward flux densities at the ``N + 1`` boundaries obey::

    E_u[i] = rho[i] E_d[i] + tau[i] E_u[i+1]          0 <= i < N      (1)
    E_d[i] = tau[i-1] E_d[i-1] + rho[i-1] E_u[i]      0 <  i <= N     (2)

with ``E_d[0] = E0`` and ``E_u[N] = ground * E_d[N]`` (Figure 3).

:func:`boundary_fluxes` solves this block tridiagonal system in O(N) per wavelength
with the adding method: a backward sweep for the reflectance ``R[i]`` of everything
below boundary ``i`` (``E_u[i] = R[i] E_d[i]``) followed by a forward sweep for
``E_d``, which is a cumulative product. :func:`boundary_fluxes_dense` assembles and
solves the Figure 3 system directly; it exists to check the fast solver.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "boundary_fluxes",
    "boundary_fluxes_dense",
    "stack_reflectance",
    "adding_sweep",
]


def adding_sweep(rho, tau2, ground, R, D):
    """Backward adding sweep over layer-major arrays, in place.

    Parameters
    ----------
    rho, tau2 : ndarray, shape (N, n)
        Layer reflectance and squared transmittance, layer ``0`` on top; ``n`` is
        any flattened batch of independent columns (samples × wavelengths).
    ground : ndarray, shape (n,)
        Ground reflectance ``rho*`` per column.
    R : ndarray, shape (N + 1, n)
        Output: ``R[i]`` is the reflectance of layers ``i..N-1`` on the ground,
        seen from boundary ``i``; ``R[N] = ground`` and ``R[0]`` is the stack's
        reflectance.
    D : ndarray, shape (N, n)
        Output: ``D[i] = 1 - rho[i] R[i+1]``, the inter-reflection denominator,
        which the forward sweep reuses: ``E_d[i+1] = tau[i] E_d[i] / D[i]``.

    Notes
    -----
    ``R[i] = rho[i] + tau[i]**2 R[i+1] / (1 - rho[i] R[i+1])`` follows from
    equations (1)–(2) by eliminating ``E_u[i+1] = R[i+1] E_d[i+1]``. Every quantity
    stays in [0, 1], so the sweep is unconditionally stable (unlike transfer
    matrices, whose growing modes overflow for thick stacks).
    """
    N = rho.shape[0]
    R[N] = ground
    tmp = np.empty_like(ground)
    for i in range(N - 1, -1, -1):
        Di = D[i]
        np.multiply(rho[i], R[i + 1], out=Di)
        np.subtract(1.0, Di, out=Di)
        np.multiply(tau2[i], R[i + 1], out=tmp)
        np.divide(tmp, Di, out=tmp)
        np.add(rho[i], tmp, out=R[i])
    return R, D


def _layer_major(a, N):
    """Move the layer axis of ``a`` (..., N, W) to the front: (N, prod(...) * W)."""
    a = np.moveaxis(np.asarray(a, dtype=float), -2, 0)
    return np.ascontiguousarray(a.reshape(N, -1))


def boundary_fluxes(rho, tau, ground, E0=1.0):
    """Downward and upward flux densities at every layer boundary, in O(N).

    Parameters
    ----------
    rho, tau : array_like, shape (..., N, W)
        Reflectance and transmittance of the ``N`` layers, top layer first.
    ground : array_like, shape (..., W)
        Ground reflectance ``rho*`` (broadcast against the batch).
    E0 : float or array_like, shape (..., W)
        Irradiance on the top boundary (any radiometric unit; the fluxes are in
        the same unit).

    Returns
    -------
    E_d, E_u : ndarray, shape (..., N + 1, W)
        Flux densities at boundaries ``0..N``, top boundary first.

    References
    ----------
    Paper, equations (1)–(2) and Figure 3; the O(N) solution it cites [15].

    Examples
    --------
    >>> E_d, E_u = boundary_fluxes([[0.0]], [[1.0]], [0.5])  # a transparent layer
    >>> E_u[..., 0, 0].item()
    0.5
    """
    rho = np.asarray(rho, dtype=float)
    tau = np.broadcast_to(np.asarray(tau, dtype=float), rho.shape)
    *batch, N, W = rho.shape
    lead = tuple(batch)
    ground = np.broadcast_to(np.asarray(ground, dtype=float), lead + (W,))
    E0 = np.broadcast_to(np.asarray(E0, dtype=float), lead + (W,))

    rho_m = _layer_major(rho, N)
    tau_m = _layer_major(tau, N)
    R = np.empty((N + 1, rho_m.shape[1]))
    D = np.empty_like(rho_m)
    adding_sweep(rho_m, tau_m * tau_m, ground.reshape(-1), R, D)

    E_d = np.empty_like(R)
    E_d[0] = E0.reshape(-1)
    np.cumprod(tau_m / D, axis=0, out=E_d[1:])
    E_d[1:] *= E_d[0]
    E_u = R * E_d

    shape = (N + 1,) + lead + (W,)
    return (
        np.moveaxis(E_d.reshape(shape), 0, -2),
        np.moveaxis(E_u.reshape(shape), 0, -2),
    )


def stack_reflectance(rho, tau, ground):
    """Reflectance of a stack of layers on a ground, ``R[0]`` of the adding sweep.

    Parameters and shapes as in :func:`boundary_fluxes`; returns (..., W).
    """
    rho = np.asarray(rho, dtype=float)
    tau = np.broadcast_to(np.asarray(tau, dtype=float), rho.shape)
    *batch, N, W = rho.shape
    ground = np.broadcast_to(np.asarray(ground, dtype=float), tuple(batch) + (W,))
    rho_m = _layer_major(rho, N)
    tau_m = _layer_major(tau, N)
    R = np.empty((N + 1, rho_m.shape[1]))
    adding_sweep(rho_m, tau_m * tau_m, ground.reshape(-1), R, np.empty_like(rho_m))
    return R[0].reshape(tuple(batch) + (W,))


def boundary_fluxes_dense(rho, tau, ground, E0=1.0):
    """Solve the Figure 3 system with a dense linear solve (O(N^3); tests only).

    Takes one column: ``rho``, ``tau`` of shape (N,), scalar ``ground`` and
    ``E0``. The unknowns are ordered ``(E_d[0], E_u[0], E_d[1], E_u[1], ...)``
    and the ``2 (N + 1)`` equations are the two boundary conditions and
    equations (1) and (2), exactly as printed in the paper.
    """
    rho = np.asarray(rho, dtype=float)
    tau = np.asarray(tau, dtype=float)
    N = rho.shape[0]
    n = 2 * (N + 1)
    A = np.zeros((n, n))
    b = np.zeros(n)

    def d(i):
        return 2 * i

    def u(i):
        return 2 * i + 1

    row = 0
    A[row, d(0)] = 1.0                          # E_d[0] = E0
    b[row] = E0
    row += 1
    for i in range(N):                          # (1): E_u[i] - rho_i E_d[i] - tau_i E_u[i+1] = 0
        A[row, u(i)] = 1.0
        A[row, d(i)] = -rho[i]
        A[row, u(i + 1)] = -tau[i]
        row += 1
    for i in range(1, N + 1):                   # (2): E_d[i] - tau_{i-1} E_d[i-1] - rho_{i-1} E_u[i] = 0
        A[row, d(i)] = 1.0
        A[row, d(i - 1)] = -tau[i - 1]
        A[row, u(i)] = -rho[i - 1]
        row += 1
    A[row, u(N)] = 1.0                          # E_u[N] = rho* E_d[N]
    A[row, d(N)] = -ground
    x = np.linalg.solve(A, b)
    return x[0::2], x[1::2]
