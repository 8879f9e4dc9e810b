"""``lightfade.age``: age the target materials and show the scene's years."""

import bpy
from bpy.props import FloatProperty

from ...output import plural
from ..errors import AgingError
from ..aging.prepare import age_scene
from ..progress import window_progress


class LIGHTFADE_OT_age(bpy.types.Operator):
    """Age the ticked materials (of the selected meshes, or all): each object gets its own \
aged copy of its materials, Base Color evaluated directly or with Cycles (the originals are \
kept untouched)"""

    bl_idname = "lightfade.age"
    bl_label = "Age"
    bl_options = {"REGISTER", "UNDO"}

    years: FloatProperty(
        name="Years",
        description="Years of exposure to show (negative: use the scene's years slider)",
        default=-1.0,
        soft_min=0.0,
        soft_max=100.0,
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        scene = context.scene
        years = scene.lightfade.years if self.years < 0 else self.years
        try:
            with window_progress(context) as progress:
                images = age_scene(scene, years, context.selected_objects, progress,
                                   report=lambda msg: self.report({"WARNING"}, msg))
        except AgingError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Aged {plural(len(images), 'material')} to {plural(years, 'year')}")
        return {"FINISHED"}
