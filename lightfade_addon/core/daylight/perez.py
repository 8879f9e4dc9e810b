"""The Perez sky: clearness and brightness, the 1990 diffuse split and luminous efficacy.

The sky's diffuse irradiance is split as in the Perez 1990 transposition model (Perez et
al. 1990, eq. 9 with table 6's all-sites composite coefficients, as pvlib's
``irradiance.perez(model='allsitescomposite1990')``): an isotropic dome carrying
``(1 - F1) DHI``, a circumsolar point source at the sun whose horizontal irradiance is
``F1 DHI`` (``F1 DHI / max(cos Z, cos 85°)`` at normal incidence) and a horizon band
(a line source along the horizon) that gives ``F2 DHI sin(tilt)`` on a tilted plane.

Luminous efficacy follows Perez et al. 1990's direct-normal and diffuse-horizontal
models (table 4; the same coefficients as Radiance ``gendaylit``), with the precipitable
water from the dew point, ``W = exp(0.07 Td - 0.075)`` cm (same paper, eq. 3).

References
----------
R. Perez, P. Ineichen, R. Seals, J. Michalsky, R. Stewart, "Modeling daylight availability
and irradiance components from direct and global irradiance", Solar Energy 44(5),
271-289, 1990, doi:10.1016/0038-092X(90)90055-H.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "COS_85",
    "CLEARNESS_BINS",
    "PEREZ_1990_F",
    "EFFICACY_PEREZ_1990",
    "PRECIPITABLE_WATER_DEFAULT",
    "sky_clearness",
    "sky_brightness",
    "clearness_bin",
    "perez_F1_F2",
    "precipitable_water_from_dew_point",
    "luminous_efficacy_Perez1990",
    "luminous_efficacy",
]

#: Lower edges of the eight sky-clearness (ε) bins, overcast (1) to clear (8).
CLEARNESS_BINS = (1.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2)

#: Perez et al. (1990) table 6, all-sites composite: per ε bin F11, F12, F13, F21, F22, F23.
PEREZ_1990_F = np.array([
    [-0.0080, 0.5880, -0.0620, -0.0600, 0.0720, -0.0220],
    [0.1300, 0.6830, -0.1510, -0.0190, 0.0660, -0.0290],
    [0.3300, 0.4870, -0.2210, 0.0550, -0.0640, -0.0260],
    [0.5680, 0.1870, -0.2950, 0.1090, -0.1520, -0.0140],
    [0.8730, -0.3920, -0.3620, 0.2260, -0.4620, 0.0010],
    [1.1320, -1.2370, -0.4120, 0.2880, -0.8230, 0.0560],
    [1.0600, -1.6000, -0.3590, 0.2640, -1.1270, 0.1310],
    [0.6780, -0.3270, -0.2500, 0.1560, -1.3770, 0.2510],
])

#: Perez et al. (1990) table 4: per ε bin the coefficients a, b, c, d of the
#: direct-normal efficacy ``a + b W + c exp(5.73 Z - 5) + d Δ`` and of the
#: diffuse-horizontal efficacy ``a + b W + c cos Z + d ln Δ``, lm/W.
EFFICACY_PEREZ_1990 = {
    "direct": np.array([
        [57.20, 98.99, 109.83, 110.34, 106.36, 107.19, 105.75, 101.18],
        [-4.55, -3.46, -4.90, -5.84, -3.97, -1.25, 0.77, 1.58],
        [-2.98, -1.21, -1.71, -1.99, -1.75, -1.51, -1.26, -1.10],
        [117.12, 12.38, -8.81, -4.56, -6.16, -26.73, -34.44, -8.29],
    ]).T,
    "diffuse": np.array([
        [97.24, 107.22, 104.97, 102.39, 100.71, 106.42, 141.88, 152.23],
        [-0.46, 1.15, 2.96, 5.59, 5.94, 3.83, 1.90, 0.35],
        [12.00, 0.59, -5.53, -13.95, -22.75, -36.15, -53.24, -45.27],
        [-8.91, -3.95, -8.77, -13.90, -23.74, -28.83, -14.03, -7.98],
    ]).T,
}

#: Precipitable water, cm, where no dew point is known (the clear sky): 2 cm, Radiance
#: ``gendaylit``'s default for the same efficacy models.
PRECIPITABLE_WATER_DEFAULT = 2.0

_KAPPA = 1.041  # Perez et al. 1990, eq. 1, for the zenith in radians

#: cos 85°: the floor of cos Z in the circumsolar term ``F1 · a / max(cos Z, cos 85°)``
#: (Perez et al. 1990, eq. 9).
COS_85 = float(np.cos(np.radians(85.0)))


def sky_clearness(dni, dhi, zenith):
    """Perez sky clearness ε (Perez et al. 1990, eq. 1); NaN where DHI is 0.

    Parameters
    ----------
    dni, dhi : array_like
        Direct normal and diffuse horizontal irradiance, W/m^2.
    zenith : array_like
        Solar zenith, degrees.
    """
    z3 = _KAPPA * np.radians(np.asarray(zenith, dtype=float)) ** 3
    dhi = np.asarray(dhi, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(dhi > 0, (dhi + np.asarray(dni, dtype=float)) / dhi, np.nan)
    return (ratio + z3) / (1.0 + z3)


def sky_brightness(dhi, airmass, dni_extra):
    """Perez sky brightness Δ = DHI · m / E0n (Perez et al. 1990, eq. 2).

    Parameters
    ----------
    dhi : array_like
        Diffuse horizontal irradiance, W/m^2.
    airmass : array_like
        Relative air mass (Kasten & Young 1989, as pvlib's Perez).
    dni_extra : array_like
        Extraterrestrial normal irradiance, W/m^2.
    """
    return np.asarray(dhi, dtype=float) * airmass / dni_extra


def clearness_bin(epsilon):
    """Index 0..7 of the ε bin; NaN ε (no diffuse light) goes to the clearest bin."""
    eps = np.asarray(epsilon, dtype=float)
    b = np.digitize(np.where(np.isfinite(eps), eps, np.inf), CLEARNESS_BINS) - 1
    return np.clip(b, 0, 7)


def perez_F1_F2(epsilon, delta, zenith):
    """Circumsolar and horizon brightening coefficients F1, F2 (Perez et al. 1990, eq. 9).

    Parameters
    ----------
    epsilon, delta : array_like
        Sky clearness and brightness.
    zenith : array_like
        Solar zenith, degrees.

    Returns
    -------
    F1, F2 : numpy.ndarray
        F1 >= 0; F2 may be negative (a darkened horizon under overcast skies).
        Both 0 where ε is NaN (DHI = 0).
    """
    z = np.radians(np.asarray(zenith, dtype=float))
    c = PEREZ_1990_F[clearness_bin(epsilon)]
    F1 = np.maximum(c[..., 0] + c[..., 1] * delta + c[..., 2] * z, 0.0)
    F2 = c[..., 3] + c[..., 4] * delta + c[..., 5] * z
    ok = np.isfinite(epsilon) & np.isfinite(delta)
    return np.where(ok, F1, 0.0), np.where(ok, F2, 0.0)


def precipitable_water_from_dew_point(dew_point):
    """Atmospheric precipitable water, cm, from the surface dew point in °C.

    Perez et al. (1990) eq. 3 (after Wright, Perez & Michalsky 1989):
    ``W = exp(0.07 Td - 0.075)``.
    """
    return np.exp(0.07 * np.asarray(dew_point, dtype=float) - 0.075)


def luminous_efficacy_Perez1990(epsilon, delta, zenith,
                                precipitable_water=PRECIPITABLE_WATER_DEFAULT):
    """Luminous efficacies of direct normal and diffuse horizontal light, lm/W.

    Parameters
    ----------
    epsilon, delta : array_like
        Perez sky clearness and brightness.
    zenith : array_like
        Solar zenith, degrees.
    precipitable_water : array_like
        Precipitable water W, cm.

    Returns
    -------
    K_direct, K_diffuse : numpy.ndarray
        lm/W: direct normal illuminance over DNI, diffuse horizontal illuminance over DHI.
        ``K_direct`` is clipped at 0 (as in Radiance gendaylit); Δ is floored at 0.01
        inside the logarithm.

    Notes
    -----
    Perez et al. (1990) table 4 and eq. 4: the direct efficacy
    ``a + b W + c exp(5.73 Z - 5) + d Δ`` and the diffuse one
    ``a + b W + c cos Z + d ln Δ``, Z in radians, coefficients per ε bin.
    """
    b = clearness_bin(epsilon)
    z = np.radians(np.asarray(zenith, dtype=float))
    W = np.asarray(precipitable_water, dtype=float)
    d = np.where(np.isfinite(delta), delta, 0.0)
    cd = EFFICACY_PEREZ_1990["direct"][b]
    cf = EFFICACY_PEREZ_1990["diffuse"][b]
    K_b = cd[..., 0] + cd[..., 1] * W + cd[..., 2] * np.exp(5.73 * z - 5.0) + cd[..., 3] * d
    K_d = (cf[..., 0] + cf[..., 1] * W + cf[..., 2] * np.cos(z)
           + cf[..., 3] * np.log(np.maximum(d, 0.01)))
    return np.maximum(K_b, 0.0), K_d


def luminous_efficacy(epsilon, delta, zenith, precipitable_water=PRECIPITABLE_WATER_DEFAULT,
                      method="Perez1990"):
    """Luminous efficacies (direct normal, diffuse horizontal) in lm/W, by ``method``.

    Only ``"Perez1990"`` (:func:`luminous_efficacy_Perez1990`) is implemented: it is the
    model Radiance ``gendaylit``/``gendaymtx`` users know and it responds to the sky
    (clear skies ~100 lm/W direct, overcast ~120 lm/W diffuse).
    """
    if method != "Perez1990":
        raise ValueError(f"unknown luminous efficacy method {method!r}; use 'Perez1990'")
    return luminous_efficacy_Perez1990(epsilon, delta, zenith, precipitable_water)
