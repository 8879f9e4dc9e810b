"""Years in the material, and real aged images when they are wanted.

Years reach every aged copy through the scene's custom property (:mod:`.years`):
setting them costs no Python work per material, and nothing is ever prepared for
them (the colour table's dose axis is absolute and saturates). This module says when a
copy no longer matches its inputs and writes real aged pixels on request:

* :func:`update_scene` — the years for the whole scene (``api.set_years``): one
  property write; stale copies are named in one line each, with what refreshes them
  (Age), as the panel says;
* :func:`apply_aging` — real aged images through the numpy evaluator, wired into the
  copies in place of the node group (export, other engines, painting);
  :func:`live_aging` puts the groups back.
"""

from __future__ import annotations

import time

import bpy
import numpy as np

from . import parts, runtime
from ..albedo import albedo_image, bake_albedos
from ..bake.emitters import remembered
from .copies import APPLIED_NAME, GROUP_NODE, copies_of, walk
from ..errors import AgingError, check_years
from ..exposure import exposure_shape, exposure_signature, exposure_uv, scene_objects
from .instances import INSTANCES_STALE, apply_problem, instances_stale
from ..pixels import write_rgba
from ..source import find_colour_socket
from .years import get_years, write_years
from ...core.colour.srgb8 import srgb_code_floats
from .group import GROUP_VERSION
from ..parts.properties import parts_digest

#: Prefix of the images :func:`apply_aging` writes.
APPLIED_PREFIX = "LF_Applied_"
GROUP_PREFIX = "LF_Aging_"


def aged_copies(scene):
    """Aged copies whose object is in ``scene`` (or is aged through instances in it)."""
    objects = scene_objects(scene)
    return [c for c in copies_of() if c.lightfade.aged_object in objects]


#: What refreshes a stale copy, said the same way everywhere (panel, info, set_years).
REFRESH = "press Age"


def stale_reason(scene, copy):
    """Why ``copy`` no longer matches its inputs ('' when up to date)."""
    props = copy.lightfade
    if runtime.group_version(copy) != GROUP_VERSION:
        return "its aging node group is from an older LightFade"
    if props.source is not None and props.parts_key != parts_digest(props.source.lightfade):
        return "the material's parts changed since Age"
    if props.signature != runtime.signature(scene, copy):
        return "exposure maps, schedule or recipe changed since Age"
    moved = instances_stale(scene, props.aged_object)
    if moved:
        return moved
    if props.aged_image is not None and props.aged_image.get(_APPLIED_SIGNATURE) != \
            exposure_signature(scene, props.aged_object):
        return "applied images predate the last exposure bake"
    return ""


def stale_message(scene, copy):
    """``"stale: <why>: <what refreshes it>"`` or ''."""
    why = stale_reason(scene, copy)
    if not why:
        return ""
    if why.startswith("applied"):
        return f"stale: {why}: press Apply Aging"
    if why.startswith(INSTANCES_STALE):
        return f"stale: {why}: bake exposure again"
    return f"stale: {why}: {REFRESH}"


def needs_age(scene, copy):
    """Why a stale copy needs the Age button: every stale copy does (kept for callers)."""
    return REFRESH if stale_reason(scene, copy) else ""


def find_nodes(tree, name):
    """Nodes called ``name`` in ``tree`` and the group trees inside it: [(tree, node)]."""
    return [(t, n) for t, n in walk(tree) if n.name == name]


def _user_image_node(copy):
    """The user's Image Texture node of the direct path (None on the other paths)."""
    props = copy.lightfade
    if props.path == "DIRECT" and props.albedo is not None:
        return next((n for _t, n in walk(copy.node_tree)
                     if n.type == "TEX_IMAGE" and n.image == props.albedo), None)
    return None


def _extension(copy):
    """The wrap mode of the user's image on the direct path (applied images follow it)."""
    node = _user_image_node(copy)
    if node is not None and node.extension in ("REPEAT", "EXTEND", "MIRROR"):
        return node.extension
    return "EXTEND"


def sampling(copy):
    """``(interpolation, extension)`` aged images of ``copy`` are read with: the user's
    image's on the direct path, else Linear and Extend."""
    user = _user_image_node(copy)
    return (user.interpolation if user is not None else "Linear"), _extension(copy)


def update_scene(scene, years=None, report=print):
    """Show ``years`` (default: the scene's) on every aged copy; seconds taken.

    Setting the years is one custom-property write and prepares nothing. Each stale
    copy is named in one line with what refreshes it (as the panel says).
    """
    t0 = time.perf_counter()
    years = check_years(get_years(scene) if years is None else years)
    with remembered(scene):
        for copy in aged_copies(scene):
            message = stale_message(scene, copy)
            if message:
                props = copy.lightfade
                report(f"LightFade: '{props.source.name}' on '{props.aged_object.name}' is "
                       f"{message}")
    write_years(scene, years)
    return time.perf_counter() - t0


#: Custom property of an applied image: the exposure signature it was computed from.
_APPLIED_SIGNATURE = "lightfade_exposure"


def _view_layer(scene):
    context = bpy.context
    return context.view_layer if context.scene == scene else scene.view_layers[0]


def ensure_albedo(scene, copy):
    """The copy's Base Color as a float image in its exposure UV map (baked path): baked
    by Cycles with the aging group muted, at the exposure maps' size, when not at hand."""
    props = copy.lightfade
    obj = props.aged_object
    shape = exposure_shape(obj)
    if props.albedo is not None and tuple(props.albedo.size)[::-1] == shape:
        return props.albedo
    colour, problem = find_colour_socket(copy)
    if problem:
        raise AgingError(problem)
    props.albedo = albedo_image(copy, shape)
    muted = [(n, n.mute) for _t, n in walk(copy.node_tree) if n.name == GROUP_NODE]
    try:
        for node, _was in muted:            # a muted group passes the artist's colour on
            node.mute = True
        bake_albedos(scene, _view_layer(scene), obj, [(copy, colour, props.albedo)],
                     exposure_uv(obj), scene.lightfade.bake_margin)
    finally:
        for node, was in muted:
            node.mute = was
    return props.albedo


def original_pixels(scene, copy):
    """(H, W, 4) linear colour the copy ages, at its texture's resolution."""
    props = copy.lightfade
    if props.path == "BAKED":
        ensure_albedo(scene, copy)
    return runtime.original_rgba(copy, exposure_shape(props.aged_object) or (64, 64))


def aged_pixels(scene, copy, years):
    """(H, W, 4) float32 linear aged colour of ``copy`` (the numpy evaluator): its colour
    at each texel centre lit by the exposure maps sampled there, as the group does."""
    if len(copy.lightfade.lanes):                    # several recipes by mask
        original = original_pixels(scene, copy)
        return parts.aged_pixels(scene, _view_layer(scene), copy, original, years)
    if copy.lightfade.path == "BAKED":
        ensure_albedo(scene, copy)
    original, key = runtime.held_colour(scene, copy)   # read only when it changed
    out = np.empty_like(original)
    out[..., 3] = original[..., 3]
    return runtime.aged_rgb(scene, copy, original, years, key=key, out=out)


def apply_copy(scene, copy, years):
    """Write ``copy``'s aged pixels at ``years`` into its applied image and wire it."""
    props = copy.lightfade
    rgba = aged_pixels(scene, copy, years)
    H, W = rgba.shape[:2]
    image = props.aged_image
    if image is None or tuple(image.size) != (W, H):
        if image is not None:
            bpy.data.images.remove(image)
        image = bpy.data.images.new(APPLIED_PREFIX + copy.name, W, H, alpha=True,
                                    float_buffer=True)
        image.colorspace_settings.name = "Linear Rec.709"
        props.aged_image = image
    write_rgba(image, rgba)
    image["lightfade_years"] = float(years)
    image[_APPLIED_SIGNATURE] = exposure_signature(scene, props.aged_object)
    for tree, node in find_nodes(copy.node_tree, GROUP_NODE):
        socket = node.outputs[0].links[0].to_socket if node.outputs[0].links else None
        if socket is None:
            continue
        applied = tree.nodes.get(APPLIED_NAME)
        if applied is None:
            applied = tree.nodes.new("ShaderNodeTexImage")
            applied.name = applied.label = APPLIED_NAME
            applied.location = (node.location.x, node.location.y + 260)
            uv = tree.nodes.new("ShaderNodeUVMap")
            uv.name = uv.label = APPLIED_NAME + " UV"
            uv.location = (applied.location.x - 220, applied.location.y)
            tree.links.new(uv.outputs["UV"], applied.inputs["Vector"])
        tree.nodes[APPLIED_NAME + " UV"].uv_map = props.uv_map
        applied.image = image
        applied.interpolation, applied.extension = sampling(copy)   # as the user's image
        tree.links.new(applied.outputs["Color"], socket)
    return image


def write_aged_file(scene, copy, years, path):
    """Write ``copy``'s aged pixels at ``years`` as an image file: ``.png`` (8-bit sRGB)
    or ``.exr`` (float, linear Rec.709), through Blender's own image writer."""
    problem = apply_problem(copy)
    if problem is not None:
        raise AgingError(problem)
    rgba = aged_pixels(scene, copy, years)
    H, W = rgba.shape[:2]
    exr = path.lower().endswith(".exr")
    image = bpy.data.images.new("LF_Export", W, H, alpha=True, float_buffer=exr)
    try:
        if exr:
            image.colorspace_settings.name = "Linear Rec.709"
            image.file_format = "OPEN_EXR"
        else:
            rgba = rgba.copy()                      # each 8-bit code through a table
            rgba[..., :3] = srgb_code_floats(rgba[..., :3])
            image.colorspace_settings.name = "sRGB"
            image.file_format = "PNG"
        write_rgba(image, rgba)
        image.filepath_raw = path
        image.save()
    finally:
        bpy.data.images.remove(image)
    return path


def apply_aging(scene, years=None):
    """Real aged images for every aged copy of ``scene``, wired in: {copy name: image}.

    Through the numpy evaluator of the copy's own aging table (the one its node group
    reads). ``years`` defaults to the scene's. :func:`live_aging` undoes the wiring.
    """
    years = check_years(get_years(scene) if years is None else years)
    update_scene(scene, years)
    out = {}
    for copy in aged_copies(scene):
        problem = apply_problem(copy)        # instances: one line, the live aging stays
        if problem is not None:
            print(f"LightFade: {problem}")
            continue
        out[copy.name] = apply_copy(scene, copy, years)
    return out


def live_aging(scene):
    """The aging node groups back in place of applied images (which are removed)."""
    n = 0
    for copy in aged_copies(scene):
        props = copy.lightfade
        for tree, node in find_nodes(copy.node_tree, GROUP_NODE):
            applied = tree.nodes.get(APPLIED_NAME)
            if applied is not None:
                for link in list(applied.outputs["Color"].links):
                    tree.links.new(node.outputs[0], link.to_socket)
                tree.nodes.remove(applied)
                tree.nodes.remove(tree.nodes[APPLIED_NAME + " UV"])
        if props.aged_image is not None:
            bpy.data.images.remove(props.aged_image)
            props.aged_image = None
            n += 1
    return n
