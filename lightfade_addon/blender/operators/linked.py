"""``lightfade.localize_linked``: age the instances of collections linked from another .blend
through local copies of their aging objects (the artist asks; Reset undoes it)."""

import bpy

from ..bake.linked import linked_instancers, localize


class LIGHTFADE_OT_localize_linked(bpy.types.Operator):
    """Make the empties instancing a collection linked from another .blend instance a local \
collection of local copies of its aging objects (their meshes stay the library's), so that \
Bake Exposure ages each instance.  Reset with the exposure maps puts the library's \
collection back"""

    bl_idname = "lightfade.localize_linked"
    bl_label = "Age Linked Instances"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and bool(linked_instancers(context.scene))

    def execute(self, context):
        for line in localize(context.scene):
            self.report({"INFO"}, line)
        return {"FINISHED"}
