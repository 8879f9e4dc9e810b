"""``lightfade.part_add`` and ``lightfade.part_remove``: a material's parts list."""

import bpy

from ..aging.copies import original


def _material(context):
    material = getattr(context, "material", None)
    return original(material) if material is not None else None


class LIGHTFADE_OT_part_add(bpy.types.Operator):
    """Add a part: texels (by a mask) that age with their own recipe or do not age"""

    bl_idname = "lightfade.part_add"
    bl_label = "Add Part"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _material(context) is not None

    def execute(self, context):
        props = _material(context).lightfade
        part = props.parts.add()
        part.name = f"Part {len(props.parts)}"
        props.part_index = len(props.parts) - 1
        return {"FINISHED"}


class LIGHTFADE_OT_part_remove(bpy.types.Operator):
    """Remove the active part (its texels go back to the rest of the material)"""

    bl_idname = "lightfade.part_remove"
    bl_label = "Remove Part"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        material = _material(context)
        return material is not None and len(material.lightfade.parts) > 0

    def execute(self, context):
        props = _material(context).lightfade
        index = min(props.part_index, len(props.parts) - 1)
        props.parts.remove(index)
        props.part_index = max(0, min(index, len(props.parts) - 1))
        return {"FINISHED"}


CLASSES = (LIGHTFADE_OT_part_add, LIGHTFADE_OT_part_remove)
