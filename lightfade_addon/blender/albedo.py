"""The unaged colour of a material as an array: read directly, or baked with Cycles.

Direct path: the image's own pixels (:func:`.pixels.read_linear`).  Baked path
(:func:`bake_albedos`): Cycles evaluates whatever drives the copy's colour socket —
any node graph — into a float, linear image in the exposure UV map at the exposure
map's resolution, so that texel i of the albedo is texel i of the exposure.  As
Blender's own bakers do, the socket is routed into an Emission shader on the material
output for the bake and the EMIT pass is baked (a DIFFUSE colour pass is not the raw
Base Color where Metallic or Transmission are non-zero).  Everything the bake changes
(the copies' trees, the other slots, render and bake settings, selection) is put back
by :class:`.undo.Undo`, also on error.
"""

from __future__ import annotations


import bpy
import numpy as np

from .bake.state import quiet_stdout
from .errors import AgingError
from .pixels import read_rgba
from .source import tree_at
from .undo import Undo

ALBEDO_PREFIX = "LF_Albedo_"
_TMP = "LF_TMP_"
_EXPOSED = "LightFade Base Color"


def albedo_image(copy, shape):
    """The float image that receives the copy's baked albedo (``LF_Albedo_<copy>``)."""
    h, w = shape
    name = ALBEDO_PREFIX + copy.name[len("LF_Aged_"):]
    image = bpy.data.images.get(name)
    if image is not None and (tuple(image.size) != (w, h) or not image.is_float):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    return image


def _expose(restore, copy, colour):
    """The output socket, in the copy's own tree, carrying the colour socket's value.

    Inside node groups (private to the copy) a temporary Group Output socket carries it
    up one level at a time; removed again by ``restore``.
    """
    trees = [copy.node_tree]
    for name in colour.groups:
        trees.append(trees[-1].nodes[name].node_tree)
    inner = trees[-1]
    target = inner.nodes[colour.node].inputs[colour.socket]
    if target.is_linked:
        value = target.links[0].from_socket
    else:
        rgb = inner.nodes.new("ShaderNodeRGB")
        restore.push(lambda t=inner, n=rgb: t.nodes.remove(n))
        rgb.outputs[0].default_value = tuple(target.default_value)
        value = rgb.outputs[0]
    for level in range(len(colour.groups), 0, -1):
        tree = trees[level]
        item = tree.interface.new_socket(_EXPOSED, in_out="OUTPUT", socket_type="NodeSocketColor")
        restore.push(lambda t=tree, i=item: t.interface.remove(i))
        out = next((n for n in tree.nodes if n.type == "GROUP_OUTPUT" and n.is_active_output), None)
        if out is None:
            out = tree.nodes.new("NodeGroupOutput")
            restore.push(lambda t=tree, n=out: t.nodes.remove(n))
        tree.links.new(value, out.inputs[item.identifier])
        parent = trees[level - 1].nodes[colour.groups[level - 1]]
        value = next(s for s in parent.outputs if s.name == _EXPOSED)
    return value


def _prepare_copy(restore, copy, colour, image):
    """Route the colour into an Emission shader on the active output; image node active."""
    tree = copy.node_tree
    value = _expose(restore, copy, colour)
    output = tree.get_output_node("CYCLES") or tree.get_output_node("ALL")
    emission = tree.nodes.new("ShaderNodeEmission")
    node = tree.nodes.new("ShaderNodeTexImage")
    restore.push(lambda: (tree.nodes.remove(emission), tree.nodes.remove(node)))
    emission.inputs["Strength"].default_value = 1.0
    tree.links.new(value, emission.inputs["Color"])
    surface = output.inputs["Surface"]
    before = surface.links[0].from_socket if surface.is_linked else None
    tree.links.new(emission.outputs["Emission"], surface)
    restore.push(lambda: tree.links.new(before, surface) if before is not None else None)
    node.image = image
    active = tree.nodes.active
    tree.nodes.active = node
    restore.push(lambda: setattr(tree.nodes, "active", active))


def _placeholder(restore, obj, slot):
    """A throwaway material in a slot that is not baked (Cycles needs an image in each)."""
    mat = bpy.data.materials.new(_TMP + "Slot")
    image = bpy.data.images.new(_TMP + "Slot", 4, 4, float_buffer=True)
    restore.push(lambda: (bpy.data.materials.remove(mat), bpy.data.images.remove(image)))
    if bpy.app.version < (5, 0, 0):       # Blender 4.x: node trees need use_nodes
        mat.use_nodes = True
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    link, material = slot.link, None
    if link != "OBJECT":
        slot.link = "OBJECT"
    material = slot.material
    slot.material = mat

    def put_back(s=slot, m=material, k=link):
        s.material = m
        if s.link != k:
            s.link = k

    restore.push(put_back)


def _settings(restore, scene, margin):
    render = scene.render
    restore.set(render, "engine", "CYCLES")
    cycles = scene.cycles
    for name, value in (("device", "CPU"), ("samples", 1), ("use_denoising", False),
                        ("bake_type", "EMIT")):
        restore.set(cycles, name, value)
    bake = render.bake
    for name, value in (("margin", margin), ("margin_type", "EXTEND"), ("use_clear", True),
                        ("use_selected_to_active", False), ("target", "IMAGE_TEXTURES"),
                        ("save_mode", "INTERNAL")):
        restore.set(bake, name, value)


def _select_only(restore, view_layer, obj):
    active = view_layer.objects.active
    selected = [o for o in view_layer.objects if o.select_get()]

    def put_back():
        for o in view_layer.objects:
            o.select_set(o in selected)
        view_layer.objects.active = active

    restore.push(put_back)
    for o in selected:
        o.select_set(False)
    restore.set(obj, "hide_render", False)
    if obj.hide_get(view_layer=view_layer):
        obj.hide_set(False, view_layer=view_layer)
        restore.push(lambda: obj.hide_set(True, view_layer=view_layer))
    obj.select_set(True)
    view_layer.objects.active = obj
    restore.set(view_layer, "material_override", None)


def bake_albedos(scene, view_layer, obj, jobs, uv_map, margin=2):
    """Bake each ``(copy, colour, image)`` job's colour into its image with one Cycles bake.

    The copies must already sit in ``obj``'s slots.  Returns ``{copy name: (H, W, 3)
    linear RGB}``.  Raises AgingError if Cycles fails (everything is restored first).
    """
    copies = {job[0] for job in jobs}
    with Undo() as restore:
        for copy, colour, image in jobs:
            _prepare_copy(restore, copy, colour, image)
        for slot in obj.material_slots:
            if slot.material not in copies:
                _placeholder(restore, obj, slot)
        _settings(restore, scene, margin)
        _select_only(restore, view_layer, obj)
        with quiet_stdout(), bpy.context.temp_override(
                scene=scene, view_layer=view_layer, active_object=obj, object=obj,
                selected_objects=[obj], selected_editable_objects=[obj]):
            result = bpy.ops.object.bake(type="EMIT", uv_layer=uv_map, margin=margin,
                                         margin_type="EXTEND", use_clear=True,
                                         target="IMAGE_TEXTURES", save_mode="INTERNAL")
        if "FINISHED" not in result:
            raise AgingError(f"Cycles could not bake the Base Color of object '{obj.name}'")
    out = {}
    for copy, _colour, image in jobs:
        image.pack()
        out[copy.name] = np.ascontiguousarray(read_rgba(image)[..., :3])
    return out
