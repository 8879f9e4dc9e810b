"""LightFade's sidebar tab (3D viewport > N > LightFade): the exposure bake and the light
schedules of lamps, emissive meshes and the sky.

The Aging panel and the material's panel are :mod:`.aging.panel`; the parts' panel is
:mod:`.parts.panel`; the daylight panel is :mod:`.daylight.panel`."""

import bpy

from .bake.daylight import stands_for_daylight
from .bake.panel import draw_bake_panel
from .stats import annual_dose, emitter_schedule, image_max


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




CLASSES = (
    VIEW3D_PT_lightfade_bake,
    VIEW3D_PT_lightfade_emitter,
    VIEW3D_PT_lightfade_world,
)
