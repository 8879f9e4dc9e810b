"""A false-colour view of an object's annual dose or years until a noticeable fade.

The view never edits the user's object or material: it adds a *view object*
``LF_DoseView.<object>`` sharing the object's mesh (and transform), whose material slots
are linked to the object and hold one Emission material showing a false-colour image in
the exposure UV map.  The object itself is hidden in the viewport meanwhile.  A source
aged through its instances shows the view on its instances instead: its own slots hold
the view's material (reading each instance's tile of the atlas) until the view is
cleared, and its slots are put back as they were.  The view
object is off in renders and is no emitter for LightFade; :func:`clear_view` removes
it, its material and image, and shows the object again as it was.
"""

from __future__ import annotations

import bpy
import numpy as np

from . import colours
from .doses import HORIZON_YEARS, total_dose, years_until_noticeable
from ..aging.graph import Graph, Sock
from ..aging.instances import tile_uv

VIEW_PREFIX = "LF_DoseView."
_OF = "lightfade_dose_view_of"
_HIDDEN = "lightfade_dose_view_hidden"
#: On the view of an instanced source: the source's slots to put back.
_SLOTS = "lightfade_dose_view_slots"


def view_objects(scene):
    """The view objects in ``scene``."""
    return [o for o in scene.objects if o.get(_OF) is not None]


def _target_material(obj):
    for slot in obj.material_slots:
        mat = slot.material
        if mat is not None:
            source = mat.lightfade.source or mat
            if source.lightfade.enabled:
                return source
    mats = [s.material for s in obj.material_slots if s.material is not None]
    return (mats[0].lightfade.source or mats[0]) if mats else None


def view_values(scene, obj, mode, material=None, horizon=HORIZON_YEARS, settings=None):
    """``(values (H, W), LogScale, note)`` of the view ``mode`` (``"DOSE"`` or ``"YEARS"``)."""
    if mode == "DOSE":
        dose = total_dose(scene, obj)
        return dose, colours.dose_scale(dose), f"{obj.name}: all light groups"
    material = material or _target_material(obj)
    if material is None:
        from ..bake.common import LightFadeBakeError

        raise LightFadeBakeError(f"Object '{obj.name}' has no material to judge the fade of")
    years = years_until_noticeable(scene, obj, material, horizon, settings=settings)
    return (years, colours.years_scale(years, horizon),
            f"{obj.name} / {material.name}: grey = no visible fade within {horizon:g} years")


def _image(name, rgba):
    h, w = rgba.shape[:2]
    image = bpy.data.images.get(name)
    if image is not None and tuple(image.size) != (w, h):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, w, h, alpha=True)
    image.pixels.foreach_set(np.ascontiguousarray(rgba, dtype=np.float32).ravel())
    image.update()
    return image


def _material(name, image, uv_map, tile=""):
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    uv = nodes.new("ShaderNodeUVMap")
    uv.uv_map = uv_map
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = "Closest"
    emit = nodes.new("ShaderNodeEmission")
    out = nodes.new("ShaderNodeOutputMaterial")
    vector = uv.outputs["UV"]
    if tile:                                 # an atlas: each instance reads its tile
        vector = tile_uv(Graph(mat.node_tree), Sock(None, vector, 0), tile).socket
    links.new(vector, tex.inputs["Vector"])
    links.new(tex.outputs["Color"], emit.inputs["Color"])
    links.new(emit.outputs["Emission"], out.inputs["Surface"])
    nodes.active = tex
    for i, node in enumerate((uv, tex, emit, out)):
        node.location = (300 * i, 0)
    mat.diffuse_color = (1.0, 1.0, 1.0, 1.0)
    return mat


def show_view(scene, obj, mode="DOSE", material=None, view_layer=None, settings=None):
    """Show ``obj`` in false colour (``"DOSE"``: annual dose, ``"YEARS"``: years until a
    just-noticeable fade); returns ``(view object, LogScale, note)``.  A view already
    shown for ``obj`` is replaced."""
    values, scale, note = view_values(scene, obj, mode, material, settings=settings)
    clear_view(scene, obj, view_layer)
    view_layer = view_layer or bpy.context.view_layer
    name = VIEW_PREFIX + obj.name
    image = _image(name, colours.false_colour(values, scale))
    mat = _material(name, image, obj.lightfade.uv_map, obj.lightfade.instance_tiles)
    view = obj.copy()
    view.name = name
    view[_OF] = obj.name
    view[_HIDDEN] = bool(obj.hide_get(view_layer=view_layer))
    view.lightfade.exposure_maps.clear()
    view.lightfade.uv_created = False
    view.lightfade_emitter.enabled = False
    view.hide_render = True
    view.parent = None
    view.matrix_world = obj.matrix_world.copy()
    scene.collection.objects.link(view)
    if obj.lightfade.instance_tiles:            # shown on the source: on every instance
        view.hide_viewport = True
        view[_SLOTS] = _swap_slots(obj, mat)
        return view, scale, note
    for slot in view.material_slots:
        slot.link = "OBJECT"
        slot.material = mat
    obj.hide_set(True, view_layer=view_layer)
    view.hide_set(False, view_layer=view_layer)
    return view, scale, note


def _swap_slots(obj, mat):
    """Show ``mat`` in every slot of ``obj`` (object-linked); returns what to put back:
    each slot's link and object-level material."""
    backup = []
    for slot in obj.material_slots:
        link = slot.link
        slot.link = "OBJECT"
        backup.append([link, slot.material.name if slot.material else ""])
        slot.material = mat
    return backup


def _restore_slots(obj, backup):
    for slot, (link, name) in zip(obj.material_slots, backup):
        slot.link = "OBJECT"
        slot.material = bpy.data.materials.get(name) if name else None
        slot.link = link


def clear_view(scene, obj=None, view_layer=None):
    """Remove the view of ``obj`` (default: every view) and show the objects as before.
    Returns how many views were removed."""
    view_layer = view_layer or bpy.context.view_layer
    removed = 0
    for view in view_objects(scene):
        of = scene.objects.get(view[_OF]) or bpy.data.objects.get(view[_OF])
        if obj is not None and of is not obj:
            continue
        if view.get(_SLOTS) is not None and of is not None:
            _restore_slots(of, [list(b) for b in view[_SLOTS]])
        hidden = bool(view.get(_HIDDEN, False))
        name = view.name
        bpy.data.objects.remove(view)
        for data in (bpy.data.materials, bpy.data.images):
            item = data.get(name)
            if item is not None and item.users == 0:
                data.remove(item)
        if of is not None and of.name in view_layer.objects:
            of.hide_set(hidden, view_layer=view_layer)
        removed += 1
    return removed
