"""``Scene.lightfade_daylight``: the scene's place on Earth, its climate and its daylight.

A place is set by :func:`..daylight.place.set_daylight` (``api.set_daylight``), by a preset
(:data:`..core.daylight.PLACES`), by typing a latitude or longitude, or comes from the Sun
Position add-on's settings when the file has them.  With a place and *Annual Daylight* on
(the default), daylight is one light group, ``"Daylight"``: the sun over every hour of the
year and the sky, baked once (:mod:`..bake.daylight`); sun lamps and a world standing for
daylight are muted in that bake.
"""

import re

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy.types import PropertyGroup

from ...core.daylight.annual import PLACES
from ..vocabulary import PRIOR_SPECTRUM_ITEMS

#: Hours and days the daylight group's map counts: its lux is the year-round mean
#: illuminance (annual lux·h / 8760 h), so ``lux × 24 × 365`` is the annual dose.
DAYLIGHT_HOURS_PER_DAY = 24.0
DAYLIGHT_DAYS_PER_YEAR = 365.0

#: Preset enum identifier -> name in :data:`PLACES`.
PLACE_IDS = {re.sub(r"[^A-Z0-9]+", "_", name.upper()).strip("_"): name for name in PLACES}

PRESET_ITEMS = (
    ("CUSTOM", "Custom", "The latitude, longitude and weather below"),
    *((key, name,
       f"{PLACES[name].latitude:.2f}°, {PLACES[name].longitude:.2f}°")
      for key, name in PLACE_IDS.items()),
)


_FILLING = []  # non-empty while a preset writes latitude and longitude


def _on_preset(self, context):
    name = PLACE_IDS.get(self.preset)
    if name is None:
        return
    place = PLACES[name]
    _FILLING.append(True)
    try:
        self.latitude, self.longitude = float(place.latitude), float(place.longitude)
        self.albedo, self.altitude = float(place.albedo), float(place.altitude)
    finally:
        _FILLING.pop()
    self.place_set = True
    self.use_sun_position = False


def _on_place_edited(self, context):
    if _FILLING:
        return
    self.place_set = True
    self.use_sun_position = False
    if self.preset != "CUSTOM":
        self.preset = "CUSTOM"  # typed values are no longer the preset's


class LIGHTFADE_PG_daylight(PropertyGroup):
    """Where the scene stands on Earth, its weather, and its daylight's spectrum."""

    enabled: BoolProperty(
        name="Annual Daylight",
        description="With a place set: daylight is the sun over every hour of the year and the "
        "sky for that place, baked once (lux·h per year); sun lamps and a world standing for "
        "daylight are muted in that bake. Off: sun lamps with their hours per day",
        default=True,
    )
    place_set: BoolProperty(
        name="Place Set",
        description="A latitude and longitude were given (preset, typed or by script)",
        default=False,
        options={"HIDDEN"},
    )
    use_sun_position: BoolProperty(
        name="From Sun Position",
        description="Take latitude, longitude and north from the Sun Position add-on's settings "
        "when the file has them",
        default=True,
    )
    preset: EnumProperty(
        name="Place",
        description="A named place (fills latitude, longitude and ground albedo)",
        items=PRESET_ITEMS,
        default="CUSTOM",
        update=_on_preset,
    )
    latitude: FloatProperty(
        name="Latitude", description="Degrees north of the equator (south negative)",
        default=0.0, min=-90.0, max=90.0, precision=4, update=_on_place_edited,
    )
    longitude: FloatProperty(
        name="Longitude", description="Degrees east of Greenwich (west negative)",
        default=0.0, min=-180.0, max=180.0, precision=4, update=_on_place_edited,
    )
    north: FloatProperty(
        name="North",
        description="Counterclockwise angle in degrees from the scene's +Y axis to geographic "
        "north, about +Z (0: +Y is north; 90: -X is north)",
        default=0.0, soft_min=-180.0, soft_max=180.0, precision=2,
    )
    weather: StringProperty(
        name="Weather File",
        description="EPW, TMY3 or TMY2 weather file of the place; empty: a clear sky every day",
        default="",
        subtype="FILE_PATH",
    )
    albedo: FloatProperty(
        name="Ground Albedo", description="Reflectance of the ground outside (0.2: grass, soil)",
        default=0.2, min=0.0, max=1.0,
    )
    altitude: FloatProperty(
        name="Altitude", description="Height of the place above sea level, m (clear-sky model)",
        default=0.0, min=-500.0, max=9000.0, subtype="DISTANCE", unit="LENGTH",
    )
    spectrum: EnumProperty(
        name="Spectrum",
        description="Spectrum of daylight reaching the scene (through window glass by default)",
        items=PRIOR_SPECTRUM_ITEMS,
        default="DAYLIGHT_GLASS",
    )
    uv_filter: BoolProperty(
        name="UV Filter",
        description="A UV-blocking film or glazing cuts daylight below 400 nm",
        default=False,
    )
    sky_width: IntProperty(
        name="Sky Map Width",
        description="Width of the equirectangular annual sky map the bake lights the scene "
        "with (height: half of it; a multiple of 4); 512 resolves the sun's path to 0.7°",
        default=512, min=16, max=4096, step=4,
    )

    # The daylight group's schedule, read like a lamp's (see .bake.emitters.schedule_of):
    # its map holds the year-round mean illuminance, on 24 h a day, 365 days a year.
    @property
    def hours_per_day(self):
        return DAYLIGHT_HOURS_PER_DAY

    @property
    def days_per_year(self):
        return DAYLIGHT_DAYS_PER_YEAR


CLASSES = (LIGHTFADE_PG_daylight,)

POINTERS = ((bpy.types.Scene, "lightfade_daylight", LIGHTFADE_PG_daylight),)
