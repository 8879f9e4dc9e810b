"""The Daylight panel (3D viewport > LightFade): place, weather, what happens to the sun
lamps, the annual doses of the active object per material, and the false-colour view."""

import bpy

from ..bake.common import LightFadeBakeError
from ..bake.daylight import replaced_lamps, sky_changed
from .doses import material_doses
from .place import (
    DaylightError,
    place_source,
    read_weather,
    sun_position_settings,
    weather_path,
)
from .view import view_objects


def _mlxh(v):
    return f"{v / 1e6:.3g} Mlx·h"


def draw_doses(layout, scene, obj):
    """Annual dose per material and light group of ``obj`` (max and mean over its texels)."""
    try:
        rows = material_doses(scene, obj)
    except LightFadeBakeError as err:
        layout.label(text=str(err).splitlines()[0], icon="INFO")
        return
    box = layout.box()
    box.label(text=f"{obj.name}: annual dose per material (max / mean per year)")
    if any(sky_changed(scene, m.image) for m in obj.lightfade.exposure_maps):
        box.label(text="Daylight was baked for another place, north or weather: bake again",
                  icon="ERROR")
    for row in rows[:12]:
        line = box.row()
        line.label(text=f"{row['material']} ← {row['group']}")
        line.label(text=f"{_mlxh(row['max'])} / {_mlxh(row['mean'])}")


class VIEW3D_PT_lightfade_daylight(bpy.types.Panel):
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "LightFade"
    bl_label = "Daylight"

    def draw(self, context):
        scene = context.scene
        props = scene.lightfade_daylight
        layout = self.layout
        layout.use_property_split = True
        source = place_source(scene)
        header = layout.row()
        header.prop(props, "enabled")
        col = layout.column(align=True)
        if sun_position_settings(scene) is not None:
            col.prop(props, "use_sun_position")
        col.prop(props, "preset")
        sub = col.column(align=True)
        sub.active = not (props.use_sun_position and sun_position_settings(scene) is not None)
        sub.prop(props, "latitude")
        sub.prop(props, "longitude")
        sub.prop(props, "north")
        col.prop(props, "weather")
        col.prop(props, "albedo")
        col.prop(props, "altitude")
        col = layout.column(align=True)
        col.prop(props, "spectrum")
        col.prop(props, "uv_filter")
        col.prop(props, "sky_width")
        info = layout.box()
        if source is None:
            info.label(text="No place: daylight is the sun lamps with their hours per day",
                       icon="INFO")
        else:
            lat, lon, north, where = source
            info.label(text=f"{lat:.2f}°, {lon:.2f}°, north {north:.0f}° (from {where})",
                       icon="WORLD")
            path = weather_path(scene)
            info.label(text=f"Weather: {path}" if path else "Weather: clear sky every day")
            if props.enabled:
                info.label(text="One annual bake: lux·h per year, no hours per day",
                           icon="LIGHT_SUN")
                muted = replaced_lamps(scene)
                if muted:
                    info.label(text=f"Muted in the bake (the annual sky replaces them): "
                               f"{', '.join(muted)}", icon="HIDE_ON")
                info.label(text="Other lamps keep their schedules")
            else:
                info.label(text="Annual daylight off: sun lamps with their hours per day")
            if path:
                try:
                    read_weather(path)
                except DaylightError as err:
                    info.label(text=str(err), icon="ERROR")

        obj = context.object
        if obj is not None and obj.type == "MESH" and len(obj.lightfade.exposure_maps):
            draw_doses(layout, scene, obj)
        row = layout.row(align=True)
        row.operator("lightfade.dose_view", text="Dose", icon="COLORSET_04_VEC").mode = "DOSE"
        row.operator("lightfade.dose_view", text="Years to Fade",
                     icon="COLORSET_02_VEC").mode = "YEARS"
        if view_objects(scene):
            row.operator("lightfade.dose_view_clear", text="", icon="X")


CLASSES = (VIEW3D_PT_lightfade_daylight,)
