"""``lightfade.key_years``: a linear key of the scene's years at the current frame."""

import bpy

from ..aging.years import get_years, keyframe_years


class LIGHTFADE_OT_key_years(bpy.types.Operator):
    """Insert a key of the years shown at the current frame (linear: a time-lapse shows \
years at a steady rate between keys)"""

    bl_idname = "lightfade.key_years"
    bl_label = "Key Years"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        scene = context.scene
        years = get_years(scene)
        keyframe_years(scene, scene.frame_current, years)
        self.report({"INFO"}, f"Keyed {years:g} years at frame {scene.frame_current}")
        return {"FINISHED"}
