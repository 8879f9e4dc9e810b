"""``Material.lightfade``: how a material ages (recipe, light sensitivity, the light it
has already aged under) and, on an aged copy, what Age made of it (path, slots, images).

Its parts are :mod:`..parts.properties`; the scene's years and bake settings are
:mod:`..properties`.
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

from ..parts.properties import REST_ITEMS, LIGHTFADE_PG_lane, LIGHTFADE_PG_part
from ..properties import hours_per_day_prop, spectrum_prop, uv_filter_prop
from ..vocabulary import (
    PRIOR_SPECTRUM_ITEMS,
    RECIPE_BLUE_WOOL,
    RECIPE_ITEMS,
)


def _on_recipe_changed(self, context):
    # A new recipe brings its usual light-fastness; the user may change it afterwards.
    self.blue_wool = RECIPE_BLUE_WOOL.get(self.recipe, 3)


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
    already_spectrum: spectrum_prop("The light the texture has already aged under",
                                PRIOR_SPECTRUM_ITEMS, "DAYLIGHT_GLASS", name="Under")
    already_uv_filter: uv_filter_prop("That light passed a UV-blocking filter")
    already_lux: FloatProperty(
        name="Illuminance",
        description="Illuminance on the material while that light was on, in lux",
        default=150.0,
        min=0.0,
        soft_max=20000.0,
    )
    already_hours_per_day: hours_per_day_prop("Hours per day that light was on")
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


#: Registered after the parts' groups (it holds them).
CLASSES = (LIGHTFADE_PG_slot_backup, LIGHTFADE_PG_material)

#: (ID type, attribute, property group): attached in order, removed in reverse.
POINTERS = ((bpy.types.Material, "lightfade", LIGHTFADE_PG_material),)
