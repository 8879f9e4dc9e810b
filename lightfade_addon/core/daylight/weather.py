"""Typical-year weather files: EPW, TMY3 (.csv) and TMY2 (.tm2), read with numpy only.

All three give hourly values that are totals over the hour *ending* at the stamped local
standard time (hour 1 = 00:00-01:00): irradiation in W·h/m^2, i.e. the hour's mean
irradiance in W/m^2.  :class:`Weather` keeps the interval ends in UTC.

A typical year stitches months from different years; the sun's path is computed for one
reference year (:data:`REFERENCE_YEAR`), so every record is moved to it (February 29th,
when a file has it, is dropped).

References
----------
EnergyPlus Auxiliary Programs, "Weather Converter Program", ch. 2.9 (EPW data dictionary):
fields 7 (dew point, °C), 13 (GHI), 14 (DNI), 15 (DHI); missing irradiance is 9999.
S. Wilcox, W. Marion, "Users Manual for TMY3 Data Sets", NREL/TP-581-43156, 2008.
W. Marion, K. Urban, "User's Manual for TMY2s", NREL, 1995 (field positions, table 3-1).
"""

from __future__ import annotations

import csv
import pathlib
from dataclasses import dataclass

import numpy as np

__all__ = ["REFERENCE_YEAR", "Weather", "WeatherFileError", "read_epw", "read_tmy3",
           "read_tmy2", "read_weather"]

#: The (non-leap) year whose sun path a typical year's records are placed in.
REFERENCE_YEAR = 2025


class WeatherFileError(ValueError):
    """A weather file that cannot be read; the message names the file and the problem."""


@dataclass(frozen=True)
class Weather:
    """Hourly irradiance of a typical year at a station.

    Attributes
    ----------
    times : numpy.ndarray of datetime64[s]
        UTC end of each hourly interval, in :data:`REFERENCE_YEAR`.
    ghi, dni, dhi : numpy.ndarray
        Global horizontal, direct normal and diffuse horizontal irradiance, W/m^2 (the
        hour's mean; missing values are 0).
    dew_point : numpy.ndarray
        °C (NaN where the file has none).
    latitude, longitude : float
        Degrees, north and east positive.
    altitude : float
        Metres.
    timezone : float
        Hours east of UTC of the file's local standard time.
    name : str
        Station name.
    """

    times: np.ndarray
    ghi: np.ndarray
    dni: np.ndarray
    dhi: np.ndarray
    dew_point: np.ndarray
    latitude: float
    longitude: float
    altitude: float
    timezone: float
    name: str = ""


def _utc_times(month, day, hour, timezone, path):
    """Interval ends in UTC from local standard month, day, hour-ending (1..24)."""
    month, day, hour = (np.asarray(a, dtype=int) for a in (month, day, hour))
    keep = ~((month == 2) & (day == 29))
    if np.any((month < 1) | (month > 12) | (day < 1) | (day > 31) | (hour < 0) | (hour > 24)):
        raise WeatherFileError(f"{path}: dates or hours out of range")
    months = np.array([f"{REFERENCE_YEAR}-{m:02d}" for m in range(1, 13)], dtype="datetime64[D]")
    dates = months[month - 1] + (day - 1).astype("timedelta64[D]")
    local = dates.astype("datetime64[s]") + (hour * 3600).astype("timedelta64[s]")
    utc = local - np.timedelta64(int(round(timezone * 3600)), "s")
    return utc, keep


def _clean(values):
    """Irradiance with missing codes (9999, negative) set to 0."""
    v = np.asarray(values, dtype=float)
    return np.where((v >= 0) & (v < 9999), v, 0.0)


def _weather(path, month, day, hour, ghi, dni, dhi, dew, lat, lon, alt, tz, name):
    times, keep = _utc_times(month, day, hour, tz, path)
    order = np.argsort(times[keep], kind="stable")
    pick = lambda a: np.asarray(a, dtype=float)[keep][order]  # noqa: E731
    dew = np.asarray(dew, dtype=float)
    dew = np.where((dew > -90) & (dew < 70), dew, np.nan)
    return Weather(times=times[keep][order], ghi=pick(_clean(ghi)), dni=pick(_clean(dni)),
                   dhi=pick(_clean(dhi)), dew_point=pick(dew), latitude=float(lat),
                   longitude=float(lon), altitude=float(alt), timezone=float(tz), name=name)


def read_epw(path):
    """Read an EnergyPlus weather file (.epw).

    The LOCATION header gives name, latitude, longitude, time zone and elevation; data
    rows (after the 8 header lines) give month, day, hour-ending, dew point, GHI, DNI, DHI.
    """
    path = pathlib.Path(path)
    with open(path, newline="", encoding="latin-1") as f:
        rows = list(csv.reader(f))
    if not rows or rows[0][0].strip().upper() != "LOCATION" or len(rows[0]) < 10:
        raise WeatherFileError(f"{path}: not an EPW file (no LOCATION header line)")
    loc = rows[0]
    data = [r for r in rows[8:] if len(r) >= 16]
    if not data:
        raise WeatherFileError(f"{path}: EPW file without data rows")
    col = lambda i: [r[i] for r in data]  # noqa: E731
    return _weather(path, col(1), col(2), col(3), col(13), col(14), col(15), col(7),
                    float(loc[6]), float(loc[7]), float(loc[9]), float(loc[8]),
                    loc[1].strip())


def read_tmy3(path):
    """Read an NREL TMY3 file (.csv): a site line, a column-name line, hourly rows.

    Site line: USAF id, name, state, time zone, latitude, longitude, elevation.  Columns
    used: ``Date (MM/DD/YYYY)``, ``Time (HH:MM)`` (hour ending), ``GHI (W/m^2)``,
    ``DNI (W/m^2)``, ``DHI (W/m^2)``, ``Dew-point (C)``.
    """
    path = pathlib.Path(path)
    with open(path, newline="", encoding="latin-1") as f:
        rows = list(csv.reader(f))
    try:
        site, names = rows[0], [n.strip() for n in rows[1]]
        idx = {k: names.index(k) for k in ("Date (MM/DD/YYYY)", "Time (HH:MM)", "GHI (W/m^2)",
                                          "DNI (W/m^2)", "DHI (W/m^2)", "Dew-point (C)")}
        lat, lon, alt, tz = float(site[4]), float(site[5]), float(site[6]), float(site[3])
    except (IndexError, ValueError) as e:
        raise WeatherFileError(f"{path}: not a TMY3 file ({e})") from None
    data = [r for r in rows[2:] if len(r) == len(names)]
    date = [r[idx["Date (MM/DD/YYYY)"]].split("/") for r in data]
    hour = [int(r[idx["Time (HH:MM)"]].split(":")[0]) for r in data]
    col = lambda k: [r[idx[k]] for r in data]  # noqa: E731
    return _weather(path, [d[0] for d in date], [d[1] for d in date], hour,
                    col("GHI (W/m^2)"), col("DNI (W/m^2)"), col("DHI (W/m^2)"),
                    col("Dew-point (C)"), lat, lon, alt, tz, site[1].strip())


# TMY2 fixed-width fields (0-based start, end) on each data line (Marion & Urban 1995,
# table 3-1; the line's first character is a blank).
_TMY2 = dict(month=(3, 5), day=(5, 7), hour=(7, 9), ghi=(17, 21), dni=(23, 27),
             dhi=(29, 33), dew=(73, 77))


def read_tmy2(path):
    """Read an NREL TMY2 file (.tm2): a fixed-width header line and hourly lines.

    Header: WBAN, city, state, time zone, ``N|S deg min``, ``E|W deg min``, elevation.
    Irradiation in W·h/m^2 over the hour ending at the stamp; dew point in 0.1 °C.
    """
    path = pathlib.Path(path)
    lines = path.read_text(encoding="latin-1").splitlines()
    try:
        h = lines[0].split()
        tz = float(h[-8])
        lat = (float(h[-6]) + float(h[-5]) / 60) * (1 if h[-7] == "N" else -1)
        lon = (float(h[-3]) + float(h[-2]) / 60) * (1 if h[-4] == "E" else -1)
        alt = float(h[-1])
        name = " ".join(h[1:-9])
        data = [ln for ln in lines[1:] if len(ln) >= 77]
        f = {k: [ln[a:b] for ln in data] for k, (a, b) in _TMY2.items()}
        dew = np.asarray(f["dew"], dtype=float) / 10.0
    except (IndexError, ValueError) as e:
        raise WeatherFileError(f"{path}: not a TMY2 file ({e})") from None
    return _weather(path, f["month"], f["day"], f["hour"], f["ghi"], f["dni"], f["dhi"],
                    dew, lat, lon, alt, tz, name)


def read_weather(path):
    """Read an EPW, TMY3 (.csv) or TMY2 (.tm2) file, chosen by its extension.

    Returns
    -------
    Weather

    Raises
    ------
    WeatherFileError
        Unknown extension or unreadable content (the message names the file).
    """
    path = pathlib.Path(path)
    if not path.is_file():
        raise WeatherFileError(f"{path}: no such weather file")
    ext = path.suffix.lower()
    if ext == ".epw":
        return read_epw(path)
    if ext == ".csv":
        return read_tmy3(path)
    if ext in (".tm2", ".tmy2", ".tmy"):
        return read_tmy2(path)
    raise WeatherFileError(f"{path}: unknown weather file type {ext!r}; use .epw, "
                           "TMY3 .csv or TMY2 .tm2")
