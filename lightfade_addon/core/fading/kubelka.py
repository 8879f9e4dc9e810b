"""Kubelka's formulae for one homogeneous layer.

A layer of thickness ``d`` with Kubelka–Munk absorption ``K`` and scattering ``S``
(both per unit length) over a non-reflecting ground reflects ``rho`` and transmits
``tau`` of the diffuse flux falling on it, the same from above and from below
(paper, Section 3.1; Kubelka 1948, ref. [19]).

With ``alpha = sqrt(K (K + 2 S))`` the closed form is::

    rho = S sinh(alpha d) / (alpha cosh(alpha d) + (K + S) sinh(alpha d))
    tau = alpha           / (alpha cosh(alpha d) + (K + S) sinh(alpha d))

which is evaluated here in a form that stays finite and accurate in every limit:

* ``S -> 0`` (a pure absorber): ``rho = 0`` and ``tau = exp(-K d)``;
* ``K -> 0`` (a pure scatterer): ``rho = S d / (1 + S d)``, ``tau = 1 / (1 + S d)``;
* ``alpha d -> inf`` (optically thick): no overflow, ``tau -> 0``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["kubelka_layer", "kubelka_layer_reference", "over_ground"]

#: Below this optical thickness ``alpha d`` the ratio ``-expm1(-2x) / x`` is
#: evaluated at this floor instead of at zero; the floor is far below double
#: precision's resolution of the result, so the value is exact to rounding.
_X_FLOOR = 1e-150


def kubelka_layer(K, S, d=1.0):
    """Reflectance and transmittance of one layer over a black ground.

    Parameters
    ----------
    K, S : array_like
        Kubelka–Munk absorption and scattering coefficients, per unit length,
        ``>= 0``; broadcast against each other.
    d : float or array_like
        Layer thickness, in the same unit of length.

    Returns
    -------
    rho, tau : ndarray
        Diffuse reflectance and transmittance in [0, 1]; ``rho + tau <= 1`` with
        equality when ``K = 0``.

    Notes
    -----
    Writing ``x = alpha d``, ``e1 = exp(-x)``, ``m = expm1(-2 x)`` and
    ``g = -m / x`` (which tends to 2 as ``x -> 0``), dividing numerator and
    denominator of Kubelka's formulae by ``x cosh(x)`` gives::

        rho = S d g / (2 + m + (K + S) d g)
        tau = 2 e1  / (2 + m + (K + S) d g)

    Only bounded quantities appear, so the pure-absorber, pure-scatterer and
    optically thick limits come out without special cases.

    References
    ----------
    Paper, Section 3.1, "Kubelka's formulae [19] for a medium having finite depth
    and zero ground reflection".

    Examples
    --------
    >>> rho, tau = kubelka_layer(0.0, 1.0, 1.0)   # pure scatterer: S d / (1 + S d)
    >>> float(rho), float(tau)
    (0.5, 0.5)
    """
    K = np.asarray(K, dtype=float)
    S = np.asarray(S, dtype=float)
    Kd = K * d
    Sd = S * d
    x = np.maximum(np.sqrt(Kd * (Kd + 2.0 * Sd)), _X_FLOOR)
    m = np.expm1(-2.0 * x)
    g = -m / x
    den = 2.0 + m + (Kd + Sd) * g
    return Sd * g / den, 2.0 * np.exp(-x) / den


def kubelka_layer_reference(K, S, d=1.0):
    """Kubelka's formulae exactly as printed (hyperbolic functions), for tests.

    Valid only away from the limits ``K = 0`` and large ``alpha d``, where the
    textbook form divides zero by zero or overflows; :func:`kubelka_layer` is the
    production evaluation.
    """
    K = np.asarray(K, dtype=float)
    S = np.asarray(S, dtype=float)
    a = 1.0 + K / S
    b = np.sqrt(a * a - 1.0)
    bSd = b * S * d
    den = a * np.sinh(bSd) + b * np.cosh(bSd)
    return np.sinh(bSd) / den, b / den


def over_ground(rho, tau, ground):
    """Reflectance of a layer ``(rho, tau)`` lying on a ground of reflectance ``ground``.

    The sum of the inter-reflections between layer and ground (the adding method
    for one layer)::

        R = rho + tau**2 ground / (1 - rho ground)
    """
    rho = np.asarray(rho, dtype=float)
    return rho + tau * tau * ground / (1.0 - rho * ground)
