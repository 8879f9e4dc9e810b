"""Material Properties > LightFade > Parts: several recipes in one material, by mask."""

import bpy

from ..aging.copies import original
from ..aging.parts import part_problems, recipes_in_use
from ..source import find_colour_socket
from .properties import KEEP

#: What each mask source does, said under it.
_MASK_HELP = {
    "IMAGE": "White where this part is; sampled like a texture (Linear, Repeat)",
    "ATTRIBUTE": "A mesh attribute (Vertex Paint, Geometry Nodes): 1 where this part is",
    "SOCKET": "An output of a node of your graph, by the node's name: 1 where this part is",
}


class LIGHTFADE_UL_parts(bpy.types.UIList):
    """One row per part: its name and what it ages as."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property,
                  index=0, flt_flag=0):
        row = layout.row(align=True)
        row.prop(item, "name", text="", emboss=False, icon="MOD_MASK")
        label = next(i[1] for i in item.bl_rna.properties["recipe"].enum_items
                     if i.identifier == item.recipe)
        row.label(text=label)


def _draw_part(layout, part):
    layout.prop(part, "recipe")
    if part.recipe == KEEP:
        layout.label(text="Its pixels stay exactly as they are, at every years", icon="INFO")
    else:
        layout.prop(part, "sensitivity_mode")
        layout.prop(part, "blue_wool" if part.sensitivity_mode == "BLUE_WOOL" else "beta")
    layout.prop(part, "mask")
    if part.mask == "IMAGE":
        layout.template_ID(part, "image", open="image.open")
        layout.prop(part, "uv_map")
    elif part.mask == "ATTRIBUTE":
        layout.prop(part, "attribute")
    else:
        layout.prop(part, "node")
        layout.prop(part, "socket")
    layout.prop(part, "channel", expand=True)
    layout.label(text=_MASK_HELP[part.mask], icon="INFO")


class MATERIAL_PT_lightfade_parts(bpy.types.Panel):
    """Which parts of the material's texture age with which recipe."""

    bl_label = "Parts"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"
    bl_parent_id = "MATERIAL_PT_lightfade"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return getattr(context, "material", None) is not None

    def draw(self, context):
        layout = self.layout
        material = original(context.material)
        props = material.lightfade
        layout.active = props.enabled
        layout.label(text="One texture, several materials: each part ages with its own "
                     "recipe", icon="INFO")
        row = layout.row()
        row.template_list("LIGHTFADE_UL_parts", "", props, "parts", props, "part_index",
                          rows=3)
        col = row.column(align=True)
        col.operator("lightfade.part_add", text="", icon="ADD")
        col.operator("lightfade.part_remove", text="", icon="REMOVE")
        layout.use_property_split = True
        if not props.parts:
            layout.label(text="No parts: the whole material ages with the recipe above")
            return
        layout.prop(props, "rest", text="Rest of the Material")
        if 0 <= props.part_index < len(props.parts):
            _draw_part(layout.box(), props.parts[props.part_index])
        layout.label(text=f"{len(recipes_in_use(material))} recipe(s) aging, mixed by the "
                     "masks; overlaps share", icon="NODETREE")
        obj = context.object
        colour, _problem = find_colour_socket(material)
        if obj is not None and obj.type == "MESH" and colour is not None:
            for problem in part_problems(obj, material, colour):
                layout.label(text=problem, icon="ERROR")


CLASSES = (LIGHTFADE_UL_parts, MATERIAL_PT_lightfade_parts)
