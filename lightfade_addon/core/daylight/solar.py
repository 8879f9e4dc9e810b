"""The sun's position and the atmosphere along its ray: numpy only.

Solar position follows Meeus's low-accuracy solar coordinates (Meeus 1998, chapter 25,
"Solar coordinates"; the algorithm behind NOAA's solar calculator) with Greenwich apparent
sidereal time (chapter 12), the solar parallax and the refraction correction of NREL's SPA
(Reda & Andreas 2008, equations 37-43).  Over a year at five latitudes from 64° N to 34° S
it stays within 0.009° (angular separation of the sun's directions) of NREL SPA as pvlib
implements it; tests/core/test_daylight.py checks 0.01°.  A 512-pixel-wide sky map's pixels
are 0.7° across.

Angles are in degrees; azimuth from geographic north, clockwise (east = 90°), as in SPA.
Times are ``numpy.datetime64`` in UTC (naive values are read as UTC).

References
----------
J. Meeus, *Astronomical Algorithms*, 2nd ed., Willmann-Bell, 1998, ch. 12, 22 and 25.
I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
NREL/TP-560-34302, revised 2008, doi:10.2172/15003974.
J. W. Spencer, "Fourier series representation of the position of the sun", Search 2(5),
172, 1971.
F. Kasten, A. T. Young, "Revised optical air mass tables and approximation formula",
Applied Optics 28(22), 4735-4738, 1989.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "SOLAR_CONSTANT",
    "julian_day",
    "day_of_year",
    "sun_position_Meeus1998",
    "sun_position",
    "refraction_SPA",
    "dni_extra_Spencer1971",
    "airmass_relative_KastenYoung1989",
    "pressure_from_altitude",
]

#: Solar constant, W/m^2 (pvlib's default for ``get_extra_radiation``).
SOLAR_CONSTANT = 1366.1

_J2000 = 2451545.0
_UNIX_EPOCH_JD = 2440587.5


def julian_day(times):
    """Julian day (UT) of ``numpy.datetime64`` times, as float64 days.

    Parameters
    ----------
    times : array_like of numpy.datetime64
        UTC instants.

    Returns
    -------
    numpy.ndarray
        Julian day numbers (Meeus 1998, ch. 7); 2451545.0 is 2000-01-01 12:00 UT.
    """
    t = np.asarray(times, dtype="datetime64[ns]")
    seconds = t.astype("int64") / 1e9
    return _UNIX_EPOCH_JD + seconds / 86400.0


def day_of_year(times):
    """Day of the year, 1 on January 1st (float, with the fraction of the day)."""
    t = np.asarray(times, dtype="datetime64[ns]")
    start = t.astype("datetime64[Y]").astype("datetime64[ns]")
    return 1.0 + (t - start).astype("int64") / 86.4e12


def refraction_SPA(elevation, pressure=101325.0, temperature=12.0):
    """Atmospheric refraction of the sun's elevation, degrees (Reda & Andreas 2008, eq. 42).

    Parameters
    ----------
    elevation : array_like
        Topocentric elevation without refraction, degrees.
    pressure : float or array_like
        Surface pressure, Pa.
    temperature : float
        Air temperature, °C.

    Returns
    -------
    numpy.ndarray
        The correction to add, degrees; zero where the sun is more than its radius plus
        0.5667° (SPA's ``atmos_refract``) below the horizon.
    """
    e0 = np.asarray(elevation, dtype=float)
    corr = ((np.asarray(pressure) / 100.0 / 1010.0) * (283.0 / (273.0 + temperature))
            * 1.02 / (60.0 * np.tan(np.radians(e0 + 10.3 / (e0 + 5.11)))))
    return np.where(e0 >= -(0.26667 + 0.5667), corr, 0.0)


def sun_position_Meeus1998(latitude, longitude, times, pressure=101325.0,
                           temperature=12.0, refraction=True):
    """Topocentric solar zenith and azimuth, degrees (Meeus 1998 ch. 25, SPA refraction).

    Parameters
    ----------
    latitude, longitude : float
        Observer, degrees (north and east positive).
    times : array_like of numpy.datetime64
        UTC instants.
    pressure : float
        Surface pressure for refraction, Pa.
    temperature : float
        Air temperature for refraction, °C.
    refraction : bool
        Return the apparent (refracted) zenith, as the sun is seen; else the geometric one.

    Returns
    -------
    zenith, azimuth : numpy.ndarray
        Degrees; azimuth clockwise from north in [0, 360).

    Notes
    -----
    With T the Julian centuries from J2000 (UT is used for TT; ΔT ≈ 70 s moves the sun
    by 0.0008°): mean longitude L0, mean anomaly M, equation of centre C (Meeus eq. 25.2,
    25.3, 25.4), apparent longitude λ = L0 + C - 0.00569 - 0.00478 sin Ω, true obliquity
    ε = ε0 + 0.00256 cos Ω (eq. 22.2, 25.8); right ascension and declination (eq. 25.6,
    25.7); Greenwich mean sidereal time (eq. 12.4) plus the nutation in right ascension
    Δψ cos ε; the hour angle H; the horizon coordinates (eq. 13.5, 13.6) and the solar
    parallax 8.794" cos(elevation) (SPA eq. 38-40 to first order).
    """
    jd = julian_day(times)
    T = (jd - _J2000) / 36525.0
    L0 = 280.46646 + T * (36000.76983 + 0.0003032 * T)
    M = np.radians(357.52911 + T * (35999.05029 - 0.0001537 * T))
    C = ((1.914602 - T * (0.004817 + 0.000014 * T)) * np.sin(M)
         + (0.019993 - 0.000101 * T) * np.sin(2 * M) + 0.000289 * np.sin(3 * M))
    omega = np.radians(125.04 - 1934.136 * T)
    lam = np.radians(L0 + C - 0.00569 - 0.00478 * np.sin(omega))
    eps0 = 23.0 + (26.0 + (21.448 - T * (46.8150 + T * (0.00059 - 0.001813 * T))) / 60.0) / 60.0
    eps = np.radians(eps0 + 0.00256 * np.cos(omega))
    alpha = np.arctan2(np.cos(eps) * np.sin(lam), np.cos(lam))
    delta = np.arcsin(np.sin(eps) * np.sin(lam))
    d = jd - _J2000
    gmst = 280.46061837 + 360.98564736629 * d + T * T * (0.000387933 - T / 38710000.0)
    nutation_ra = -0.004778 * np.sin(omega) * np.cos(eps)
    H = np.radians(np.mod(gmst + nutation_ra + longitude, 360.0)) - alpha
    phi = np.radians(latitude)
    sin_e = np.sin(phi) * np.sin(delta) + np.cos(phi) * np.cos(delta) * np.cos(H)
    e0 = np.degrees(np.arcsin(np.clip(sin_e, -1.0, 1.0)))
    e0 = e0 - (8.794 / 3600.0) * np.cos(np.radians(e0))
    azimuth = np.degrees(np.arctan2(np.sin(H), np.cos(H) * np.sin(phi)
                                    - np.tan(delta) * np.cos(phi))) + 180.0
    if refraction:
        e0 = e0 + refraction_SPA(e0, pressure, temperature)
    return 90.0 - e0, np.mod(azimuth, 360.0)


def sun_position(place, times, refraction=True):
    """Solar zenith and azimuth for a place, degrees.

    Parameters
    ----------
    place : Place
        Its ``latitude``, ``longitude`` and ``altitude`` (metres, for the refraction's
        pressure) are used.
    times : array_like of numpy.datetime64
        UTC instants.
    refraction : bool
        Apparent zenith (True, the sun as seen) or geometric.

    Returns
    -------
    zenith, azimuth : numpy.ndarray
        Degrees; azimuth clockwise from geographic north (east = 90°).

    Examples
    --------
    >>> from lightfade_addon.core.daylight.annual import PLACES
    >>> z, a = sun_position(PLACES["London"], np.array(["2025-06-21T12:00"], "datetime64[m]"))
    >>> round(float(z[0]))
    28
    """
    return sun_position_Meeus1998(place.latitude, place.longitude, times,
                                  pressure=pressure_from_altitude(place.altitude),
                                  refraction=refraction)


def dni_extra_Spencer1971(doy, solar_constant=SOLAR_CONSTANT):
    """Extraterrestrial normal irradiance, W/m^2 (Spencer 1971's Earth-Sun distance).

    Parameters
    ----------
    doy : array_like
        Day of the year (1 on January 1st).
    """
    B = 2.0 * np.pi * (np.asarray(doy, dtype=float) - 1.0) / 365.0
    r = (1.00011 + 0.034221 * np.cos(B) + 0.00128 * np.sin(B)
         + 0.000719 * np.cos(2 * B) + 7.7e-05 * np.sin(2 * B))
    return solar_constant * r


def airmass_relative_KastenYoung1989(zenith):
    """Relative optical air mass (Kasten & Young 1989), NaN below the horizon.

    Parameters
    ----------
    zenith : array_like
        Apparent solar zenith, degrees.
    """
    z = np.asarray(zenith, dtype=float)
    zc = np.where(z > 90.0, np.nan, z)
    return 1.0 / (np.cos(np.radians(zc)) + 0.50572 * (96.07995 - zc) ** -1.6364)


def pressure_from_altitude(altitude):
    """Standard-atmosphere surface pressure, Pa, at an altitude in metres.

    The ICAO standard atmosphere as pvlib's ``alt2pres`` writes it.
    """
    return 100.0 * ((44331.514 - np.asarray(altitude, dtype=float)) / 11880.516) ** (1 / 0.1902632)
