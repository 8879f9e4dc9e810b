"""Daylight over the year: a place, its climate and the annual cumulative sky map.

The annual daylight of a place becomes one equirectangular environment map whose pixels
hold the year's cumulative luminance (lux·h per steradian, i.e. cd·h/m^2 per year): the
sun's direct light in the pixels of its path, the sky's diffuse light spread by the Perez
1993 all-weather distribution (or the Perez 1990 split) and, below the horizon, the
ground lit by the global horizontal light.  The cosine-weighted integral of the map over the
hemisphere around a normal is the annual illuminance dose on an unobstructed plane with
that normal (:func:`plane_dose`), so a Cycles bake with this map as the World gives each
texel its annual daylight dose in lux·h directly.

Modules: :mod:`.solar` (sun position), :mod:`.clearsky` (Ineichen-Perez), :mod:`.weather`
(EPW/TMY readers), :mod:`.perez` (clearness, the 1990 split, efficacy), :mod:`.allweather`
(the 1993 distribution), :mod:`.skysamples` (the year's samples), :mod:`.skygrid`
(Blender's equirectangular frame).  docs/daylight.md explains
the choices and benchmarks/daylight.py compares against pvlib.
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass

import numpy as np

from .perez import COS_85, luminous_efficacy, luminous_efficacy_Perez1990
from .skygrid import (
    check_width,
    grid,
    north_from_sun_position_addon,
    scene_to_enu,
    sun_direction_scene,
)
from .skymap import PEREZ1993_SUBSTEPS, SKY_MODELS, accumulate, substeps_for
from .skysamples import SkySamples, sky_samples
from .solar import sun_position
from .weather import Weather, WeatherFileError, read_weather

__all__ = [
    "Place",
    "PLACES",
    "SKY_MODELS",
    "annual_sky_map",
    "plane_dose",
    "annual_irradiation",
    "luminous_efficacy",
    "luminous_efficacy_Perez1990",
    "read_weather",
    "sun_position",
    "sun_direction_scene",
    "north_from_sun_position_addon",
    "Weather",
    "WeatherFileError",
    "SkySamples",
    "sky_samples",
]



@dataclass(frozen=True)
class Place:
    """Where a scene is on Earth, which way is north in it, and its climate.

    Attributes
    ----------
    latitude : float
        Degrees, north positive.
    longitude : float
        Degrees, east positive.
    north : float
        Counterclockwise degrees from the scene's +Y axis to geographic north, about +Z
        (0: +Y is north; 90: -X is north).
    weather : str or None
        None: clear sky (Ineichen-Perez); else the path of an EPW, TMY3 (.csv) or TMY2
        (.tm2) file, whose own station position and altitude are used for the sun.
    albedo : float
        Ground reflectance (0..1) for the lower half of the map.
    altitude : float
        Metres above sea level (clear sky; a weather file's header overrides it).
    """

    latitude: float
    longitude: float
    north: float = 0.0
    weather: str | None = None
    albedo: float = 0.2
    altitude: float = 0.0

    @classmethod
    def from_weather(cls, path, north=0.0, albedo=0.2):
        """The place of a weather file's station (its header's latitude, longitude and
        altitude), with that file as its weather."""
        wx = read_weather(path)
        return cls(wx.latitude, wx.longitude, north=north, weather=str(path), albedo=albedo,
                   altitude=wx.altitude)

    def __post_init__(self):
        if not -90.0 <= self.latitude <= 90.0:
            raise ValueError(f"latitude must be within -90..90 degrees, got {self.latitude!r}")
        if not -180.0 <= self.longitude <= 360.0:
            raise ValueError(f"longitude must be within -180..180 degrees, got {self.longitude!r}")
        if not 0.0 <= self.albedo <= 1.0:
            raise ValueError(f"albedo must be within 0..1, got {self.albedo!r}")
        if not np.isfinite(self.north) or not np.isfinite(self.altitude):
            raise ValueError("north and altitude must be finite numbers")


#: Named places (clear sky by default; city-centre coordinates and altitudes).
PLACES = {
    "London": Place(51.5074, -0.1278, altitude=11.0),
    "Amsterdam/52N": Place(52.3676, 4.9041, altitude=0.0),
    "Madrid": Place(40.4168, -3.7038, altitude=657.0),
    "New York": Place(40.7128, -74.0060, altitude=10.0),
    "Sydney": Place(-33.8688, 151.2093, altitude=3.0),
    "Singapore": Place(1.2903, 103.8519, altitude=15.0),
    "Cairo": Place(30.0444, 31.2357, altitude=23.0),
    "Reykjavik": Place(64.1466, -21.9426, altitude=0.0),
}


def annual_sky_map(place, width=512, ground=True, photometric=True, sky="Perez1993"):
    """Annual cumulative sky (sun + sky + ground) as a Blender equirectangular map.

    Parameters
    ----------
    place : Place
        Position, north, weather (None = clear sky), albedo, altitude.
    width : int
        Map width W in pixels (a multiple of 4, >= 16); the height is W // 2.
    ground : bool
        Fill the lower hemisphere with the ground: isotropic luminance
        ``albedo × (global horizontal dose) / π``.
    photometric : bool
        True: lux·h per year per steradian (cd·h·m^-2 per year), with the Perez 1990
        luminous efficacies; False: W·h·m^-2·sr^-1 per year (for checks against pvlib).
    sky : {"Perez1993", "Perez1990"}
        How the diffuse light is spread over the sky (:data:`SKY_MODELS`): the Perez 1993
        all-weather luminance distribution normalised to each sample's diffuse
        horizontal light, as Radiance ``gendaymtx`` does (default; :mod:`.allweather`,
        evaluated on a grid at most 64 pixels wide for 2 samples an hour, interpolated
        onto the map's pixels and scaled to the diffuse dose), or the Perez 1990
        transposition's isotropic dome + circumsolar point source + horizon band, the
        model of pvlib's plane-of-array irradiance (equal to it by construction).

    Returns
    -------
    numpy.ndarray
        (W // 2, W) float32, **in scene coordinates** and in Blender's image pixel order:
        row 0 is the bottom of the image (the nadir, v = 0), the last row the zenith;
        column 0 looks along -X, W/4 along +Y, W/2 along +X, 3W/4 along -Y (Cycles'
        ``direction_to_equirectangular``; see :mod:`.skygrid`).  Write it to an image
        with ``pixels.foreach_set`` (adding RGBA) and use it with an Environment Texture
        node, equirectangular, default vector: the World's strength is then 1 for
        lux·h per year (scale by whatever the bake's lux unit is).  A fresh array each
        call (the last 8 maps are memoised; a weather file is re-read when its
        modification time or size changes).

    Notes
    -----
    For each daylight sample of the year (:func:`.skysamples.sky_samples`; every
    hour split into ``max(6, ceil(W/12))`` sub-intervals, so that the sun moves at most
    about half a pixel between them) with duration Δt:

    * direct: ``K_b · DNI · Δt`` into the pixel of the sun's position, divided by the
      pixel's solid angle;
    * sky, ``"Perez1993"``: ``K_d · DHI · Δt`` spread over the sky half by the
      all-weather relative luminance (Perez, Seals & Michalsky 1993), whose
      cosine-weighted integral is that dose;

    or, with ``"Perez1990"``:

    * circumsolar: ``K_d · F1 · DHI / max(cos Z, cos 85°) · Δt`` into the same pixel
      (Perez et al. 1990, eq. 9: ``F1 · DHI · a / b`` on a plane);
    * horizon band: ``K_d · F2 · DHI / 2 · Δt`` per radian of azimuth, spread evenly in the
      first row above the horizon, giving ``F2 · DHI · sin β`` on a plane of tilt β;
    * isotropic: the rest of the diffuse light, ``K_d · (1 - F1) · DHI · Δt`` on the
      horizontal, evenly over the sky half (normalised by the discrete cosine sum so the
      horizontal dose is exact);

    and with either:

    * ground (``ground=True``): ``albedo × global horizontal`` spread evenly below the
      horizon, so a plane of tilt β receives ``albedo · GHI · (1 - cos β) / 2``.

    Luminous efficacies K_b, K_d: Perez et al. 1990 (:mod:`.perez`).  Negative sums
    (with ``"Perez1990"``, possible only in the horizon row under mostly overcast
    climates) are clipped to 0.

    Examples
    --------
    >>> m = annual_sky_map(PLACES["London"], width=64)
    >>> m.shape, m.dtype
    ((32, 64), dtype('float32'))
    """
    width = check_width(width)
    if sky not in SKY_MODELS:
        raise ValueError(f"unknown sky model {sky!r}; use one of {SKY_MODELS}")
    return _sky_map(place, width, bool(ground), bool(photometric), sky, _file_stamp(place)).copy()


def _file_stamp(place):
    """What identifies the weather file's content for the cache: (mtime, size), or None."""
    if place.weather is None:
        return None
    try:
        st = os.stat(place.weather)
    except OSError:
        return None              # read_weather will raise the error a user can act on
    return st.st_mtime_ns, st.st_size


@functools.lru_cache(maxsize=8)
def _sky_map(place, width, ground, photometric, sky, stamp):
    """:func:`annual_sky_map`, memoised (a panel and a bake ask for the same map; a
    weather file's (mtime, size) is part of the key, so an edited file is read again)."""
    s = sky_samples(place, substeps_for(width))
    coarse = sky_samples(place, PEREZ1993_SUBSTEPS) if sky == "Perez1993" else None
    m = accumulate(s, width, place.north, place.albedo, ground, photometric, sky, coarse)
    m.setflags(write=False)
    return m


def plane_dose(sky_map, normal):
    """Cosine-weighted integral of a sky map over the hemisphere around ``normal``.

    Parameters
    ----------
    sky_map : numpy.ndarray
        (W // 2, W) map from :func:`annual_sky_map` (lux·h/sr per year, or W·h/m^2/sr).
    normal : array_like
        (3,) plane normal in scene coordinates (need not be unit length).

    Returns
    -------
    float
        lux·h per year (or W·h/m^2 per year) on an unobstructed plane facing ``normal``:
        ``sum(L · Ω · max(n · d, 0))`` over pixels, Ω each pixel's solid angle and d its
        centre direction.
    """
    sky_map = np.asarray(sky_map, dtype=float)
    H, W = sky_map.shape
    if W != 2 * H:
        raise ValueError(f"a sky map is (W // 2, W); got shape {sky_map.shape}")
    d, omega = grid(W)
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    return float(np.sum(sky_map * omega * np.maximum(d @ n, 0.0)))


def annual_irradiation(place, normal, substeps=12, photometric=False):
    """Annual irradiation on unobstructed planes straight from the model, no map.

    Parameters
    ----------
    place : Place
    normal : array_like
        (3,) plane normal in scene coordinates, or (N, 3) for N planes.
    substeps : int
        Sub-intervals per hour.
    photometric : bool
        False: W·h/m^2 per year; True: lux·h per year (Perez 1990 efficacies).

    Returns
    -------
    float or numpy.ndarray
        (N,) for (N, 3) normals.  The sum over the year's samples of
        ``DNI · max(cos θ, 0)`` + the Perez 1990 sky diffuse
        ``DHI · ((1 - F1)(1 + cos β)/2 + F1 a / b + F2 sin β)`` (clipped at 0 per sample,
        as pvlib does) + ``albedo · GHI · (1 - cos β)/2``, times each sample's duration:
        the model of pvlib's ``get_total_irradiance(model='perez')``.
    """
    s = sky_samples(place, substeps)
    normal = np.asarray(normal, dtype=float)
    n = scene_to_enu(normal / np.linalg.norm(normal, axis=-1, keepdims=True), place.north)
    n2 = np.atleast_2d(n)                                           # (N, 3)
    z, a = np.radians(s.zenith), np.radians(s.azimuth)
    sun = np.stack([np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z)], axis=-1)
    cos_t = np.maximum(sun @ n2.T, 0.0)                             # (samples, N)
    cos_b = n2[:, 2]
    sin_b = np.sqrt(np.maximum(0.0, 1.0 - cos_b * cos_b))
    K_b = s.K_direct[:, None] if photometric else 1.0
    K_d = s.K_diffuse[:, None] if photometric else 1.0
    col = lambda v: v[:, None]  # noqa: E731
    diffuse = col(s.dhi) * ((1.0 - col(s.F1)) * (1.0 + cos_b) / 2.0
                            + col(s.F1) * cos_t / col(np.maximum(np.cos(z), COS_85))
                            + col(s.F2) * sin_b)
    k_g = s.K_global if photometric else 1.0
    ground = col(place.albedo * k_g * s.ghi) * (1.0 - cos_b) / 2.0
    out = np.sum((K_b * col(s.dni) * cos_t + K_d * np.maximum(diffuse, 0.0) + ground)
                 * col(s.hours), axis=0)
    return float(out[0]) if n.ndim == 1 else out
