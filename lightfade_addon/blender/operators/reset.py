"""``lightfade.reset``: undo aging — original links back, LightFade's images removed."""

import bpy
from bpy.props import BoolProperty

from .. import aging


class LIGHTFADE_OT_reset(bpy.types.Operator):
    """Restore the materials' original Base Color links and remove LightFade's aged images \
(and, optionally, the exposure maps and stored grids)"""

    bl_idname = "lightfade.reset"
    bl_label = "Reset"
    bl_options = {"REGISTER", "UNDO"}

    exposure: BoolProperty(
        name="Remove Exposure Maps",
        description="Also remove the baked exposure maps and the grids stored in the file",
        default=False,
    )

    def execute(self, context):
        scene = context.scene
        materials = [m for m in bpy.data.materials if m.lightfade.aged_image is not None
                     or (m.node_tree and m.node_tree.nodes.get(aging.NODE_NAME))]
        for material in materials:
            aging.reset_material(material)
        removed_maps = 0
        if self.exposure:
            for obj in scene.objects:
                for item in obj.lightfade.exposure_maps:
                    if item.image is not None and item.image.users <= 1:
                        bpy.data.images.remove(item.image)
                        removed_maps += 1
                obj.lightfade.exposure_maps.clear()
            if aging.GRID_STORE in scene:
                del scene[aging.GRID_STORE]
        self.report({"INFO"}, f"Reset {len(materials)} material(s)"
                    + (f", removed {removed_maps} exposure map(s)" if self.exposure else ""))
        return {"FINISHED"}
