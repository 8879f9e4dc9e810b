"""Materials as artists make them, side by side under one sun, half of each in shadow.

One plate (1 m square, its own UVs) per kind of Base Color, in a row along x; an
awning floating above the row shades the plates' ``y < 0`` half (the sun shines
straight down), so every plate has a lit half and a shaded half:

=================  ===========================================================
kind               Base Color
=================  ===========================================================
``image``          an Image Texture straight into Base Color (the control)
``tiled``          UV Map -> Mapping (scale 3) -> Image Texture
``procedural``     Checker Texture -> Color Ramp
``adjusted``       Image -> Hue/Saturation/Value -> Mix (multiply) -> reroute
``grouped``        the Principled BSDF inside a node group, its image outside
``attribute``      a colour attribute (vertex colours) of the mesh
``shared``         one material on two plates: one in full sun, one in full shade
``duplicates``     linked duplicates (one mesh): one in full sun, one in full shade
=================  ===========================================================

Each material is tagged ``lightfade_recipe = "dyed-fabric"`` (Blue Wool 3).
Run ``python -m scenes.materials out.blend`` to build and save.
"""

from __future__ import annotations

import bpy
import numpy as np

from . import cli
from . import common as C
from .render import configure_render, save_blend, view_settings

KINDS = ("image", "tiled", "procedural", "adjusted", "grouped", "attribute", "shared",
         "duplicates")
#: Sun strength giving about 20,000 lux on the plates (sun straight down).
SUN_LUX = 20000.0
RECIPE = "dyed-fabric"
BLUE_WOOL = 3


def _stripes(name, n, colours=((0.75, 0.15, 0.3), (0.2, 0.45, 0.7), (0.85, 0.7, 0.2))):
    """An sRGB image of vertical colour stripes (n × n texels)."""
    x = np.arange(n)[None, :, None]
    k = (x * len(colours) * 2 // n) % len(colours)
    rgb = np.asarray(colours, dtype=np.float32)[k.repeat(n, axis=0)[..., 0]]
    return C.image_from_array(name, rgb)


def _material(name):
    mat = C.new_material(name)
    mat["lightfade_recipe"] = RECIPE
    mat["lightfade_blue_wool"] = BLUE_WOOL
    return mat


def _image_node(tree, image, location=(-500, 300)):
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    node.location = location
    return node


def material_image(n):
    mat = _material("Mat_Image")
    tree = mat.node_tree
    tex = _image_node(tree, _stripes("Img_Image", n))
    tree.links.new(tex.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def material_tiled(n):
    mat = _material("Mat_Tiled")
    tree = mat.node_tree
    tex = _image_node(tree, _stripes("Img_Tiled", n))
    uv = tree.nodes.new("ShaderNodeUVMap")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (3.0, 3.0, 1.0)
    tree.links.new(uv.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    tree.links.new(tex.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def material_procedural():
    mat = _material("Mat_Procedural")
    tree = mat.node_tree
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 4.0
    ramp = tree.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.6, 0.05, 0.1, 1.0)
    ramp.color_ramp.elements[1].color = (0.1, 0.3, 0.6, 1.0)
    tree.links.new(checker.outputs["Fac"], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def material_adjusted(n):
    mat = _material("Mat_Adjusted")
    tree = mat.node_tree
    tex = _image_node(tree, _stripes("Img_Adjusted", n), (-900, 300))
    hsv = tree.nodes.new("ShaderNodeHueSaturation")
    hsv.inputs["Hue"].default_value = 0.55
    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.blend_type = "MULTIPLY"
    mix.inputs["Factor"].default_value = 0.5
    mix.inputs["B"].default_value = (0.9, 0.6, 0.5, 1.0)
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(tex.outputs["Color"], hsv.inputs["Color"])
    tree.links.new(hsv.outputs["Color"], mix.inputs["A"])
    tree.links.new(mix.outputs["Result"], reroute.inputs[0])
    tree.links.new(reroute.outputs[0], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def material_grouped(n):
    """The Principled BSDF inside a node group; the image feeds the group's Color input."""
    mat = _material("Mat_Grouped")
    tree = mat.node_tree
    group = bpy.data.node_groups.new("Fabric Shader", "ShaderNodeTree")
    group.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    gin = group.nodes.new("NodeGroupInput")
    gout = group.nodes.new("NodeGroupOutput")
    bsdf = group.nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Roughness"].default_value = 0.9
    group.links.new(gin.outputs["Color"], bsdf.inputs["Base Color"])
    group.links.new(bsdf.outputs["BSDF"], gout.inputs["Shader"])
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    tex = _image_node(tree, _stripes("Img_Grouped", n))
    tree.links.new(tex.outputs["Color"], node.inputs["Color"])
    out = tree.get_output_node("ALL")
    tree.links.new(node.outputs["Shader"], out.inputs["Surface"])
    return mat


def material_attribute():
    mat = _material("Mat_Attribute")
    tree = mat.node_tree
    attr = tree.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "Paint"
    tree.links.new(attr.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def material_plain(name, colour):
    mat = _material(name)
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*colour, 1.0)
    return mat


def _plate(name, x, y, material, mesh=None):
    if mesh is None:
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(x, y, 0.0))
        obj = bpy.context.active_object
        obj.name = obj.data.name = name
        obj.data.materials.append(material)
        return obj
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = (x, y, 0.0)
    return obj


def _paint(mesh):
    """A colour attribute "Paint" on the face corners: red to blue across the plate."""
    attr = mesh.color_attributes.new("Paint", "FLOAT_COLOR", "CORNER")
    co = np.array([mesh.vertices[l.vertex_index].co.x for l in mesh.loops])
    t = (co - co.min()) / max(np.ptp(co), 1e-9)
    rgba = np.stack([0.7 * (1 - t) + 0.1, 0.15 + 0 * t, 0.1 + 0.6 * t, 1 + 0 * t], -1)
    attr.data.foreach_set("color", rgba.astype(np.float32).ravel())


def build(path=None, resolution=64):
    """Build the plates, the awning and the sun; save to ``path`` if given.

    Returns
    -------
    dict
        ``plates`` {kind: [object names]} (sunny first where there are two),
        ``materials`` {kind: material name}, ``camera`` and ``view``.
    """
    C.reset()
    scene = bpy.context.scene
    n = int(resolution)
    makers = {
        "image": lambda: material_image(n),
        "tiled": lambda: material_tiled(n),
        "procedural": material_procedural,
        "adjusted": lambda: material_adjusted(n),
        "grouped": lambda: material_grouped(n),
        "attribute": material_attribute,
    }
    plates, materials = {}, {}
    for i, (kind, make) in enumerate(makers.items()):
        mat = make()
        obj = _plate(f"Plate_{kind}", 1.5 * i, 0.0, mat)
        if kind == "attribute":
            _paint(obj.data)
        plates[kind], materials[kind] = [obj.name], mat.name
    x = 1.5 * len(makers)
    shared = material_plain("Mat_Shared", (0.7, 0.1, 0.35))
    plates["shared"] = [_plate("Shared_Sun", x, 2.0, shared).name,
                        _plate("Shared_Shade", x, -2.0, shared).name]
    materials["shared"] = shared.name
    dup_mat = material_image(n)
    dup_mat.name = "Mat_Duplicates"
    sunny = _plate("Duplicate_Sun", x + 1.5, 2.0, dup_mat)
    shade = _plate("Duplicate_Shade", x + 1.5, -2.0, None, mesh=sunny.data)
    plates["duplicates"] = [sunny.name, shade.name]
    materials["duplicates"] = dup_mat.name
    # the awning: shades y < 0 of the row and the whole "shade" plates at y = -2
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(x / 2 + 0.75, -1.5, 1.2))
    awning = bpy.context.active_object
    awning.name = "Awning"
    awning.scale = (x + 4.0, 3.0, 0.05)
    # dark underneath, so that little light bounces from the lit halves into the shade
    awning.data.materials.append(C.plain_material("Awning", (0.02, 0.02, 0.02)))
    C.add_light("Sun", "SUN", C.sun_strength_for_lux(SUN_LUX), (0.0, 0.0, 5.0),
                spectrum="daylight-glass", hours_per_day=8.0, uv_filter=False,
                direction=(0.0, 0.0, -1.0), angle=0.0)
    camera = C.add_camera("Camera", (x / 2 + 0.75, -1.0, 9.0), (x / 2 + 0.75, 0.0, 0.0), lens=24)
    scene.camera = camera
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    configure_render(scene, 640, 400, samples=16)
    info = dict(plates=plates, materials=materials, camera=camera.name,
                view=view_settings(scene))
    if path:
        save_blend(path)
    return info


if __name__ == "__main__":
    cli.main(build, __doc__.splitlines()[0], default_resolution=64)
