"""Materials as artists make them, side by side in one sun, half of each in shadow.

One plate (1 m square, its own UVs) per kind of Base Color, in two rows, each kind
labelled on the ground in front of its plates. The sun comes from behind the rows at 45°
and a low wall stands behind each plate, as high as its distance from the plate's middle:
its shadow ends across the middle, so every plate has a lit front half and a shaded back
half. The two kinds that are about objects rather than graphs (``shared``, ``duplicates``)
have two plates side by side: one in full sun (no wall), one in full shade (a taller
wall). The camera looks at the rows from the front and above, over the labels; nothing
stands between it and the plates.

=================  ===========================================================
kind               Base Color
=================  ===========================================================
``image``          an Image Texture straight into Base Color (the control)
``tiled``          UV Map -> Mapping (scale 3) -> Image Texture
``procedural``     Checker Texture -> Color Ramp
``adjusted``       Image -> Hue/Saturation/Value -> Mix (multiply) -> reroute
``grouped``        the Principled BSDF inside a node group, its image outside
``attribute``      a colour attribute (vertex colours) of the mesh
``shared``         one material on two plates: one in full sun (left), one in full shade
``duplicates``     linked duplicates (one mesh): one in full sun (left), one in full shade
=================  ===========================================================

Each material is tagged ``lightfade_recipe = "dyed-fabric"`` (Blue Wool 3).  The sun gives
``SUN_LUX`` on the plates, 8 hours a day: bright daylight indoors by a window, about
5.8 Mlx·h a year, so that the demo's years (0, 2, 10) go from new through a visible fade
to clearly faded (a Blue Wool 3 dye fades noticeably after about 4 Mlx·h).
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
#: Illuminance on the plates' lit halves (lux), from a sun at ``SUN_ELEVATION``.
SUN_LUX = 2000.0
SUN_ELEVATION = 45.0
#: Distance between the plates' centres along x, and between the two rows along y (m).
SPACING, ROW_GAP = 1.35, 2.6
#: Height of the low wall behind each plate (m); at the sun's 45° its shadow ends across
#: the middle of the plate.  Behind the shaded plates of the two-plate kinds it is raised
#: to ``TALL`` so that its shadow covers them whole; their sunny plates have none.
WALL, TALL = 0.55, 1.15
#: (kind, column, row, role) of every plate: front row first; the two-plate kinds put
#: their sunny and their shaded plate side by side.
LAYOUT = (
    ("image", 0, 0, ""), ("tiled", 1, 0, ""), ("procedural", 2, 0, ""),
    ("adjusted", 3, 0, ""), ("grouped", 4, 0, ""),
    ("attribute", 0, 1, ""), ("shared", 1, 1, "Sun"), ("shared", 2, 1, "Shade"),
    ("duplicates", 3, 1, "Sun"), ("duplicates", 4, 1, "Shade"),
)
#: The label in front of each kind's plates.
LABELS = {"image": "image", "tiled": "tiled", "procedural": "procedural",
          "adjusted": "adjusted", "grouped": "node group", "attribute": "attribute",
          "shared": "shared: sun | shade", "duplicates": "duplicates: sun | shade"}
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


def _label(text, x, y, material, size=0.24):
    """Text lying on the ground, centred at (x, y), read from the camera (+x to the right)."""
    curve = bpy.data.curves.new(f"Label_{text}", "FONT")
    curve.body = text
    curve.size = size
    curve.align_x, curve.align_y = "CENTER", "CENTER"
    obj = bpy.data.objects.new(f"Label_{text}", curve)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = (x, y, 0.002)
    curve.materials.append(material)
    return obj


def _box(name, centre, size, material):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=centre)
    obj = bpy.context.active_object
    obj.name = obj.data.name = name
    obj.scale = size
    obj.data.materials.append(material)
    return obj


def build(path=None, resolution=64):
    """Build the plates, their labels, the ground, the wall and the sun; save to ``path``.

    Returns
    -------
    dict
        ``plates`` {kind: [object names]} (sunny first where there are two),
        ``materials`` {kind: material name}, ``labels`` {kind: text object name},
        ``camera`` and ``view``.
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
    shared = material_plain("Mat_Shared", (0.7, 0.1, 0.35))
    dup_mat = material_image(n)
    dup_mat.name = "Mat_Duplicates"
    plates = {kind: [] for kind in KINDS}
    materials = {"shared": shared.name, "duplicates": dup_mat.name}
    ground, wall = (C.plain_material("Ground", (0.05, 0.05, 0.05), roughness=0.9),
                    C.plain_material("Wall", (0.3, 0.3, 0.3), roughness=0.9))
    white = C.plain_material("Label", (0.8, 0.8, 0.8), roughness=0.9)
    for kind, col, row, role in LAYOUT:
        x, y = SPACING * col, ROW_GAP * row
        if kind in makers:
            mat = makers[kind]()
            obj = _plate(f"Plate_{kind}", x, y, mat)
            if kind == "attribute":
                _paint(obj.data)
            materials[kind] = mat.name
        elif kind == "shared":
            obj = _plate(f"Shared_{role}", x, y, shared)
        elif role == "Sun":
            obj = _plate("Duplicate_Sun", x, y, dup_mat)
        else:
            obj = _plate("Duplicate_Shade", x, y, None, mesh=bpy.data.objects["Duplicate_Sun"].data)
        plates[kind].append(obj.name)
        if role != "Sun":  # a sunny plate of a two-plate kind stays in full sun
            height = TALL if role == "Shade" else WALL
            _box(f"Wall_{obj.name}", (x, y + 0.55, height / 2), (SPACING, 0.1, height), wall)
    labels = {}
    for kind in KINDS:
        cols = [col for k, col, _row, _role in LAYOUT if k == kind]
        row = next(r for k, _c, r, _ in LAYOUT if k == kind)
        labels[kind] = _label(LABELS[kind], SPACING * sum(cols) / len(cols),
                              ROW_GAP * row - 0.8, white).name
    last = SPACING * max(col for _k, col, _r, _ro in LAYOUT)
    centre = last / 2
    # a dark ground: little light bounces from the sunny ground into the shade; the
    # ground and the walls are untagged, so they do not age
    _box("Ground", (centre, ROW_GAP / 2, -0.03), (last + 10.0, ROW_GAP + 10.0, 0.05), ground)
    C.add_light("Sun", "SUN", C.sun_strength_for_lux(SUN_LUX, SUN_ELEVATION), (centre, 8.0, 5.0),
                spectrum="daylight-glass", hours_per_day=8.0, uv_filter=False,
                direction=C.sun_direction(SUN_ELEVATION, -90.0), angle=0.0)
    # a dim grey sky for the render only (untagged: not part of aging)
    C.world_sky(scene, (0.6, 0.65, 0.75), 0.15)
    camera = C.add_camera("Camera", (centre, -4.0, 7.0), (centre, 1.2, 0.0), lens=35)
    scene.camera = camera
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    configure_render(scene, 640, 400, samples=16)
    info = dict(plates=plates, materials=materials, labels=labels, camera=camera.name,
                view=view_settings(scene))
    if path:
        save_blend(path)
    return info


if __name__ == "__main__":
    cli.main(build, __doc__.splitlines()[0], default_resolution=64)
