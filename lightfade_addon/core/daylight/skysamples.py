"""A typical year of daylight as sun positions with their sky: the samples the map sums.

Every hour of the year is split into ``substeps`` equal sub-intervals; each sub-interval
with the sun above the horizon is one sample: the sun's apparent position at its middle,
the hour's irradiance (W/m^2), its duration (h), the Perez 1990 diffuse split (F1, F2)
and luminous efficacies.  Clear sky: the irradiance is the Ineichen-Perez model's at the
sample's own sun position.  Weather file: the hour's recorded irradiation is shared among
the sub-intervals of that hour with the sun up (so that the whole recorded hour is kept,
sunrise and sunset hours included).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .clearsky import clearsky_Ineichen2002, linke_turbidity
from .perez import (
    PRECIPITABLE_WATER_DEFAULT,
    luminous_efficacy,
    perez_F1_F2,
    precipitable_water_from_dew_point,
    sky_brightness,
    sky_clearness,
)
from .solar import (
    airmass_relative_KastenYoung1989,
    day_of_year,
    dni_extra_Spencer1971,
    pressure_from_altitude,
    sun_position_Meeus1998,
)
from .weather import REFERENCE_YEAR, read_weather

__all__ = ["SkySamples", "sky_samples"]

_HOUR = np.timedelta64(3600, "s")


@dataclass(frozen=True)
class SkySamples:
    """Daylight samples of a typical year (1-D arrays, one entry per sample).

    Attributes
    ----------
    zenith, azimuth : numpy.ndarray
        Apparent sun position, degrees (azimuth clockwise from north).
    dni, dhi, ghi : numpy.ndarray
        W/m^2.
    hours : numpy.ndarray
        Duration each sample stands for, h (they sum to the hours of daylight).
    F1, F2 : numpy.ndarray
        Perez 1990 circumsolar and horizon brightening coefficients.
    K_direct, K_diffuse : numpy.ndarray
        Luminous efficacy of direct normal and diffuse light, lm/W.
    epsilon, delta : numpy.ndarray
        Perez sky clearness and brightness (NaN clearness where DHI = 0).
    latitude, longitude, altitude : float
        Where the sun was computed (the weather file's station when there is one).
    dropped_wh : float
        W·h/m^2 of global horizontal irradiation in hours with no sub-interval of sun
        above the horizon (kept out of the samples; normally 0).
    """

    zenith: np.ndarray
    azimuth: np.ndarray
    dni: np.ndarray
    dhi: np.ndarray
    ghi: np.ndarray
    hours: np.ndarray
    F1: np.ndarray
    F2: np.ndarray
    K_direct: np.ndarray
    K_diffuse: np.ndarray
    epsilon: np.ndarray
    delta: np.ndarray
    latitude: float
    longitude: float
    altitude: float
    dropped_wh: float = 0.0

    @property
    def K_global(self):
        """Luminous efficacy of the global horizontal light, lm/W:
        ``(K_b DNI cos Z + K_d DHI) / (DNI cos Z + DHI)`` (0 where both are 0)."""
        beam_h = self.dni * np.cos(np.radians(self.zenith))
        total = beam_h + self.dhi
        safe = np.where(total > 0, total, 1.0)
        return np.where(total > 0, (self.K_direct * beam_h + self.K_diffuse * self.dhi) / safe, 0.0)


def _sub_times(interval_starts, substeps):
    offsets = ((np.arange(substeps) + 0.5) / substeps * 3600.0 * 1e3).astype("timedelta64[ms]")
    return interval_starts.astype("datetime64[ms]")[:, None] + offsets[None, :]


def _samples(t, zenith, azimuth, dni, dhi, ghi, hours, water, lat, lon, alt, dropped=0.0):
    e0 = dni_extra_Spencer1971(day_of_year(t))
    am = airmass_relative_KastenYoung1989(zenith)
    eps = sky_clearness(dni, dhi, zenith)
    delta = sky_brightness(dhi, am, e0)
    F1, F2 = perez_F1_F2(eps, delta, zenith)
    K_b, K_d = luminous_efficacy(eps, delta, zenith, water)
    return SkySamples(zenith=zenith, azimuth=azimuth, dni=dni, dhi=dhi, ghi=ghi, hours=hours,
                      F1=F1, F2=F2, K_direct=K_b, K_diffuse=K_d, epsilon=eps, delta=delta,
                      latitude=float(lat),
                      longitude=float(lon), altitude=float(alt), dropped_wh=float(dropped))


def _clear_sky(place, substeps):
    start = np.datetime64(f"{REFERENCE_YEAR}-01-01T00:00", "s")
    hours = np.arange(365 * 24) * _HOUR + start
    t = _sub_times(hours, substeps).ravel()
    pressure = pressure_from_altitude(place.altitude)
    z, a = sun_position_Meeus1998(place.latitude, place.longitude, t, pressure=pressure)
    up = z < 90.0
    t, z, a = t[up], z[up], a[up]
    month = (t.astype("datetime64[M]").astype(int) % 12) + 1
    tl = linke_turbidity(place.latitude, place.longitude, month)
    e0 = dni_extra_Spencer1971(day_of_year(t))
    ghi, dni, dhi = clearsky_Ineichen2002(z, tl, place.altitude, e0)
    w = np.full(z.shape, 1.0 / substeps)
    return _samples(t, z, a, dni, dhi, ghi, w, PRECIPITABLE_WATER_DEFAULT,
                    place.latitude, place.longitude, place.altitude)


def _weather_file(path, substeps):
    wx = read_weather(path)
    t = _sub_times(wx.times - _HOUR, substeps)                  # (N, k), interval ends given
    z, a = sun_position_Meeus1998(wx.latitude, wx.longitude, t.ravel(),
                                  pressure=pressure_from_altitude(wx.altitude))
    z, a = z.reshape(t.shape), a.reshape(t.shape)
    up = z < 90.0
    n_up = up.sum(axis=1)
    dropped = float(wx.ghi[n_up == 0].sum())
    w = np.where(up, 1.0 / np.maximum(n_up, 1)[:, None], 0.0)
    rec = np.broadcast_to(np.arange(len(wx.times))[:, None], t.shape)
    sel = up & ((wx.ghi > 0) | (wx.dni > 0) | (wx.dhi > 0))[:, None]
    r = rec[sel]
    water = precipitable_water_from_dew_point(wx.dew_point[r])
    water = np.where(np.isfinite(water), water, PRECIPITABLE_WATER_DEFAULT)
    return _samples(t[sel], z[sel], a[sel], wx.dni[r], wx.dhi[r], wx.ghi[r], w[sel], water,
                    wx.latitude, wx.longitude, wx.altitude, dropped)


def sky_samples(place, substeps=12):
    """The daylight samples of a place's typical year.

    Parameters
    ----------
    place : Place
        ``weather`` None: the clear sky at ``latitude``, ``longitude``, ``altitude``;
        else the weather file's own station (its header's latitude, longitude, altitude
        and time zone: the recorded hours belong to that sun).
    substeps : int
        Sub-intervals per hour (12: every 5 minutes; the sun moves 1.25° between them).

    Returns
    -------
    SkySamples
    """
    substeps = int(substeps)
    if substeps < 1:
        raise ValueError("substeps must be >= 1")
    if place.weather is None:
        return _clear_sky(place, substeps)
    return _weather_file(place.weather, substeps)
