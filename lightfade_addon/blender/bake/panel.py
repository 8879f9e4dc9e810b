"""What the Exposure Bake panel shows: quality presets with their measured cost, texel
density and map sizes, the light groups, and an estimate of the bake before it starts."""

from __future__ import annotations

import bpy

from ...output import plural
from . import sizing
from .common import LUX_PER_BAKE_UNIT, UV_MAP_NAME, luminance
from .emitters import (
    find_emitters,
    group_emitters,
    uncounted_emissive,
    uncounted_note,
    world_counts,
)
from .settings import BakeSettings
from . import instances
from .linked import linked_instancers
from .sizing import planned_map
from .presets import PRESETS
from .targets import find_targets, validate_targets

#: Targets whose sizes the panel lists (the estimate covers all of them).
LIST_LIMIT = 8

_SIZE_CACHE = {}
#: Sizes kept between redraws: more than a building's targets (at 512 a scene of 1000
#: objects planned every map again at each redraw).
SIZE_CACHE_LIMIT = 1 << 14


def _size(obj, depsgraph, settings):
    """Map width of ``obj`` under ``settings``, as the bake will make it (cached on what
    it depends on)."""
    layers = obj.data.uv_layers
    key = (obj.name, obj.data.name, len(obj.data.polygons), tuple(map(tuple, obj.matrix_world)),
           layers.active.name if layers.active else None, obj.lightfade.uv_created,
           UV_MAP_NAME in layers, settings.texels_per_metre, settings.max_size,
           settings.resolution)
    if key not in _SIZE_CACHE:
        _SIZE_CACHE[key] = planned_map(obj, depsgraph, settings, diagnose=False)[0]
        if len(_SIZE_CACHE) > SIZE_CACHE_LIMIT:
            _SIZE_CACHE.clear()
    return _SIZE_CACHE[key]


def world_lux(world):
    """Illuminance of an open horizontal plane under the world's Background (lux)."""
    for node in world.node_tree.nodes:
        if node.type == "BACKGROUND" and not node.mute:
            colour = luminance(tuple(node.inputs["Color"].default_value[:3]))
            return float(node.inputs["Strength"].default_value * colour * LUX_PER_BAKE_UNIT)
    return 0.0


def _draw_presets(layout, bake):
    col = layout.column(align=True)
    col.prop(bake, "quality")
    for key, preset in PRESETS.items():
        row = col.row()
        row.active = bake.quality == key
        if preset.noise_target is not None:
            row.label(text=f"{preset.label}: passes of {preset.pass_samples} spp, denoised, "
                           f"to noise {preset.noise_target:.0%} (p95 per texel) and "
                           f"±{preset.mean_target:.1%} (mean)")
        else:
            row.label(text=f"{preset.label}: {preset.samples} spp, denoised — "
                           f"{preset.relative_time:.0%} of the old time, noise "
                           f"{preset.noise_lit:.1%} lit / {preset.noise_shadow:.0%} shadow")
    preset = PRESETS.get(bake.quality)
    if preset is not None and preset.noise_target is not None:
        cap = layout.column(align=True)
        cap.prop(bake, "max_samples")
        cap.prop(bake, "max_minutes")


def _draw_groups(layout, scene, emitters):
    box = layout.box()
    groups = group_emitters(scene, emitters)
    box.label(text=f"{plural(len(groups), 'light group')} from "
                   f"{plural(len(emitters), 'emitter')}", icon="LIGHT")
    for group in groups:
        spectrum, uv_filter, hours, days = group.key
        names = ", ".join(group.member_names)
        row = box.row()
        row.label(text=names)
        if any(e.kind == "DAYLIGHT" for e in group.emitters):
            row.label(text=f"{spectrum}{' +UV filter' if uv_filter else ''}, the year's sun "
                      "and sky: one annual bake")
        else:
            row.label(text=f"{spectrum}{' +UV filter' if uv_filter else ''}, "
                      f"{hours:g} h × {days:g} d")
    world = scene.world
    if world is not None and world_counts(world):
        box.label(text=f"World: {world_lux(world):,.0f} lx on open ground", icon="WORLD")
    elif world is not None:
        box.label(text="World not counted: give it a spectrum (Sky Schedule)", icon="INFO")
    note = uncounted_note(uncounted_emissive(scene), limit=2)
    if note:
        box.label(text=note, icon="INFO")
    return groups


def draw_bake_panel(layout, context):
    """Draw the Exposure Bake panel into ``layout``."""
    scene = context.scene
    props, bake = scene.lightfade, scene.lightfade_bake
    layout.use_property_split = True
    _draw_presets(layout, bake)
    col = layout.column(align=True)
    if bake.quality == "CUSTOM":
        col.prop(props, "bake_samples")
        col.prop(bake, "denoise")
    col.prop(bake, "texels_per_metre")
    col.prop(props, "bake_resolution", text="Max Size")
    col.prop(props, "bake_margin")
    col.prop(bake, "window_portals")

    view_layer = getattr(context, "view_layer", None) or scene.view_layers[0]
    emitters = find_emitters(scene, view_layer)
    groups = _draw_groups(layout, scene, emitters)
    settings = BakeSettings.from_scene(scene)
    selected = list(getattr(context, "selected_objects", None) or []) or find_targets(scene)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    plans = instances.planned(depsgraph, view_layer, settings,
                              getattr(context, "selected_objects", None) or ())
    targets, _, _ = validate_targets([o for o in selected if o not in plans], True)
    linked = linked_instancers(scene)
    if linked:                                   # skipped by the bake unless the artist asks
        row = layout.row()
        row.label(text=f"{plural(len(linked), 'instance')} of linked collections: not aged",
                  icon="LIBRARY_DATA_DIRECT")
        row.operator("lightfade.localize_linked", text="Age Them")
    if (targets or plans) and groups:
        sizes = {o.name: _size(o, depsgraph, settings) for o in targets}
        box = layout.box()
        for obj in targets[:LIST_LIMIT]:
            box.label(text=f"{obj.name}: {sizes[obj.name]}²", icon="OBJECT_DATA")
        if len(targets) > LIST_LIMIT:
            box.label(text=f"… and {len(targets) - LIST_LIMIT} more")
        for plan in plans.values():              # one atlas per instanced source
            box.label(text=f"{plan.source.name}: {len(plan.placements)} instances, "
                      f"{plan.size}² atlas", icon="OUTLINER_OB_GROUP_INSTANCE")
        per_group = [[sizes[o.name] for o in targets if o.name not in g.member_names]
                     + [p.size for p in plans.values()] for g in groups]
        est = sizing.estimate_for(scene, per_group, settings)
        row = box.row()
        row.label(text=est.text(), icon="TIME")
        row.operator("lightfade.bake_calibrate", text="", icon="PREVIEW_RANGE")
    row = layout.row(align=True)
    row.operator("lightfade.bake_exposure", icon="RENDER_STILL")
    row.prop(bake, "only_changed", text="Changed Groups Only")
