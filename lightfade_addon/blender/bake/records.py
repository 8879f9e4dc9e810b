"""What a bake leaves in the .blend: exposure-map records and the bake settings.

``Object.lightfade`` (:class:`LIGHTFADE_PG_object`)
    The exposure maps of a mesh, one per light group (:class:`LIGHTFADE_PG_exposure_map`),
    the UV map they were baked on, and whether LightFade made that UV map.
``Scene.lightfade_bake`` (:class:`LIGHTFADE_PG_bake_settings`)
    Quality preset, texel density and denoising of the exposure bake.  The largest map
    size, the custom sample count and the margin stay in ``Scene.lightfade``
    (``bake_resolution``, ``bake_samples``, ``bake_margin``).

Registered by :mod:`lightfade_addon.blender` with the other classes and pointers
(:data:`CLASSES`, :data:`POINTERS`).
"""

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)
from bpy.types import PropertyGroup

from ..vocabulary import EMITTER_KIND_ITEMS
from .presets import PRESETS


class LIGHTFADE_PG_emitter_ref(PropertyGroup):
    """One emitter of a light group (``name`` is the light object, "World" or the mesh)."""

    kind: EnumProperty(name="Kind", items=EMITTER_KIND_ITEMS, default="SUN",
                       description="What this emitter is: a kind of lamp, the world or an "
                       "emissive mesh")


class LIGHTFADE_PG_exposure_map(PropertyGroup):
    """One baked exposure map: the illuminance (lux) one light group gives each texel.

    ``name`` (inherited) is the group's name: the first emitter's name, with ``+N`` when
    N more emitters share its spectrum and schedule.
    """

    emitter: StringProperty(
        name="Emitter",
        description="First emitter of the group (light object name, \"World\", or emissive object name)",
    )
    emitter_kind: EnumProperty(
        name="Emitter Kind",
        description="Type of the group's first emitter",
        items=EMITTER_KIND_ITEMS,
        default="SUN",
    )
    members: CollectionProperty(
        type=LIGHTFADE_PG_emitter_ref,
        name="Emitters",
        description="The emitters baked together into this map (same spectrum, UV filter and schedule)",
    )
    noise: FloatProperty(
        name="Noise",
        description="Relative error (95th percentile over lit texels) the map reached, from "
        "its independent passes; 0: not measured (one pass)",
        default=0.0,
        min=0.0,
    )
    samples: IntProperty(
        name="Samples",
        description="Samples per texel the map was baked with (all passes)",
        default=0,
        min=0,
    )
    image: PointerProperty(
        name="Exposure Image",
        type=bpy.types.Image,
        description="Float image (packed) holding illuminance in lux per texel (luminance of the "
        "baked irradiance) while the group is on",
    )


class LIGHTFADE_PG_object(PropertyGroup):
    """Exposure maps baked for a mesh object."""

    exposure_maps: CollectionProperty(
        type=LIGHTFADE_PG_exposure_map,
        name="Exposure Maps",
        description="One illuminance map per light group",
    )
    active_map_index: IntProperty(
        name="Active Exposure Map",
        description="Index of the exposure map shown in the panel list",
        default=0,
        min=0,
    )
    uv_map: StringProperty(
        name="UV Map",
        description="UV map the exposure maps were baked on (the aged textures must use the same one)",
    )
    uv_created: BoolProperty(
        name="UV Map Made by LightFade",
        description="LightFade made the UV map (the mesh's own UVs overlap): Reset removes it",
        default=False,
    )
    instance_tiles: StringProperty(
        name="Instance Tiles",
        description="Aged per instance: the attribute (custom property of each instancer) "
        "naming each placement's tile in the exposure atlas; empty: not instanced",
    )
    instance_record: StringProperty(
        name="Instance Record",
        description="The placements baked into the atlas (instancer, id, world matrix), to "
        "tell instances that moved, appeared or went",
    )
    instance_changes: StringProperty(
        name="Instance Changes",
        description="Why the instances are aged as they stand at the bake's frame only "
        "(they change with the frame), said by the bake and info; empty: they do not",
    )


QUALITY_ITEMS = tuple(
    (key, preset.label, preset.description) for key, preset in PRESETS.items()
) + (("CUSTOM", "Custom", "The samples and denoising set below"),)


class LIGHTFADE_PG_bake_settings(PropertyGroup):
    """How exposure is baked: quality preset, texel density, denoising."""

    quality: EnumProperty(
        name="Quality",
        description="Samples and denoising of the exposure bake",
        items=QUALITY_ITEMS,
        default="FINAL",
    )
    denoise: BoolProperty(
        name="Denoise",
        description="Denoise each map with Open Image Denoise (Custom quality)",
        default=True,
    )
    only_changed: BoolProperty(
        name="Changed Groups Only",
        description="Bake only light groups whose emitters changed; keep the other maps, and add "
        "up maps of groups that merged (a schedule made equal) without baking",
        default=False,
    )
    window_portals: BoolProperty(
        name="Portals over Windows",
        description="While the sky (world or annual daylight) is baked, put a temporary Cycles "
        "light portal over each window (a flat pane of glass with the sky on one side): less "
        "noise indoors, the same mean; glass that refracts is shown as a clear pane meanwhile, "
        "so that Cycles' shadow rays pass it. Off where the scene has portals of its own",
        default=True,
    )
    max_samples: IntProperty(
        name="Max Samples",
        description="Adaptive bake (Final): the most samples per texel any map gets; a map "
        "still noisier than the target there is named in the bake's report",
        default=128,
        min=8,
        soft_max=1024,
    )
    max_minutes: FloatProperty(
        name="Max Minutes",
        description="Adaptive bake (Final): no more passes start after this long (the first "
        "passes of every map always run); 0: no limit",
        default=0.0,
        min=0.0,
        soft_max=240.0,
    )
    texels_per_metre: FloatProperty(
        name="Texels per Metre",
        description="Exposure map density: map size follows each object's surface area, up to "
        "the Max Size",
        default=256.0,
        min=1.0,
        soft_max=2048.0,
    )


CLASSES = (
    LIGHTFADE_PG_emitter_ref,
    LIGHTFADE_PG_exposure_map,
    LIGHTFADE_PG_object,
    LIGHTFADE_PG_bake_settings,
)


#: (ID type, attribute, property group): attached in order, removed in reverse.
POINTERS = (
    (bpy.types.Object, "lightfade", LIGHTFADE_PG_object),
    (bpy.types.Scene, "lightfade_bake", LIGHTFADE_PG_bake_settings),
)

