"""``lightfade.apply_aging`` and ``lightfade.live_aging``: real aged pixels, and back.

The aged materials evaluate the years themselves (a node group). For other engines,
glTF/USD export and texture painting, *Apply Aging* writes the aged colours at the
scene's years into real images (``LF_Applied_*``) and feeds them in place of the
groups; *Live Aging* puts the groups back and removes those images.
"""

import bpy

from ...output import plural
from ..aging.apply import apply_aging, live_aging
from ..errors import AgingError
from ..aging.years import get_years


class LIGHTFADE_OT_apply_aging(bpy.types.Operator):
    """Write the aged colours at the scene's years into real images and use them in the \
aged materials (for export, other engines and texture painting)"""

    bl_idname = "lightfade.apply_aging"
    bl_label = "Apply to Images"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        years = get_years(context.scene)
        try:
            images = apply_aging(context.scene, years)
        except AgingError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Applied {plural(years, 'year')} to "
                    f"{plural(len(images), 'image')}")
        return {"FINISHED"}


class LIGHTFADE_OT_live_aging(bpy.types.Operator):
    """Let the aged materials evaluate the years again (removes the applied images)"""

    bl_idname = "lightfade.live_aging"
    bl_label = "Live Aging"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        n = live_aging(context.scene)
        self.report({"INFO"}, f"Removed {plural(n, 'applied image')}")
        return {"FINISHED"}
