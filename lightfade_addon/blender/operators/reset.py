"""``lightfade.reset``: undo aging — slots and links back, LightFade's images removed."""

import bpy
from bpy.props import BoolProperty

from ...output import plural
from ..reset import reset_scene


class LIGHTFADE_OT_reset(bpy.types.Operator):
    """Put the objects' original materials back and remove LightFade's aged copies, images \
and unused grids (and, optionally, the exposure maps)"""

    bl_idname = "lightfade.reset"
    bl_label = "Reset"
    bl_options = {"REGISTER", "UNDO"}

    exposure: BoolProperty(
        name="Remove Exposure Maps",
        description="Also remove the baked exposure maps and the UV map the bake made",
        default=False,
    )

    def execute(self, context):
        count = reset_scene(context.scene, exposure=self.exposure)
        self.report({"INFO"}, f"Reset {plural(count, 'aged material')}"
                    + (", removed the exposure maps" if self.exposure else ""))
        return {"FINISHED"}
