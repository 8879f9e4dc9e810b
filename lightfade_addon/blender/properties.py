"""LightFade's data model: the property groups stored in the .blend file.

Where the data lives
--------------------
``Scene.lightfade`` (:class:`LIGHTFADE_PG_scene`)
    The years slider and the bake settings.
``Light.lightfade`` and ``World.lightfade`` (:class:`LIGHTFADE_PG_schedule`)
    The light schedule of a lamp or of the sky: spectrum, UV filter, hours per day,
    days per year, and whether the emitter takes part in aging.  It lives on the light
    *data* (shared by instanced lamps) and on the world.
``Object.lightfade_emitter`` (:class:`LIGHTFADE_PG_schedule`)
    The same schedule for an emissive mesh (an emissive window pane, a light panel).
    A mesh counts as an emitter when one of its materials has a non-zero Emission
    (an Emission node or the Principled BSDF's Emission Strength) and this schedule is
    enabled (the default).
``Material.lightfade`` (:class:`LIGHTFADE_PG_material`)
    The aging recipe of a material.
``Object.lightfade`` and ``Scene.lightfade_bake``
    The exposure maps of a mesh and the bake settings: :mod:`.bake.records` (registered
    with the bake package).

Exposure maps hold illuminance in lux (see :mod:`.bake` for the calibration); the annual
dose of a texel is ``lux * hours_per_day * days_per_year`` lux·h.
"""

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)
from bpy.types import PropertyGroup

from ..core import recipes as _recipes

# --------------------------------------------------------------------------- spectra

#: Spectrum enum identifier -> the id the core uses for that light spectrum.
SPECTRUM_IDS = {
    "DAYLIGHT": "daylight",
    "DAYLIGHT_GLASS": "daylight-glass",
    "INCANDESCENT": "incandescent",
    "FLUORESCENT": "fluorescent",
    "LED": "led",
}

#: What ``AUTO`` means for each emitter kind.  Sun, sky and emissive meshes stand for
#: daylight entering a room through window glass (CIE ID65: UV below ~320 nm cut);
#: point, spot and area lamps are taken as modern white LEDs (CIE LED-B).
AUTO_SPECTRUM = {
    "SUN": "DAYLIGHT_GLASS",
    "WORLD": "DAYLIGHT_GLASS",
    "EMISSIVE": "DAYLIGHT_GLASS",
    "POINT": "LED",
    "SPOT": "LED",
    "AREA": "LED",
}

SPECTRUM_ITEMS = (
    ("AUTO", "Auto", "From the emitter type: sun, sky and emissive meshes give daylight "
     "through window glass; point, spot and area lamps give white LED light"),
    ("DAYLIGHT", "Daylight", "CIE D65 daylight, with its full UV content (outdoors, open window)"),
    ("DAYLIGHT_GLASS", "Daylight through Glass",
     "CIE ID65: daylight behind ordinary window glass, UV below about 320 nm cut"),
    ("INCANDESCENT", "Incandescent", "CIE illuminant A: tungsten filament lamp, 2856 K"),
    ("FLUORESCENT", "Fluorescent", "CIE FL series fluorescent tube (emits some UV)"),
    ("LED", "LED", "CIE LED-B white LED (practically no UV)"),
)

EMITTER_KIND_ITEMS = (
    ("SUN", "Sun", "A sun lamp"),
    ("POINT", "Point", "A point lamp"),
    ("SPOT", "Spot", "A spot lamp"),
    ("AREA", "Area", "An area lamp"),
    ("WORLD", "World", "The world background (sky light)"),
    ("EMISSIVE", "Emissive Mesh", "A mesh with an emissive material"),
)


def resolve_spectrum(schedule, kind):
    """The core's spectrum id for ``schedule`` on an emitter of ``kind``.

    Parameters
    ----------
    schedule : LIGHTFADE_PG_schedule
        The light schedule (its ``spectrum`` may be ``'AUTO'``).
    kind : str
        One of the :data:`EMITTER_KIND_ITEMS` identifiers.

    Returns
    -------
    str
        ``"daylight"``, ``"daylight-glass"``, ``"incandescent"``, ``"fluorescent"``
        or ``"led"``.
    """
    spectrum = schedule.spectrum
    if spectrum == "AUTO":
        spectrum = AUTO_SPECTRUM.get(kind, "DAYLIGHT_GLASS")
    return SPECTRUM_IDS[spectrum]


# --------------------------------------------------------------------------- recipes

#: Recipe enum identifier -> the id the core knows it by.
RECIPE_IDS = {
    "PRINTED_PAPER": "printed-paper",
    "DYED_FABRIC": "dyed-fabric",
    "PAINTED_WOOD": "painted-wood",
    "BARE_WOOD": "bare-wood",
}

#: Blue Wool class a recipe starts from (ISO 105-B; 1 = very fugitive, 8 = very stable):
#: the class of its most light-sensitive colourant in the core's recipe.
RECIPE_BLUE_WOOL = {
    key: int(min(k for k in _recipes.RECIPES[core_id].blue_wool if k is not None))
    for key, core_id in RECIPE_IDS.items()
}

RECIPE_ITEMS = (
    ("PRINTED_PAPER", "Printed Paper",
     "CMY inks on paper: photographs, posters, book covers (weak dyes fade first, paper yellows)"),
    ("DYED_FABRIC", "Dyed Fabric", "Dyed textile: carpets, curtains, upholstery"),
    ("PAINTED_WOOD", "Painted Wood", "Pigmented paint or stain over wood"),
    ("BARE_WOOD", "Bare Wood", "Unfinished or clear-finished wood: lignin yellows then bleaches"),
)


def _on_recipe_changed(self, context):
    # A new recipe brings its usual light-fastness; the user may change it afterwards.
    self.blue_wool = RECIPE_BLUE_WOOL.get(self.recipe, 3)


# --------------------------------------------------------------------------- groups


class LIGHTFADE_PG_schedule(PropertyGroup):
    """How long and with which spectrum an emitter shines (lamp, world or emissive mesh)."""

    enabled: BoolProperty(
        name="Include in Aging",
        description="Bake an exposure map for this emitter and count its light when aging",
        default=True,
    )
    spectrum: EnumProperty(
        name="Spectrum",
        description="Spectral power distribution of this emitter's light (UV content drives much of the fading)",
        items=SPECTRUM_ITEMS,
        default="AUTO",
    )
    uv_filter: BoolProperty(
        name="UV Filter",
        description="A UV-blocking filter or film cuts this emitter's light below 400 nm",
        default=False,
    )
    hours_per_day: FloatProperty(
        name="Hours per Day",
        description="Hours per day this emitter is on (for the sun: hours of direct sun on the scene)",
        default=8.0,
        min=0.0,
        max=24.0,
        precision=1,
    )
    days_per_year: FloatProperty(
        name="Days per Year",
        description="Days per year this emitter is on",
        default=365.0,
        min=0.0,
        max=366.0,
        precision=0,
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
    albedo_image: PointerProperty(
        name="Albedo Image",
        type=bpy.types.Image,
        description="Texture holding the unaged colour; empty = the image feeding the Principled BSDF "
        "Base Color",
    )
    # -- state written by the Age operator (read by Reset and the handlers) --
    aged_image: PointerProperty(
        name="Aged Image",
        type=bpy.types.Image,
        description="The image LightFade writes the aged colour into (the original is never changed)",
    )
    aged_object: StringProperty(
        name="Aged Object",
        description="The object whose exposure maps aged this material",
    )
    original_node: StringProperty(
        name="Original Node",
        description="Name of the Image Texture node that fed Base Color before aging",
    )
    original_output: StringProperty(
        name="Original Output",
        description="Identifier of the output socket that fed Base Color before aging",
    )
    flat_albedo: BoolProperty(
        name="Flat Albedo",
        description="The material had a flat Base Color, which LightFade turned into a texture",
        default=False,
    )


def _on_years_changed(self, context):
    # Dragging the slider: update the aged textures (keyframed values go through the
    # frame-change handler instead: update callbacks do not fire for F-curves).
    from . import handlers

    handlers.years_changed(self.id_data)


class LIGHTFADE_PG_scene(PropertyGroup):
    """Scene-wide LightFade settings: the years slider and the bake settings."""

    years: FloatProperty(
        name="Years",
        description="Years of light exposure to show (animatable: keyframe it for a time-lapse)",
        default=0.0,
        min=0.0,
        soft_max=100.0,
        precision=1,
        options={"ANIMATABLE"},
        update=_on_years_changed,
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
    LIGHTFADE_PG_material,
    LIGHTFADE_PG_scene,
)

#: (ID type, attribute, property group): attached in order, removed in reverse.
POINTERS = (
    (bpy.types.Scene, "lightfade", LIGHTFADE_PG_scene),
    (bpy.types.Light, "lightfade", LIGHTFADE_PG_schedule),
    (bpy.types.World, "lightfade", LIGHTFADE_PG_schedule),
    (bpy.types.Object, "lightfade_emitter", LIGHTFADE_PG_schedule),
    (bpy.types.Material, "lightfade", LIGHTFADE_PG_material),
)


def register_pointers():
    """Attach the property groups to Blender's ID types (after the classes are registered)."""
    for id_type, attr, group in POINTERS:
        setattr(id_type, attr, PointerProperty(type=group, name="LightFade",
                                               description="LightFade settings"))


def unregister_pointers():
    """Remove what :func:`register_pointers` attached, in reverse order."""
    for id_type, attr, _group in reversed(POINTERS):
        if hasattr(id_type, attr):
            delattr(id_type, attr)
