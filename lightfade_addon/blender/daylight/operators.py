"""Operators of the daylight and dose views: show and clear the false-colour view."""

import os
import tempfile

import bpy
from bpy.props import EnumProperty, StringProperty

from ..bake.common import LightFadeBakeError
from . import colours
from .view import clear_view, show_view

MODE_ITEMS = (
    ("DOSE", "Annual Dose", "Annual dose per texel, lux·h per year, all light groups"),
    ("YEARS", "Years to Noticeable Fade", "Years until each texel of the material fades by "
     "ΔE00 = 1 (a just-noticeable difference) under its light"),
)


class LIGHTFADE_OT_dose_view(bpy.types.Operator):
    """Show the active mesh in false colour: its annual dose, or the years until a \
just-noticeable fade; writes a legend image.  The object and its materials are not \
changed (a view object stands in for it until Clear)"""

    bl_idname = "lightfade.dose_view"
    bl_label = "Show Dose View"
    bl_options = {"REGISTER", "UNDO"}

    mode: EnumProperty(name="Show", items=MODE_ITEMS, default="DOSE")
    legend: StringProperty(
        name="Legend", subtype="FILE_PATH", default="",
        description="PNG to write the legend to (empty: next to the .blend file, or in the "
        "temporary folder for an unsaved file)",
    )

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.type == "MESH" and context.mode == "OBJECT"

    def execute(self, context):
        obj = context.object
        if obj.get("lightfade_dose_view_of") is not None:
            obj = context.scene.objects.get(obj["lightfade_dose_view_of"]) or obj
        try:
            view, scale, note = show_view(context.scene, obj, self.mode,
                                          view_layer=context.view_layer)
        except LightFadeBakeError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        path = self.legend or os.path.join(
            bpy.path.abspath("//") if bpy.data.filepath else tempfile.gettempdir(),
            f"lightfade_{self.mode.lower()}_{bpy.path.clean_name(obj.name)}_legend.png")
        try:
            colours.write_legend(bpy.path.abspath(path), scale, note)
            legend = f"; legend: {path}"
        except (ImportError, OSError) as err:
            legend = f"; no legend image: {err}"
        self.report({"INFO"}, f"{obj.name}: {scale.title} from {colours.format_value(scale.low)} "
                              f"to {colours.format_value(scale.high)} {scale.unit}{legend}")
        return {"FINISHED"}


class LIGHTFADE_OT_dose_view_clear(bpy.types.Operator):
    """Remove the false-colour views and show the objects again as they were"""

    bl_idname = "lightfade.dose_view_clear"
    bl_label = "Clear Dose View"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        n = clear_view(context.scene, view_layer=context.view_layer)
        self.report({"INFO"}, f"Removed {n} dose view(s)")
        return {"FINISHED"}


CLASSES = (LIGHTFADE_OT_dose_view, LIGHTFADE_OT_dose_view_clear)
