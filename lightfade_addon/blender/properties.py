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
``Material.lightfade`` (:class:`LIGHTFADE_PG_material`)
    The aging recipe of a material, and its parts (:mod:`.parts.properties`).
``Object.lightfade`` and ``Scene.lightfade_bake``
    The exposure maps of a mesh and the bake settings: :mod:`.bake.records` (registered
    with the bake package).

Exposure maps hold illuminance in lux (see :mod:`.bake` for the calibration); the annual
dose of a texel is ``lux * hours_per_day * days_per_year`` lux·h.
"""

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)
from bpy.types import PropertyGroup


from .parts.properties import REST_ITEMS, LIGHTFADE_PG_lane, LIGHTFADE_PG_part
from .aging.years import SOFT_MAX_YEARS, get_years, write_years
from .vocabulary import (
    AGED_RAYS_ITEMS,
    AUTO_SPECTRUM,
    PRIOR_SPECTRUM_ITEMS,
    EMITTER_KIND_ITEMS,
    RECIPE_BLUE_WOOL,
    RECIPE_IDS,
    RECIPE_ITEMS,
    SPECTRUM_IDS,
    SPECTRUM_ITEMS,
    resolve_spectrum,
)


def _on_recipe_changed(self, context):
    # A new recipe brings its usual light-fastness; the user may change it afterwards.
    self.blue_wool = RECIPE_BLUE_WOOL.get(self.recipe, 3)


# ----------------------------------------------------------------- a light's schedule
# The same properties describe a light now (an emitter's schedule) and a light the texture
# has already aged under (``Material.lightfade.already_*``).


def _spectrum(description, items, default, name="Spectrum"):
    return EnumProperty(name=name, description=description, items=items, default=default)


def _uv_filter(description):
    return BoolProperty(name="UV Filter", description=description, default=False)


def _hours_per_day(description):
    return FloatProperty(name="Hours per Day", description=description, default=8.0,
                         min=0.0, max=24.0, precision=1)


# --------------------------------------------------------------------------- groups


class _ScheduleFields:
    """What every emitter's schedule holds besides whether it counts."""

    spectrum: _spectrum("Spectral power distribution of this emitter's light (UV content "
                        "drives much of the fading)", SPECTRUM_ITEMS, "AUTO")
    uv_filter: _uv_filter("A UV-blocking filter or film cuts this emitter's light below 400 nm")
    hours_per_day: _hours_per_day("Hours per day this emitter is on (for the sun: hours of "
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


PATH_ITEMS = (
    ("DIRECT", "Direct", "An image straight into Base Color through the exposure UV map: "
     "aged at the image's full resolution"),
    ("BAKED", "Baked", "Any other Base Color graph, evaluated by Cycles into a float texture "
     "in the exposure UV map at the exposure map's resolution"),
    ("FLAT", "Flat", "A plain colour: a constant albedo at the exposure map's resolution"),
)


class LIGHTFADE_PG_slot_backup(PropertyGroup):
    """One material slot of the aged object as it was before Age (restored by Reset)."""

    index: IntProperty(name="Slot", description="Index of the material slot", min=0)
    link: StringProperty(name="Link", description="The slot's link ('DATA' or 'OBJECT') before aging")
    material: PointerProperty(
        name="Object Material",
        type=bpy.types.Material,
        description="The slot's object-level material before aging (usually none)",
    )


class LIGHTFADE_PG_material(PropertyGroup):
    """How a material ages: recipe and light sensitivity."""

    enabled: BoolProperty(
        name="Age this Material",
        description="Let LightFade age this material (and bake exposure for the objects using it)",
        default=False,
    )
    recipe: EnumProperty(
        name="Recipe",
        description="What the material is made of: sets its colourants, substrate and yellowing",
        items=RECIPE_ITEMS,
        default="PRINTED_PAPER",
        update=_on_recipe_changed,
    )
    sensitivity_mode: EnumProperty(
        name="Sensitivity",
        description="How the colourants' light sensitivity is given",
        items=(
            ("BLUE_WOOL", "Blue Wool", "ISO Blue Wool class 1-8: about 0.4 Mlx·h to a just-noticeable "
             "fade for class 1, about 3 times more per class"),
            ("BETA", "β", "The sensitivity coefficient β of the fading model (paper, equation 3) directly"),
        ),
        default="BLUE_WOOL",
    )
    blue_wool: IntProperty(
        name="Blue Wool Class",
        description="ISO Blue Wool light-fastness class: 1 very fugitive (fades in weeks of daylight) "
        "to 8 very stable",
        default=RECIPE_BLUE_WOOL["PRINTED_PAPER"],
        min=1,
        max=8,
    )
    fastness: StringProperty(
        name="Per-Colourant Classes",
        description="Blue Wool classes for single colourants, e.g. 'yellow=2' for a fugitive "
        "yellow dye (its colour goes first); empty: the recipe's matched classes",
        default="",
    )
    beta: FloatProperty(
        name="β (×10⁻⁶)",
        description="Sensitivity β of the most light-sensitive colourant (paper, equation 3), in "
        "millionths of 1 / (W m⁻² nm⁻¹ · nm · h · K): the other colourants keep their ratios to it. "
        "Blue Wool class 2 on paper is about 23",
        default=23.0,
        min=0.0,
        soft_max=1000.0,
        precision=3,
    )
    # -- the texture's own history (issue 14): a photograph of something already faded
    already_years: FloatProperty(
        name="Already Aged",
        description="The texture shows the material after this many years under the light "
        "below (0: it is new). Age first estimates the colours when new (the years slider's 0), "
        "then ages them with the scene's light",
        default=0.0,
        min=0.0,
        soft_max=200.0,
    )
    already_spectrum: _spectrum("The light the texture has already aged under",
                                PRIOR_SPECTRUM_ITEMS, "DAYLIGHT_GLASS", name="Under")
    already_uv_filter: _uv_filter("That light passed a UV-blocking filter")
    already_lux: FloatProperty(
        name="Illuminance",
        description="Illuminance on the material while that light was on, in lux",
        default=150.0,
        min=0.0,
        soft_max=20000.0,
    )
    already_hours_per_day: _hours_per_day("Hours per day that light was on")
    # -- several recipes in one material, by mask (.parts.properties, .aging.parts)
    parts: CollectionProperty(type=LIGHTFADE_PG_part, name="Parts",
                              description="Parts of the texture that age with their own recipe "
                              "(or do not age), each given by a mask")
    part_index: IntProperty(name="Active Part", default=0, min=0, options={"HIDDEN"},
                            description="The part shown below the list")
    rest: EnumProperty(name="Rest", items=REST_ITEMS, default="RECIPE",
                       description="What happens to everything no part claims")
    lanes: CollectionProperty(type=LIGHTFADE_PG_lane, name="Recipes in Use",
                              description="On an aged copy with parts: one preparation per "
                              "recipe in use")
    parts_key: StringProperty(name="Parts at Age", description="On an aged copy: the parts "
                              "it was made for (different parts now: press Age)")
    # -- written by Age on the object's aged copy of a material (read by Reset, the
    # -- handlers and the panels); the original material keeps none of this
    source: PointerProperty(
        name="Source Material",
        type=bpy.types.Material,
        description="The original material this aged copy was made from (set on aged copies only)",
    )
    aged_object: PointerProperty(
        name="Aged Object",
        type=bpy.types.Object,
        description="The object whose light aged this copy",
    )
    slot_backups: CollectionProperty(
        type=LIGHTFADE_PG_slot_backup,
        name="Slot Backups",
        description="The object's material slots as they were before aging (Reset puts them back)",
    )
    path: EnumProperty(
        name="Albedo Path",
        description="How the unaged colour was obtained",
        items=PATH_ITEMS,
        default="BAKED",
    )
    reason: StringProperty(
        name="Reason",
        description="Why this material took its albedo path",
    )
    albedo: PointerProperty(
        name="Albedo",
        type=bpy.types.Image,
        description="The unaged colour: the original image (direct path) or LightFade's "
        "Cycles-baked float image in the exposure UV map",
    )
    flat_colour: FloatVectorProperty(
        name="Flat Colour",
        description="Linear Base Color of a material with a plain colour",
        size=3,
        default=(0.8, 0.8, 0.8),
    )
    uv_map: StringProperty(
        name="UV Map",
        description="UV map the aged image is sampled with",
    )
    aged_image: PointerProperty(
        name="Aged Image",
        type=bpy.types.Image,
        description="Real aged pixels written by Apply Aging (for export, other engines, "
        "painting); none while the material evaluates the aging itself",
    )
    table_image: PointerProperty(
        name="Aging Table Image",
        type=bpy.types.Image,
        description="The colour table of this material's recipe and light spectra, shared "
        "by every aged material using them (read by the aging node group and by Apply Aging)",
    )
    signature: StringProperty(
        name="Signature",
        description="Digest of the exposure, schedules and recipe this copy was prepared from "
        "(a different digest now means stale)",
    )
    lost_texels: IntProperty(
        name="Lost Texels",
        description="Texels whose colour when new cannot be recovered (the texture's own "
        "history faded it past recovery)",
        default=0,
        min=0,
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
    LIGHTFADE_PG_slot_backup,
    LIGHTFADE_PG_material,
    LIGHTFADE_PG_scene,
)

#: (ID type, attribute, property group): attached in order, removed in reverse.
POINTERS = (
    (bpy.types.Scene, "lightfade", LIGHTFADE_PG_scene),
    (bpy.types.Light, "lightfade", LIGHTFADE_PG_schedule),
    (bpy.types.World, "lightfade", LIGHTFADE_PG_schedule),
    (bpy.types.Object, "lightfade_emitter", LIGHTFADE_PG_emission),
    (bpy.types.Material, "lightfade", LIGHTFADE_PG_material),
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
