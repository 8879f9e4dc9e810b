"""The fused, cache-blocked evaluation of one time step's optics.

:class:`LayeredStack` evaluates, for a chunk of samples whose layers hold volume
fractions ``f``, the stack reflectance and the absorbed-light rate of every
colourant in every layer (the exponent of equation 3 per unit time). It is the
same mathematics as :func:`.kubelka.kubelka_layer` followed by
:func:`.flux.boundary_fluxes` and a trapezoidal integral, organised for speed:

* arrays are layer-major, ``(N, n)``, with the chunk's samples × wavelengths
  flattened into ``n`` columns, so that the sweeps run over contiguous rows;
* the layers are processed in blocks of a few rows: a block's Kubelka optics are
  computed just before the backward (adding) sweep consumes them, and its
  fluence and absorption just after the forward sweep produces them, so the
  temporaries stay in cache and only ``R`` and ``tau / D`` make the round trip
  through memory.

The tests check it against the plain functions and against a dense solve of the
paper's Figure 3 system.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import trapezoid

from .kubelka import _X_FLOOR

__all__ = ["LayeredStack", "trapezoid_weights"]

#: Target size in bytes of one block array; a block's dozen temporaries then fit
#: in a core's L2 cache.
_BLOCK_BYTES = 1 << 17


def trapezoid_weights(wavelengths):
    """Weights ``w`` with ``sum(w * y) = trapz(y, wavelengths)`` (nm).

    Examples
    --------
    >>> trapezoid_weights([400.0, 410.0, 430.0]).tolist()
    [5.0, 15.0, 10.0]
    """
    lam = np.asarray(wavelengths, dtype=float)
    if lam.size < 2:
        return np.zeros_like(lam)
    # the rule is linear in y: its weights are the integrals of the unit vectors
    return trapezoid(np.eye(lam.size), lam, axis=1)


#: Largest ``y = x**2`` (x = alpha d) for which the series below are used: their first
#: omitted terms are then below 4e-14 relative.
THIN_LAYER_Y = 1e-3
#: tanh(x)/x = 1 - y/3 + 2y²/15 - 17y³/315 + ...;  sech(x) = 1 - y/2 + 5y²/24 - 61y³/720 + ...
_TANHC = (-17.0 / 315.0, 2.0 / 15.0, -1.0 / 3.0)
_SECH = (-61.0 / 720.0, 5.0 / 24.0, -0.5)


def kubelka_into(Kd, Sd, rho, tau, x, m, g, thin=None):
    """:func:`.kubelka.kubelka_layer` for optical depths ``Kd``, ``Sd``, in place.

    Writes ``rho`` and ``tau``; ``x``, ``m``, ``g`` are scratch arrays of the same
    shape. Optically thin layers (``(alpha d)**2 <= THIN_LAYER_Y``, as in the
    1024-layer reference) may use the Taylor series of ``tanh(x)/x`` and ``sech(x)``
    in ``y = x**2``: multiply-adds only, equal to the closed form to ~1e-13.
    ``thin=None`` decides from this block; callers that need the same path for every
    block (bitwise reproducibility) decide once and pass True or False.
    """
    np.add(Sd, Sd, out=x)
    x += Kd
    x *= Kd                            # y = (alpha d)^2 = Kd (Kd + 2 Sd)
    if thin is None:
        thin = x.max() <= THIN_LAYER_Y
    if thin:
        _thin_layer_into(Kd, Sd, rho, tau, x, m, g)
        return
    x += _X_FLOOR * _X_FLOOR           # keeps x > 0 where K = 0; invisible otherwise
    np.sqrt(x, out=x)                  # x = alpha d
    np.multiply(x, -2.0, out=m)
    np.expm1(m, out=m)                 # m = expm1(-2x)
    np.divide(m, x, out=g)
    np.negative(g, out=g)              # g = -m / x
    np.add(Kd, Sd, out=rho)
    rho *= g
    rho += m
    rho += 2.0                         # den = 2 + m + (Kd + Sd) g
    np.negative(x, out=x)
    np.exp(x, out=x)
    x *= 2.0
    np.divide(x, rho, out=tau)         # tau = 2 exp(-x) / den
    g *= Sd
    np.divide(g, rho, out=rho)         # rho = Sd g / den


def _series_into(y, coefficients, out):
    """``1 + c1 y + c2 y² + c3 y³`` by Horner's rule into ``out``; coefficients (c3, c2, c1)."""
    c3, c2, c1 = coefficients
    np.multiply(y, c3, out=out)
    out += c2
    out *= y
    out += c1
    out *= y
    out += 1.0


def _thin_layer_into(Kd, Sd, rho, tau, y, t, s):
    """Kubelka's formulae as series in ``y = (alpha d)^2`` (``y`` given), in place.

    ``rho = Sd t / (1 + (Kd + Sd) t)`` and ``tau = sech / (1 + (Kd + Sd) t)`` with
    ``t = tanh(x)/x``: the closed form divided by ``cosh x``.
    """
    _series_into(y, _TANHC, t)         # t = tanh(x) / x
    _series_into(y, _SECH, s)          # s = sech(x)
    np.add(Kd, Sd, out=y)
    y *= t
    y += 1.0                           # den = 1 + (Kd + Sd) t
    np.divide(s, y, out=tau)
    t *= Sd
    np.divide(t, y, out=rho)


class LayeredStack:
    """Optics of ``B`` samples × ``W`` wavelengths in ``N`` equal layers.

    Parameters
    ----------
    A, S : ndarray, shape (C, W)
        Colourant absorption and scattering per unit thickness at full
        concentration.
    beta : ndarray, shape (C,)
        Sensitivities.
    E0 : ndarray, shape (W,)
        Irradiance on the top surface.
    ground : ndarray, shape (W,)
        Substrate reflectance.
    wavelengths : ndarray, shape (W,)
        nm, for the trapezoidal rule.
    thickness : float
        Medium thickness; each layer is ``thickness / N`` thick.
    N, B : int
        Layers and samples.
    fmax : float or ndarray, shape (C,)
        Upper bound of each colourant's volume fraction during the run (1 unless
        yields can raise a product above 1).
    kinetics : {"first-order", "paper", "shared"}
        ``"paper"``: the rate per unit of colourant carries ``mu_a = f A_j``
        (equation 3 as printed); ``"first-order"``: ``A_j`` (each molecule absorbs
        for itself); ``"shared"``: the light absorbed by all the colourants of the
        layer per unit of colourant, ``sum_i f_i A_i / sum_i f_i`` (photosensitised
        fading). See :mod:`.fading`.
    """

    def __init__(self, A, S, beta, E0, ground, wavelengths, thickness, N, B, fmax=1.0,
                 kinetics="first-order"):
        C, W = A.shape
        d = thickness / N
        n = B * W
        # The thin-layer series is used for every block or for none (so results do not
        # depend on how samples are chunked), judged by the largest possible layer.
        Kmax = (np.asarray(fmax) * A.T).sum(axis=1) * d
        Smax = (np.asarray(fmax) * S.T).sum(axis=1) * d
        self.thin = bool(np.max(Kmax * (Kmax + 2 * Smax)) <= THIN_LAYER_Y)
        self.N, self.B, self.C, self.W, self.n = N, B, C, W, n
        self.Ad = np.ascontiguousarray(A * d)        # (C, W) optical depth of a layer
        self.Sd = np.ascontiguousarray(S * d)
        # beta_j * trapz(A_j E0 F): the 1/2 turns the sum of a layer's two boundary
        # fluences into its mean (Section 3.1, "the average of the fluence rates").
        self.Wr = np.ascontiguousarray((0.5 * trapezoid_weights(wavelengths) * E0 * A).T)
        self.beta = np.asarray(beta, dtype=float)
        self.times_f = kinetics == "paper"
        self.shared = kinetics == "shared"
        self.ground = np.tile(ground, B)
        self.rows = max(1, min(N, _BLOCK_BYTES // (8 * n)))
        self.R = np.empty((N + 1, n))                # reflectance below each boundary
        self.G = np.empty((N, n))                    # tau_i / D_i, the forward factors
        shape = (self.rows, n)
        self._Kd, self._Sd, self._rho, self._tau, self._x, self._m, self._g = (
            np.empty(shape) for _ in range(7))
        self._Ed = np.empty((self.rows + 1, n))
        self._tmp = np.empty(n)

    def _blocks(self):
        r = self.rows
        return [(i, min(i + r, self.N)) for i in range(0, self.N, r)]

    def _optics(self, f, i0, i1):
        """Kubelka optics of layers ``i0:i1`` into the block buffers; returns views."""
        k = i1 - i0
        fb = f[i0:i1].reshape(k * self.B, self.C)
        Kd, Sd = self._Kd[:k], self._Sd[:k]
        np.matmul(fb, self.Ad, out=Kd.reshape(k * self.B, self.W))
        np.matmul(fb, self.Sd, out=Sd.reshape(k * self.B, self.W))
        rho, tau = self._rho[:k], self._tau[:k]
        kubelka_into(Kd, Sd, rho, tau, self._x[:k], self._m[:k], self._g[:k], self.thin)
        return rho, tau

    def backward(self, f):
        """Adding sweep from the ground up: fills ``R`` and ``G``; returns ``R[0]``.

        ``R[i] = rho_i + tau_i^2 R[i+1] / D_i`` with ``D_i = 1 - rho_i R[i+1]``
        (equations 1–2 with ``E_u[i] = R[i] E_d[i]``), and ``G_i = tau_i / D_i``.
        """
        R, G, tmp = self.R, self.G, self._tmp
        R[self.N] = self.ground
        with np.errstate(divide="ignore"):
            for i0, i1 in reversed(self._blocks()):
                rho, tau = self._optics(f, i0, i1)
                tau2 = self._m[: i1 - i0]
                np.multiply(tau, tau, out=tau2)
                # R[i] = rho + tau^2 / (1 / R[i+1] - rho): four row operations; where
                # R[i+1] = 0 the reciprocal is inf and R[i] = rho, as it should be.
                for k in range(i1 - i0 - 1, -1, -1):
                    i = i0 + k
                    np.divide(1.0, R[i + 1], out=tmp)
                    tmp -= rho[k]
                    np.divide(tau2[k], tmp, out=tmp)
                    np.add(rho[k], tmp, out=R[i])
                D = self._x[: i1 - i0]                  # D = 1 - rho R[i+1], per block
                np.multiply(rho, R[i0 + 1:i1 + 1], out=D)
                np.subtract(1.0, D, out=D)
                np.divide(tau, D, out=G[i0:i1])
        return R[0]

    def reflectance(self, f):
        """Stack reflectance (B, W) for fractions ``f`` (N, B, C)."""
        return self.backward(f).reshape(self.B, self.W).copy()

    def rates(self, f):
        """Equation (3)'s exponent per unit time, and the reflectance.

        Parameters
        ----------
        f : ndarray, shape (N, B, C)
            Volume fractions, top layer first.

        Returns
        -------
        rate : ndarray, shape (N, B, C)
            ``beta_j * trapz(mu_a_j * F)`` with ``F`` the layer's mean fluence rate
            under the irradiance ``E0`` and ``mu_a_j = f A_j`` (``"paper"``
            kinetics) or ``A_j`` (``"first-order"``); with ``"shared"``,
            ``beta_j * sum_i f_i trapz(A_i F) / sum_i f_i``.
        R0 : ndarray, shape (B, W)
            The stack reflectance at these fractions.
        """
        N, B, C, W = self.N, self.B, self.C, self.W
        R0 = self.reflectance(f)
        R, G = self.R, self.G
        rate = np.empty((N, B, C))
        Ed = self._Ed
        Ed[0] = 1.0                      # unit irradiance: E0 is folded into Wr
        for i0, i1 in self._blocks():
            k = i1 - i0
            for j in range(k):           # E_d[i+1] = E_d[i] tau_i / D_i
                np.multiply(Ed[j], G[i0 + j], out=Ed[j + 1])
            F = self._Kd[:k]             # reuse block buffers
            Fb = self._Sd[:k]
            # F at boundaries i0..i1: E_d (1 + R); the layer sums F[i] + F[i+1]
            np.add(R[i0:i1], 1.0, out=F)
            F *= Ed[:k]
            np.add(R[i0 + 1:i1 + 1], 1.0, out=Fb)
            Fb *= Ed[1:k + 1]
            F += Fb
            np.matmul(F.reshape(k * B, W), self.Wr, out=rate[i0:i1].reshape(k * B, C))
            Ed[0] = Ed[k]
        if self.shared:                  # sum_i f_i a_i / sum_i f_i, for every j
            total = f.sum(axis=2, keepdims=True)
            mean = np.einsum("nbc,nbc->nb", rate, f)[..., None]
            np.divide(mean, total, out=rate[..., :1], where=total > 0)
            rate[..., :1][total <= 0] = 0.0
            rate[...] = rate[..., :1]
        rate *= self.beta
        if self.times_f:
            rate *= f
        return rate, R0
