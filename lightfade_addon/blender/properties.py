"""LightFade's data model: the property groups stored in the .blend file.

Where the data lives
--------------------
``Scene.lightfade`` (:class:`LIGHTFADE_PG_scene`)
    The bake settings, and ``years``: a view of the scene's custom property
    ``lightfade_years`` (:mod:`.aging.years`), which the aged materials read themselves.
``Light.lightfade`` and ``World.lightfade`` (:class:`LIGHTFADE_PG_schedule`)
    The light schedule of a lamp or of the sky: spectrum, UV filter, hours per day,
    days per year, and whether the emitter takes part in aging.  It lives on the light
    *data* (shared by instanced lamps) and on the world.
``Object.lightfade_emitter`` (:class:`LIGHTFADE_PG_emission`)
    The same schedule for an emissive mesh (a light panel, a screen, glazing).  A mesh
    counts as an emitter when one of its materials has a non-zero Emission (an Emission
    node or the Principled BSDF's Emission Strength, glTF ``emissiveFactor``) *and* the
    user ticked *Count Emission as Light* (``enabled``, off by default: glazing and
    screens are not lamps); otherwise its emission is off while baking and the bake
    report and panel say so, naming the object and material.
``Material.lightfade``
    The aging recipe of a material (:mod:`.aging.properties`), and its parts
    (:mod:`.parts.properties`).
``Object.lightfade`` and ``Scene.lightfade_bake``
    The exposure maps of a mesh and the bake settings: :mod:`.bake.records` (registered
    with the bake package).

Exposure maps hold illuminance in lux (see :mod:`.bake` for the calibration); the annual
dose of a texel is ``lux * hours_per_day * days_per_year`` lux·h.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty
from bpy.types import PropertyGroup

from .aging.years import SOFT_MAX_YEARS, get_years, write_years
from .vocabulary import AGED_RAYS_ITEMS, SPECTRUM_ITEMS


# ----------------------------------------------------------------- a light's schedule
# The same properties describe a light now (an emitter's schedule) and a light the texture
# has already aged under (``Material.lightfade.already_*``).


def spectrum_prop(description, items, default, name="Spectrum"):
    return EnumProperty(name=name, description=description, items=items, default=default)


def uv_filter_prop(description):
    return BoolProperty(name="UV Filter", description=description, default=False)


def hours_per_day_prop(description):
    return FloatProperty(name="Hours per Day", description=description, default=8.0,
                         min=0.0, max=24.0, precision=1)


# --------------------------------------------------------------------------- groups


class _ScheduleFields:
    """What every emitter's schedule holds besides whether it counts."""

    spectrum: spectrum_prop("Spectral power distribution of this emitter's light (UV content "
                        "drives much of the fading)", SPECTRUM_ITEMS, "AUTO")
    uv_filter: uv_filter_prop("A UV-blocking filter or film cuts this emitter's light below 400 nm")
    hours_per_day: hours_per_day_prop("Hours per day this emitter is on (for the sun: hours of "
                                  "direct sun on the scene)")
    days_per_year: FloatProperty(name="Days per Year", description="Days per year this emitter "
                                 "is on", default=365.0, min=0.0, max=366.0, precision=0)


class LIGHTFADE_PG_schedule(_ScheduleFields, PropertyGroup):
    """How long and with which spectrum an emitter shines (lamp or world)."""

    enabled: BoolProperty(
        name="Include in Aging",
        description="Bake an exposure map for this emitter and count its light when aging",
        default=True,
    )


class LIGHTFADE_PG_emission(_ScheduleFields, PropertyGroup):
    """The schedule of a mesh's emissive materials: not a lamp unless the user says so.

    Window glazing, screens and glTF ``emissiveFactor`` make materials emit without being
    lamps; counting them by default would add a light group next to daylight unasked.
    """

    enabled: BoolProperty(
        name="Count Emission as Light",
        description="Count this mesh's emissive materials as a lamp in the exposure bake "
                    "(off: their emission is switched off while baking)",
        default=False,
    )


#: Blender stores an infinite float property as the largest float32: that is "inf" too.
_FLOAT32_MAX = 3.0e38


def valid_years(years):
    """True for a finite number >= 0 (a property set to infinity holds ~3.4e38)."""
    return years == years and 0.0 <= years < _FLOAT32_MAX


def _get_years(self):
    return get_years(self.id_data)


def _set_years(self, value):
    # The slider writes the scene's custom property the aged materials read (see
    # .years): nothing else runs, so scrubbing costs no Python work.
    if not valid_years(value):
        bad = float("inf") if value >= _FLOAT32_MAX else value
        print(f"LightFade: years must be a finite number >= 0, got {bad!r}; "
              f"kept {get_years(self.id_data):g}")
        return
    write_years(self.id_data, value)


class LIGHTFADE_PG_scene(PropertyGroup):
    """Scene-wide LightFade settings: the years slider and the bake settings."""

    years: FloatProperty(
        name="Years",
        description="Years of light exposure to show: the scene's custom property "
        "'lightfade_years' (keyframe that one for a time-lapse)",
        soft_min=0.0,
        soft_max=SOFT_MAX_YEARS,
        precision=1,
        options=set(),
        get=_get_years,
        set=_set_years,
    )
    lock_interface_before: IntProperty(
        name="Lock Interface Before Aging",
        description="Render > Lock Interface as it was before Age turned it on (-1: Age has not)",
        default=-1,
        options={"HIDDEN"},
    )
    bake_resolution: IntProperty(
        name="Resolution",
        description="Width and height in pixels of each exposure map",
        default=1024,
        min=64,
        max=8192,
    )
    bake_samples: IntProperty(
        name="Samples",
        description="Cycles samples per texel for the exposure bake (more: less noise, slower)",
        default=64,
        min=1,
        max=65536,
    )
    aged_rays: EnumProperty(name="Aged Colour On", items=AGED_RAYS_ITEMS, default="ALL",
                            description="Which rays see the aged colour (taken at Age); the "
                            "others see the original colour and skip the aging group")
    frame_detail: EnumProperty(
        name="Frame Detail", default="CAMERA",
        items=(("CAMERA", "From the Camera", "Cycles renders read each aged texture at the detail "
                "the camera can resolve (as a mipmap): fast frames where textures are small on "
                "screen"),
               ("FULL", "Full", "Cycles renders read each aged texture at its full resolution "
                "(objects seen close up in mirrors or through lenses)")),
        description="How much of each aged texture a Cycles render writes for its frame; "
        "Apply always writes the full images")
    bake_margin: IntProperty(
        name="Margin",
        description="Pixels the baked exposure is extended past UV island borders (avoids seams)",
        default=16,
        min=0,
        max=64,
        subtype="PIXEL",
    )


CLASSES = (
    LIGHTFADE_PG_schedule,
    LIGHTFADE_PG_emission,
    LIGHTFADE_PG_scene,
)

#: (ID type, attribute, property group): attached in order, removed in reverse.
POINTERS = (
    (bpy.types.Scene, "lightfade", LIGHTFADE_PG_scene),
    (bpy.types.Light, "lightfade", LIGHTFADE_PG_schedule),
    (bpy.types.World, "lightfade", LIGHTFADE_PG_schedule),
    (bpy.types.Object, "lightfade_emitter", LIGHTFADE_PG_emission),
)


def register_pointers(pointers=POINTERS):
    """Attach ``(ID type, attribute, property group)`` triples (after the classes are registered)."""
    for id_type, attr, group in pointers:
        setattr(id_type, attr, PointerProperty(type=group, name="LightFade",
                                               description="LightFade settings"))


def unregister_pointers(pointers=POINTERS):
    """Remove what :func:`register_pointers` attached, in reverse order."""
    for id_type, attr, _group in reversed(pointers):
        if hasattr(id_type, attr):
            delattr(id_type, attr)
