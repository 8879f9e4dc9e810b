"""Clear-sky irradiance: the Ineichen-Perez model with a monthly Linke turbidity.

References
----------
P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
coefficient", Solar Energy 73(3), 151-157, 2002, doi:10.1016/S0038-092X(02)00045-2.
R. Perez et al., "A new operational model for satellite-derived irradiances: description
and validation", Solar Energy 73(5), 307-317, 2002.
J. Remund, L. Wald, M. Lefèvre, T. Ranchin, J. Page, "Worldwide Linke turbidity
information", Proc. ISES Solar World Congress, Göteborg, 2003 (the climatology pvlib ships
as ``LinkeTurbidities.h5``; LightFade bundles it resampled to 1°, ``data/linke_turbidity.npz``,
made by ``tools/linke_turbidity.py``).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from .solar import airmass_relative_KastenYoung1989, pressure_from_altitude

__all__ = ["CLIMATOLOGY_FILE", "linke_turbidity", "clearsky_Ineichen2002"]

#: The worldwide monthly climatology: ``tl20`` uint8 (12, H, W), 20 × T_L on cells of
#: ``step_deg`` degrees, written by ``tools/linke_turbidity.py`` from pvlib's
#: ``LinkeTurbidities.h5`` (Remund et al. 2003; source and licence inside the file).
CLIMATOLOGY_FILE = Path(__file__).parent.parent / "data" / "linke_turbidity.npz"


@functools.lru_cache(maxsize=1)
def _climatology():
    """``(T_L (12, H, W) float, cell size in degrees)`` read once from the bundled file."""
    with np.load(CLIMATOLOGY_FILE) as data:
        return data["tl20"].astype(float) / 20.0, float(data["step_deg"])


def linke_turbidity(latitude, longitude, month):
    """Monthly Linke turbidity (air mass 2) at any place on Earth.

    Parameters
    ----------
    latitude : float
        Degrees north, -90..90.
    longitude : float
        Degrees east (any value; wrapped).
    month : array_like of int
        1..12.

    Returns
    -------
    numpy.ndarray
        Linke turbidity, dimensionless, shaped like ``month``.

    Notes
    -----
    Bilinear interpolation in latitude and longitude between the centres of the
    climatology's cells (longitude wraps at ±180°, latitude is held at the outermost row
    near the poles); one value per month, as pvlib's
    ``lookup_linke_turbidity(..., interp_turbidity=False)``.

    Examples
    --------
    >>> linke_turbidity(52.52, 13.405, [1, 7]).round(2)   # Berlin, January and July
    array([2.85, 3.87])
    """
    tl, step = _climatology()
    month = np.asarray(month, dtype=int)
    h, w = tl.shape[1:]
    y = np.clip((90.0 - float(latitude)) / step - 0.5, 0.0, h - 1.0)
    x = (float(longitude) + 180.0) / step - 0.5
    y0, x0 = min(int(np.floor(y)), h - 2), int(np.floor(x))
    fy, fx = y - y0, x - x0
    rows, cols = (y0, y0 + 1), (x0 % w, (x0 + 1) % w)
    m = month - 1
    return ((1 - fy) * ((1 - fx) * tl[m, rows[0], cols[0]] + fx * tl[m, rows[0], cols[1]])
            + fy * ((1 - fx) * tl[m, rows[1], cols[0]] + fx * tl[m, rows[1], cols[1]]))


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
