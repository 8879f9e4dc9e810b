"""The aging panels: the sidebar's Aging panel (years, Age, Reset, Apply, the aged
copies and their state) and Material Properties > LightFade (the material's recipe,
light sensitivity and the light it has already aged under)."""

import bpy

from ...core.fading.recipes import RECIPES, blue_wool_dose, fastness_text
from ...output import plural
from ..panels import LightFadeSidebarMixin
from ..source import material_plan
from ..status import copy_status
from ..vocabulary import RECIPE_IDS
from .apply import aged_copies
from .copies import original
from .runtime import material_recipe
from .years import YEARS_PROP


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
        layout.prop(scene.lightfade, "frame_detail")
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


#: The sidebar's Aging panel first (it heads the tab); the material panel before the
#: parts' panel, its child.
CLASSES = (VIEW3D_PT_lightfade_aging, MATERIAL_PT_lightfade)
