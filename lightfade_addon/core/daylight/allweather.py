"""The Perez all-weather sky luminance distribution (Perez, Seals & Michalsky 1993).

The relative luminance of a sky element at zenith angle ζ and angle γ from the sun is

    lv(ζ, γ) = (1 + a exp(b / cos ζ)) · (1 + c exp(d γ) + e cos² γ)     (their eq. 1)

with a..e from the sky clearness ε bin, the sky brightness Δ and the solar zenith Z
(eq. 6-8, table 1).  As Radiance ``gendaymtx`` does, each sample's distribution is
normalised so that its cosine-weighted integral over the sky is that sample's diffuse
horizontal light; the sun (DNI) is added separately at its position.

References
----------
R. Perez, R. Seals, J. Michalsky, "All-weather model for sky luminance distribution -
preliminary configuration and validation", Solar Energy 50(3), 235-245, 1993,
doi:10.1016/0038-092X(93)90017-I.  Table 1 as in Radiance ``gendaylit.c``/``gendaymtx.c``
(``coeff_perez``); the Δ >= 0.2 floor for 1.065 < ε < 2.8 and cos ζ >= 0.01 as there
and in Radiance's ``perezlum.cal``.
"""

from __future__ import annotations

import numpy as np

from .perez import clearness_bin
from .skygrid import grid, scene_to_enu

__all__ = ["PEREZ_1993", "perez1993_parameters", "relative_luminance_Perez1993",
           "diffuse_sky_Perez1993"]

#: Perez et al. (1993) table 1: per ε bin, for a, b, c, d, e, the four coefficients
#: (x0, x1, x2, x3) of ``x0 + x1 Z + Δ (x2 + x3 Z)`` (bin 1's c and d have their own form).
PEREZ_1993 = np.array([
    [1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004,
     1.2375, 1.0000, 1.8734, 0.6297, 0.9738, 0.2809, 0.0356, -0.1246, -0.5718, 0.9938],
    [-1.2219, -0.7730, 1.4148, 1.1016, -0.2054, 0.0367, -3.9128, 0.9156, 6.9750, 0.1774,
     6.4477, -0.1239, -1.5798, -0.5081, -1.7812, 0.1080, 0.2624, 0.0672, -0.2190, -0.4285],
    [-1.1000, -0.2515, 0.8952, 0.0156, 0.2782, -0.1812, -4.5000, 1.1766, 24.7219, -13.0812,
     -37.7000, 34.8438, -5.0000, 1.5218, 3.9229, -2.6204, -0.0156, 0.1597, 0.4199, -0.5562],
    [-0.5484, -0.6654, -0.2672, 0.7117, 0.7234, -0.6219, -5.6812, 2.6297, 33.3389, -18.3000,
     -62.2500, 52.0781, -3.5000, 0.0016, 1.1477, 0.1062, 0.4659, -0.3296, -0.0876, -0.0329],
    [-0.6000, -0.3566, -2.5000, 2.3250, 0.2937, 0.0496, -5.6812, 1.8415, 21.0000, -4.7656,
     -21.5906, 7.2492, -3.5000, -0.1554, 1.4062, 0.3988, 0.0032, 0.0766, -0.0656, -0.1294],
    [-1.0156, -0.3670, 1.0078, 1.4051, 0.2875, -0.5328, -3.8500, 3.3750, 14.0000, -0.9999,
     -7.1406, 7.5469, -3.4000, -0.1078, -1.0750, 1.5702, -0.0672, 0.4016, 0.3017, -0.4844],
    [-1.0000, 0.0211, 0.5025, -0.5119, -0.3000, 0.1922, 0.7023, -1.6317, 19.0000, -5.0000,
     1.2438, -1.9094, -4.0000, 0.0250, 0.3844, 0.2656, 1.0468, -0.3788, -2.4517, 1.4656],
    [-1.0500, 0.0289, 0.4260, 0.3590, -0.3250, 0.1156, 0.7781, 0.0025, 31.0625, -14.5000,
     -46.1148, 55.3750, -7.2312, 0.4050, 13.3500, 0.6234, 1.5000, -0.6426, 1.8564, 0.5636],
]).reshape(8, 5, 4)


def perez1993_parameters(epsilon, delta, zenith):
    """The five parameters a, b, c, d, e of the all-weather model (Perez et al. 1993).

    Parameters
    ----------
    epsilon, delta : array_like
        Sky clearness and brightness (:mod:`.perez`).
    zenith : array_like
        Solar zenith, degrees.

    Returns
    -------
    numpy.ndarray
        (..., 5): a, b, c, d, e.
    """
    eps = np.asarray(epsilon, dtype=float)
    Z = np.radians(np.asarray(zenith, dtype=float))
    D = np.where(np.isfinite(delta), delta, 0.0)
    D = np.where((eps > 1.065) & (eps < 2.8), np.maximum(D, 0.2), D)
    b = clearness_bin(eps)
    x = PEREZ_1993[b]                                            # (..., 5, 4)
    p = x[..., 0] + x[..., 1] * Z[..., None] + D[..., None] * (x[..., 2] + x[..., 3] * Z[..., None])
    first = b == 0                                               # eq. 7-8, overcast bin
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        c1 = (np.exp(np.power(np.abs(D * (x[..., 2, 0] + x[..., 2, 1] * Z)), x[..., 2, 2]))
              - x[..., 2, 3])
        d1 = -np.exp(D * (x[..., 3, 0] + x[..., 3, 1] * Z)) + x[..., 3, 2] + D * x[..., 3, 3]
    p[..., 2] = np.where(first, c1, p[..., 2])
    p[..., 3] = np.where(first, d1, p[..., 3])
    return p


def relative_luminance_Perez1993(params, cos_zeta, gamma, cos_gamma=None):
    """lv(ζ, γ) (Perez et al. 1993, eq. 1), cos ζ floored at 0.01 as in ``perezlum.cal``.

    Parameters
    ----------
    params : array_like
        (..., 5) from :func:`perez1993_parameters`, broadcast against the others.
    cos_zeta : array_like
        Cosine of the sky element's zenith angle.
    gamma : array_like
        Angle between the sky element and the sun, radians.
    cos_gamma : array_like, optional
        cos γ when already known.
    """
    p = np.asarray(params)
    a, b, c, d, e = (p[..., i] for i in range(5))
    cos_gamma = np.cos(gamma) if cos_gamma is None else cos_gamma
    grad = 1.0 + a * np.exp(np.minimum(b / np.maximum(cos_zeta, 0.01), 50.0))
    indic = 1.0 + c * np.exp(d * gamma) + e * cos_gamma * cos_gamma
    return grad * indic


def diffuse_sky_Perez1993(samples, weights, width, north, chunk=256):
    """Annual diffuse sky, all-weather distribution, on the upper half of a map.

    Parameters
    ----------
    samples : SkySamples
        Sun positions and sky clearness and brightness.
    weights : numpy.ndarray
        Each sample's diffuse horizontal dose (e.g. ``K_d · DHI · Δt``).
    width : int
        Width of the grid the distribution is evaluated on.
    north : float
        Scene north angle, degrees.

    Returns
    -------
    numpy.ndarray
        (width // 4, width) radiance-time of the sky rows (horizon first), whose
        cosine-weighted integral is ``weights.sum()``.  Negative relative luminances
        (the model's fit can dip below 0 at extreme parameters) are set to 0; a sample
        whose sky is then dark everywhere (1 in 8770 in the Greensboro TMY3 year) is
        spread isotropically.
    """
    d, omega = grid(width)
    H = d.shape[0]
    sky_d = d[H // 2:]                                           # (H/2, W, 3)
    enu = scene_to_enu(sky_d.reshape(-1, 3), north)              # (P, 3)
    cos_zeta = enu[:, 2]
    w_cos = (omega[H // 2:] * sky_d[..., 2]).reshape(-1)         # Ω cos ζ per pixel
    s = samples
    # float32 inside the loop: the distribution is a smooth shape, normalised per sample
    params = perez1993_parameters(s.epsilon, s.delta, s.zenith).astype(np.float32)
    z, a = np.radians(s.zenith), np.radians(s.azimuth)
    sun = np.stack([np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z)], -1).astype(np.float32)
    enu32, w_cos = enu.astype(np.float32), w_cos.astype(np.float32)
    cz32 = cos_zeta.astype(np.float32)[None, :]
    acc = np.zeros(enu.shape[0])
    for i in range(0, len(weights), chunk):
        sl = slice(i, i + chunk)
        # elementwise products, not BLAS: (n, 3) x (3, P) is too thin for a threaded gemm
        sv = sun[sl]
        cos_g = sv[:, :1] * enu32[:, 0] + sv[:, 1:2] * enu32[:, 1] + sv[:, 2:] * enu32[:, 2]
        np.clip(cos_g, -1.0, 1.0, out=cos_g)                    # (n, P)
        lv = relative_luminance_Perez1993(params[sl, None, :], cz32, np.arccos(cos_g), cos_g)
        np.maximum(lv, 0.0, out=lv)
        norm = np.einsum("ij,j->i", lv, w_cos, dtype=np.float64)
        bad = ~(norm > 0)                   # no positive luminance anywhere: isotropic
        lv[bad] = 1.0
        norm[bad] = w_cos.sum()
        acc += np.einsum("i,ij->j", weights[sl] / norm, lv, dtype=np.float64)
    return acc.reshape(H // 2, -1)
