"""Clear-sky irradiance: the Ineichen-Perez model with a monthly Linke turbidity.

References
----------
P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
coefficient", Solar Energy 73(3), 151-157, 2002, doi:10.1016/S0038-092X(02)00045-2.
R. Perez et al., "A new operational model for satellite-derived irradiances: description
and validation", Solar Energy 73(5), 307-317, 2002.
J. Remund, L. Wald, M. Lefèvre, T. Ranchin, J. Page, "Worldwide Linke turbidity
information", Proc. ISES Solar World Congress, Göteborg, 2003 (the climatology pvlib ships
as ``LinkeTurbidities.h5``).
"""

from __future__ import annotations

import numpy as np

from .solar import airmass_relative_KastenYoung1989, pressure_from_altitude

__all__ = ["LINKE_TURBIDITY", "LINKE_TURBIDITY_DEFAULT", "linke_turbidity",
           "clearsky_Ineichen2002"]

#: Monthly Linke turbidity (January..December) at the :data:`.daylight.PLACES` presets,
#: keyed by (latitude, longitude).  Read from the Remund et al. (2003) climatology in
#: pvlib 0.16.1's ``pvlib/data/LinkeTurbidities.h5`` with
#: ``pvlib.clearsky.lookup_linke_turbidity(t, lat, lon, interp_turbidity=False)`` on the
#: 15th of each month; tests/core/test_daylight.py checks these numbers against that file.
LINKE_TURBIDITY = {
    (51.5074, -0.1278): (3.35, 4.35, 3.95, 3.65, 4.6, 4.95, 4.4, 4.3, 3.85, 3.45, 3.1, 3.15),
    (52.3676, 4.9041): (2.55, 3.5, 3.2, 3.35, 3.75, 4.0, 4.5, 4.0, 3.6, 2.45, 2.75, 2.7),
    (40.4168, -3.7038): (3.2, 2.9, 3.3, 3.5, 3.95, 3.85, 4.2, 3.9, 3.7, 3.5, 3.05, 3.05),
    (40.7128, -74.006): (2.45, 2.7, 3.05, 3.5, 3.8, 3.85, 3.95, 3.25, 2.9, 2.65, 2.3, 2.25),
    (-33.8688, 151.2093): (2.85, 2.8, 2.65, 2.6, 2.45, 2.5, 2.65, 2.7, 2.85, 2.7, 2.85, 3.15),
    (1.2903, 103.8519): (4.65, 5.3, 5.05, 4.8, 5.0, 4.75, 4.8, 5.55, 5.3, 4.8, 4.9, 4.45),
    (30.0444, 31.2357): (4.6, 4.5, 4.85, 5.25, 4.3, 5.05, 5.85, 5.5, 5.3, 5.3, 4.3, 3.9),
    (64.1466, -21.9426): (2.0, 2.0, 2.0, 2.15, 2.45, 2.1, 2.25, 2.2, 2.1, 2.1, 2.05, 2.05),
}

#: Linke turbidity for places away from the presets: 3.5, the median of the preset
#: months above (a moderately turbid mid-latitude sky; Remund et al. 2003, fig. 1).
LINKE_TURBIDITY_DEFAULT = 3.5


def linke_turbidity(latitude, longitude, month):
    """Linke turbidity (air mass 2) of a month at a place.

    Parameters
    ----------
    latitude, longitude : float
        Degrees.  A place within 0.5° of a preset uses that preset's monthly values,
        any other place :data:`LINKE_TURBIDITY_DEFAULT`.
    month : array_like of int
        1..12.

    Returns
    -------
    numpy.ndarray
        Linke turbidity, dimensionless, shaped like ``month``.
    """
    month = np.asarray(month, dtype=int)
    for (lat, lon), table in LINKE_TURBIDITY.items():
        if abs(lat - latitude) <= 0.5 and abs((lon - longitude + 180) % 360 - 180) <= 0.5:
            return np.asarray(table, dtype=float)[month - 1]
    return np.full(month.shape, LINKE_TURBIDITY_DEFAULT)


def clearsky_Ineichen2002(apparent_zenith, linke_turbidity, altitude, dni_extra):
    """Clear-sky GHI, DNI and DHI, W/m^2 (Ineichen & Perez 2002).

    Parameters
    ----------
    apparent_zenith : array_like
        Refracted solar zenith, degrees.
    linke_turbidity : array_like
        Linke turbidity at air mass 2.
    altitude : float
        Site altitude, metres.
    dni_extra : array_like
        Extraterrestrial normal irradiance, W/m^2.

    Returns
    -------
    ghi, dni, dhi : numpy.ndarray
        Zero where the sun is below the horizon.

    Notes
    -----
    Ineichen & Perez (2002) eq. 8-10 with the "empirical correction" of the DNI (their
    eq. 11 and Perez et al. 2002), as pvlib's ``clearsky.ineichen`` with
    ``perez_enhancement=False``: air mass is Kasten & Young's (1989) times the
    standard-atmosphere pressure ratio; ``b = 0.664 + 0.163 / fh1``.
    """
    z = np.asarray(apparent_zenith, dtype=float)
    tl = np.asarray(linke_turbidity, dtype=float)
    cos_z = np.maximum(np.cos(np.radians(z)), 0.0)
    am = airmass_relative_KastenYoung1989(z) * pressure_from_altitude(altitude) / 101325.0
    fh1 = np.exp(-altitude / 8000.0)
    fh2 = np.exp(-altitude / 1250.0)
    cg1 = 5.09e-05 * altitude + 0.868
    cg2 = 3.92e-05 * altitude + 0.0387
    with np.errstate(invalid="ignore", divide="ignore"):
        ghi = cg1 * dni_extra * cos_z * np.fmax(np.exp(-cg2 * am * (fh1 + fh2 * (tl - 1.0))), 0.0)
        b = 0.664 + 0.163 / fh1
        bnci = dni_extra * np.fmax(b * np.exp(-0.09 * am * (tl - 1.0)), 0.0)
        bnci_2 = (1.0 - (0.1 - 0.2 * np.exp(-tl)) / (0.1 + 0.882 / fh1)) / cos_z
        bnci_2 = ghi * np.fmin(np.fmax(bnci_2, 0.0), 1e20)
        dni = np.minimum(bnci, bnci_2)
    up = np.isfinite(am) & (cos_z > 0)
    ghi = np.where(up, ghi, 0.0)
    dni = np.where(up, dni, 0.0)
    dhi = np.where(up, ghi - dni * cos_z, 0.0)
    return ghi, dni, dhi
