"""The scene's place, weather and annual sky map, read from its settings.

Where the place comes from, first match wins:

1. the Sun Position add-on's settings (``Scene.sun_pos_properties``: ``latitude``,
   ``longitude`` in degrees, ``north_offset`` in radians) when the file has them and
   ``Scene.lightfade_daylight.use_sun_position`` is on.  They are read from the add-on's
   properties when it is enabled, else from the ID properties it left in the file
   (``scene["sun_pos_properties"]`` up to Blender 4.x, the scene's system properties from
   5.0).  Sun Position turns the sun's azimuth (clockwise from north) by ``north_offset``,
   so geographic north lies ``north_offset`` *clockwise* from +Y: LightFade's north
   (counterclockwise) is ``-degrees(north_offset)``;
2. LightFade's own latitude, longitude and north (a preset, typed, or ``api.set_daylight``).

Without either, daylight stays what the sun lamps and the world say.
"""

from __future__ import annotations

import math
import os

import bpy

from ...core.daylight import annual as _daylight
from ..bake.common import LightFadeBakeError

SUN_POSITION = "sun_pos_properties"


class DaylightError(LightFadeBakeError, ValueError):
    """A place or weather file that cannot be used; the message names it and what to do."""


# ----------------------------------------------------------------------- Sun Position


def _stored_group(scene, name):
    """The ID-property group ``name`` the file stores on ``scene`` (registered or not)."""
    getter = getattr(scene, "bl_system_properties_get", None)  # Blender 5.0+
    if getter is not None:
        system = getter()
        group = system.get(name) if system is not None else None
        if group is not None:
            return group
    return scene.get(name)


def sun_position_settings(scene):
    """``(latitude, longitude, north)`` in degrees from the Sun Position add-on's settings
    stored in the file, or None when the file has none."""
    group = _stored_group(scene, SUN_POSITION)
    if group is None:
        return None
    props = getattr(scene, SUN_POSITION, None)  # the add-on is enabled: its values
    if props is not None and all(hasattr(props, k) for k in ("latitude", "longitude",
                                                             "north_offset")):
        lat, lon, offset = props.latitude, props.longitude, props.north_offset
    else:  # stored values; a key never written holds the add-on's default, 0
        lat, lon, offset = (float(group.get(k, 0.0))
                            for k in ("latitude", "longitude", "north_offset"))
    return float(lat), float(lon), float(_daylight.north_from_sun_position_addon(float(offset)))


# ----------------------------------------------------------------------- the place


def place_source(scene):
    """``(latitude, longitude, north, where from)`` or None: no place set."""
    props = scene.lightfade_daylight
    if props.use_sun_position:
        found = sun_position_settings(scene)
        if found is not None:
            return (*found, "Sun Position add-on")
    if props.place_set:
        return props.latitude, props.longitude, props.north, "LightFade"
    return None


def daylight_active(scene):
    """Annual daylight replaces the sun lamps: a place is set and the toggle is on."""
    return bool(scene.lightfade_daylight.enabled) and place_source(scene) is not None


def weather_path(scene):
    """Absolute path of the scene's weather file, or None (clear sky)."""
    path = scene.lightfade_daylight.weather.strip()
    return os.path.normpath(bpy.path.abspath(path)) if path else None


_WEATHER = {}


def read_weather(path):
    """:func:`..core.daylight.read_weather` of ``path`` (a check that it reads), cached
    on its size and time; :class:`DaylightError` naming the file when it is missing or
    unreadable."""
    try:
        st = os.stat(path)
    except OSError:
        raise DaylightError(f"Weather file '{path}' not found: give an EPW, TMY3 or TMY2 file, "
                            "or clear the Weather File for a clear sky") from None
    if not os.path.isfile(path):
        raise DaylightError(f"Weather file '{path}' is not a file: give an EPW, TMY3 or TMY2 file")
    key = (path, st.st_size, st.st_mtime_ns)
    if key not in _WEATHER:
        try:
            weather = _daylight.read_weather(path)
        except (OSError, ValueError, KeyError, IndexError, UnicodeDecodeError) as err:
            raise DaylightError(f"Weather file '{path}' could not be read as EPW, TMY3 or TMY2: "
                                f"{err}") from None
        _WEATHER.clear()
        _WEATHER[key] = weather
    return _WEATHER[key]


def scene_place(scene):
    """The scene's :class:`..core.daylight.Place`, or None without a place.

    Raises :class:`DaylightError` for a weather file that is missing or unreadable.
    """
    source = place_source(scene)
    if source is None:
        return None
    lat, lon, north, _where = source
    props = scene.lightfade_daylight
    path = weather_path(scene)
    if path:
        read_weather(path)  # a missing or unreadable file: one line naming it
    try:
        return _daylight.Place(latitude=lat, longitude=lon, north=north, weather=path,
                               albedo=props.albedo, altitude=props.altitude)
    except ValueError as err:
        raise DaylightError(f"The scene's place cannot be used: {err}") from None


_SKY = {}


def sky_width(scene):
    """The sky map's width: the setting rounded down to a multiple of 4, at least 16."""
    return max(16, int(scene.lightfade_daylight.sky_width) // 4 * 4)


def sky_key(scene):
    """What the annual sky map depends on (None without a place)."""
    source = place_source(scene)
    if source is None:
        return None
    props = scene.lightfade_daylight
    path = weather_path(scene)
    stamp = None
    if path and os.path.isfile(path):
        st = os.stat(path)
        stamp = (path, st.st_size, st.st_mtime_ns)
    return (round(source[0], 6), round(source[1], 6), round(source[2], 6), path, stamp,
            round(props.albedo, 6), round(props.altitude, 3), sky_width(scene))


def annual_sky(scene):
    """The scene's annual sky map, ``(w/2, w)`` float32 lux·h per year per steradian in
    scene coordinates (:func:`..core.daylight.annual_sky_map`), cached on what it depends on.
    """
    key = sky_key(scene)
    if key is None:
        raise DaylightError("No place is set: give the scene a latitude and longitude "
                            "(LightFade > Daylight) or turn Annual Daylight off")
    if key not in _SKY:
        place = scene_place(scene)
        sky = _daylight.annual_sky_map(place, width=sky_width(scene), ground=True)
        if len(_SKY) >= 4:
            _SKY.clear()
        _SKY[key] = sky
    return _SKY[key]


# ----------------------------------------------------------------------- setting it


def _finite(name, value, low=None, high=None):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise DaylightError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or (low is not None and not low <= v <= high):
        span = f" between {low:g} and {high:g}" if low is not None else ""
        raise DaylightError(f"{name} must be a finite number{span}, got {value!r}")
    return v


def set_daylight(scene, latitude, longitude, north=0.0, weather=None):
    """Give ``scene`` a place and climate; annual daylight on.  Everything is checked
    before anything changes (:class:`DaylightError`, one line naming the value or file)."""
    lat = _finite("Latitude", latitude, -90.0, 90.0)
    lon = _finite("Longitude", longitude, -180.0, 180.0)
    nor = _finite("North", north)
    path = ""
    if weather is not None:
        path = os.path.normpath(os.path.abspath(bpy.path.abspath(os.fspath(weather))))
        read_weather(path)
    props = scene.lightfade_daylight
    props.preset = "CUSTOM"
    props.latitude, props.longitude = lat, lon
    props.north = (nor + 180.0) % 360.0 - 180.0 if abs(nor) > 180.0 else nor
    props.weather = path
    props.use_sun_position = False
    props.place_set = True
    props.enabled = True
    return props
