"""LightFade's panels: a "LightFade" tab in the 3D viewport sidebar, and a panel in
Material Properties."""

import bpy

from ..core.fading.recipes import RECIPES, blue_wool_dose, fastness_text
from .aging.apply import aged_copies
from .aging.copies import original
from .vocabulary import RECIPE_IDS
from .source import material_plan
from .bake.daylight import stands_for_daylight
from .bake.panel import draw_bake_panel
from .stats import annual_dose, emitter_schedule, image_max
from .status import copy_status
from .aging.runtime import material_recipe
from .aging.years import YEARS_PROP
from ..output import plural


class LightFadeSidebarMixin:
    """Shared placement of the sidebar panels (3D viewport > N panel > LightFade)."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "LightFade"


def _draw_schedule(layout, schedule):
    layout.prop(schedule, "enabled")
    col = layout.column()
    col.active = schedule.enabled
    col.prop(schedule, "spectrum")
    col.prop(schedule, "uv_filter")
    col.prop(schedule, "hours_per_day")
    col.prop(schedule, "days_per_year")


def _draw_dose(layout, label, max_lux, schedule):
    """One row: ``label  max lux  annual dose``."""
    dose = annual_dose(max_lux, schedule) if schedule is not None else 0.0
    row = layout.row()
    row.label(text=label)
    row.label(text=f"{max_lux:,.0f} lx")
    row.label(text=f"{dose:,.0f} lx·h/yr ({dose / 1e6:.3g} Mlx·h)")


class VIEW3D_PT_lightfade_aging(LightFadeSidebarMixin, bpy.types.Panel):
    bl_label = "Aging"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        scene = context.scene
        row = layout.row(align=True)
        if YEARS_PROP in scene.keys():             # the keyframable custom property (I keys it)
            row.prop(scene, f'["{YEARS_PROP}"]', text="Years")
        else:
            row.prop(scene.lightfade, "years")
        row.operator("lightfade.key_years", text="", icon="KEY_HLT")
        layout.prop(scene.lightfade, "aged_rays")
        row = layout.row(align=True)
        row.operator("lightfade.age", icon="TIME")
        row.operator("lightfade.reset", icon="LOOP_BACK")
        copies = aged_copies(context.scene)
        if copies:
            row = layout.row(align=True)
            applied = any(c.lightfade.aged_image is not None for c in copies)
            row.operator("lightfade.apply_aging", icon="IMAGE_DATA")
            if applied:
                row.operator("lightfade.live_aging", icon="NODETREE")
        col = layout.column(align=True)
        for copy in copies[:8]:
            props = copy.lightfade
            status = copy_status(context.scene, copy)
            col.label(text=f"{props.aged_object.name} · {props.source.name}: "
                      f"{props.path.lower()}, {status}",
                      icon="ERROR" if status.startswith("stale") else "MATERIAL")
        if len(copies) > 8:
            col.label(text=f"… and {len(copies) - 8} more")


class VIEW3D_PT_lightfade_bake(LightFadeSidebarMixin, bpy.types.Panel):
    bl_label = "Exposure Bake"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        draw_bake_panel(layout, context)

        obj = context.object
        if obj is None or obj.type != "MESH" or not obj.lightfade.exposure_maps:
            return
        box = layout.box()
        box.label(text=f"{obj.name}: exposure maps (UV \"{obj.lightfade.uv_map}\")")
        for item in obj.lightfade.exposure_maps:
            schedule = emitter_schedule(context.scene, item.emitter, item.emitter_kind)
            label = ("Daylight (lx: year-round mean)" if item.emitter_kind == "DAYLIGHT"
                     else item.emitter)
            _draw_dose(box, label, image_max(item.image), schedule)


class VIEW3D_PT_lightfade_emitter(LightFadeSidebarMixin, bpy.types.Panel):
    """Schedule of the active lamp or emissive mesh, and the brightest texel it lights."""

    bl_label = "Light Schedule"

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.type in {"LIGHT", "MESH"}

    def draw(self, context):
        layout = self.layout
        obj = context.object
        if obj.type == "LIGHT":
            schedule = obj.data.lightfade
            if stands_for_daylight(context.scene, schedule, obj.data.type):
                layout.label(text="Annual daylight replaces this sun in the exposure bake "
                             "(muted there; it still lights renders)", icon="HIDE_ON")
        else:
            schedule = obj.lightfade_emitter
            layout.label(text="Emissive materials are not lamps unless counted here "
                         "(glazing, screens: leave off)", icon="INFO")
        layout.use_property_split = True
        _draw_schedule(layout, schedule)
        _draw_lit_objects(layout.box(), context.scene, obj.name, schedule)


class VIEW3D_PT_lightfade_world(LightFadeSidebarMixin, bpy.types.Panel):
    bl_label = "Sky Schedule (World)"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return context.scene.world is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        schedule = context.scene.world.lightfade
        if schedule.spectrum != "AUTO" and stands_for_daylight(context.scene, schedule, "WORLD"):
            layout.label(text="Annual daylight replaces this sky in the exposure bake",
                         icon="HIDE_ON")
        _draw_schedule(layout, schedule)
        _draw_lit_objects(layout.box(), context.scene, "World", schedule)


def _draw_lit_objects(layout, scene, emitter_name, schedule, limit=8):
    """Brightest texel per object lit by ``emitter_name``, and its annual dose."""
    rows = 0
    for obj in scene.objects:
        if obj.type != "MESH":
            continue
        item = obj.lightfade.exposure_maps.get(emitter_name)
        if item is None or item.image is None:
            continue
        if rows == limit:
            layout.label(text="…")
            break
        _draw_dose(layout, obj.name, image_max(item.image), schedule)
        rows += 1
    if rows == 0:
        layout.label(text="No exposure maps baked for this emitter yet")


class MATERIAL_PT_lightfade(bpy.types.Panel):
    """Aging recipe of the active material."""

    bl_label = "LightFade"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.material is not None

    def draw_header(self, context):
        self.layout.prop(original(context.material).lightfade, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        material = original(context.material)
        props = material.lightfade
        if material != context.material:
            layout.label(text=f"Aged copy of '{material.name}' (its settings below)", icon="INFO")
        layout.active = props.enabled
        layout.prop(props, "recipe")
        recipe = RECIPES[RECIPE_IDS[props.recipe]]
        layout.label(text=recipe.description, icon="INFO")
        layout.prop(props, "sensitivity_mode")
        if props.sensitivity_mode == "BLUE_WOOL":
            layout.prop(props, "blue_wool")
            dose = blue_wool_dose(props.blue_wool) / 1e6
            layout.label(text=f"Just-noticeable fade after ~{dose:.3g} Mlx·h of UV-free light")
            layout.prop(props, "fastness")
            try:
                layout.label(text=f"Per colourant: {fastness_text(material_recipe(material))}")
            except ValueError as exc:
                layout.label(text=f"Per-Colourant Classes: {exc}", icon="ERROR")
        else:
            layout.prop(props, "beta")
        layout.prop(props, "already_years")
        if props.already_years > 0:
            col = layout.column(align=True)
            col.prop(props, "already_spectrum")
            col.prop(props, "already_lux")
            col.prop(props, "already_hours_per_day")
            col.prop(props, "already_uv_filter")
            col.label(text="Years 0 shows it new; the slider ages it with the scene's light",
                      icon="INFO")
        obj = context.object
        if obj is None or obj.type != "MESH":
            return
        box = layout.box()
        copy = context.material if material != context.material else None
        if copy is not None:
            box.label(text=f"{obj.name}: {copy.lightfade.path.lower()} — {copy.lightfade.reason}")
            box.label(text=copy_status(context.scene, copy))
            lost = copy.lightfade.lost_texels
            if lost:
                key = copy.lightfade.albedo
                share = lost / max(key.size[0] * key.size[1], 1) if key is not None else 0.0
                box.label(text=f"{plural(lost, 'texel')} ({share:.1%}) faded past recovery: "
                          "their colour when new is a best guess", icon="ERROR")
            return
        plan = material_plan(context.scene, obj, material)
        box.label(text=f"{obj.name}: {plan.path.lower()} — {plan.reason or 'not checked'}")
        for problem in plan.problems:
            box.label(text=problem, icon="ERROR")


CLASSES = (
    VIEW3D_PT_lightfade_aging,
    VIEW3D_PT_lightfade_bake,
    VIEW3D_PT_lightfade_emitter,
    VIEW3D_PT_lightfade_world,
    MATERIAL_PT_lightfade,
)
