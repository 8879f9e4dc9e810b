"""Years in the material, and real aged images when they are wanted.

Years reach every aged copy through the scene's custom property (:mod:`.years`):
setting them costs no Python work per material. This module keeps the copies up to
date with their inputs and writes real aged pixels on request:

* :func:`update_scene` — the years for the whole scene (``api.set_years``): stale
  copies (a new bake, a changed recipe or schedule) and copies whose prepared range
  the years pass are prepared again first (:func:`refresh`), each said in one line;
* :func:`apply_aging` — real aged images through the numpy evaluator, wired into the
  copies in place of the node group (export, other engines, painting);
  :func:`live_aging` puts the groups back.
"""

from __future__ import annotations

import time

import bpy
import numpy as np

from . import agingdata, parts, runtime
from .copies import APPLIED_NAME, GROUP_NODE, TREE_TAG, copies_of, walk
from .errors import AgingError, check_years
from .exposure import exposure_shape, exposure_uv
from .grids import purge
from .nodes.aging import new_group
from .part_properties import parts_digest
from .pixels import write_rgba
from .years import get_years, write_years
from ..core.colorimetry import srgb_encode
from ..core.table import evaluate

#: Prefix of the images :func:`apply_aging` writes.
APPLIED_PREFIX = "LF_Applied_"
GROUP_PREFIX = "LF_Aging_"


def aged_copies(scene):
    """Aged copies whose object is in ``scene``."""
    objects = set(scene.objects)
    return [c for c in copies_of() if c.lightfade.aged_object in objects]


def stale_reason(scene, copy):
    """Why ``copy`` no longer matches its inputs ('' when up to date)."""
    props = copy.lightfade
    if props.signature != runtime.signature(scene, copy):
        return "exposure, schedule or recipe changed since Age"
    return ""


def needs_age(scene, copy):
    """Why a stale copy needs the Age button (a new Cycles albedo bake), or ''."""
    props = copy.lightfade
    obj = props.aged_object
    if props.source is not None and props.parts_key != parts_digest(props.source.lightfade):
        return "the material's parts changed since Age: press Age"
    if props.path == "BAKED" and props.albedo is not None and obj is not None:
        shape = exposure_shape(obj)
        if shape != tuple(props.albedo.size)[::-1] or exposure_uv(obj) != props.uv_map:
            return "the exposure was baked at another size or UV map: press Age"
    return ""


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
    """The wrap mode of the user's image on the direct path (keys follow it)."""
    node = _user_image_node(copy)
    if node is not None and node.extension in ("REPEAT", "EXTEND", "MIRROR"):
        return node.extension
    return "EXTEND"


def build_group(copy, lane=None):
    """A new aging node group for the copy's current images (or one lane's, :mod:`.parts`)."""
    name = GROUP_PREFIX + copy.name + ("" if lane is None else f"~{lane.name}")
    group = new_group(name, agingdata.group_spec(copy, _extension(copy), lane))
    group[TREE_TAG] = True
    return group


def refresh(scene, copy, max_years=None):
    """Prepare ``copy`` again from the file's data and put the new group in place."""
    props = copy.lightfade
    blocked = needs_age(scene, copy)
    if blocked:
        raise AgingError(f"Material '{props.source.name}' on '{props.aged_object.name}' is "
                         f"stale: {blocked}")
    if max_years is not None:
        props.max_years = max_years
    obj = props.aged_object
    if len(props.lanes):                             # several recipes by mask
        parts.prepare_lanes(scene, copy, exposure_shape(obj) or (64, 64))
        props.signature = runtime.signature(scene, copy)
        parts.wire(copy, parts.colour_socket(copy), [build_group(copy, lane)
                                                    for lane in props.lanes])
        if props.aged_image is not None:
            apply_copy(copy, get_years(scene))
        return
    runtime.prepare(scene, copy, exposure_shape(obj) or (64, 64))
    props.signature = runtime.signature(scene, copy)
    group = build_group(copy)
    for _tree, node in find_nodes(copy.node_tree, GROUP_NODE):
        old = node.node_tree
        node.node_tree = group
        if old is not None and old != group and old.users == 0:
            bpy.data.node_groups.remove(old)
    if props.aged_image is not None:                 # applied pixels are now out of date
        apply_copy(copy, get_years(scene))


def update_scene(scene, years=None, report=print):
    """Show ``years`` (default: the scene's) on every aged copy; seconds taken.

    Setting the years is one custom-property write. A stale copy, or one whose
    prepared range ``years`` passes, is prepared again first (and said so); one that
    needs Age is left as it was and reported in one line.
    """
    t0 = time.perf_counter()
    years = check_years(get_years(scene) if years is None else years)
    refreshed = False
    for copy in aged_copies(scene):
        props = copy.lightfade
        stale = props.signature != runtime.signature(scene, copy)
        short = years > props.max_years
        if not (stale or short):
            continue
        try:
            if short:
                report(f"LightFade: '{props.source.name}' on '{props.aged_object.name}' was "
                       f"prepared for {props.max_years:g} years: preparing "
                       f"{runtime.prepared_range(years):g}")
            refresh(scene, copy, runtime.prepared_range(years) if short else None)
        except AgingError as err:
            report(f"LightFade: {err}")
        else:
            refreshed = True
    if refreshed:
        purge(scene, parts.grids_in_use())
    write_years(scene, years)
    return time.perf_counter() - t0


def aged_pixels(copy, years):
    """(H, W, 4) float32 linear aged colour of ``copy`` (the numpy evaluator)."""
    if len(copy.lightfade.lanes):
        return parts.aged_pixels(copy, years)
    table, texels, positions, original = runtime.evaluator(copy)
    H, W = agingdata.key_shape(copy)
    rgba = original.reshape(H * W, 4).copy()          # zero years: the original itself
    if years > 0:
        evaluate(table, texels, years, positions, out=rgba)
    return rgba.reshape(H, W, 4)


def apply_copy(copy, years):
    """Write ``copy``'s aged pixels at ``years`` into its applied image and wire it."""
    props = copy.lightfade
    H, W = parts.key_shape(copy) if len(props.lanes) else agingdata.key_shape(copy)
    image = props.aged_image
    if image is None or tuple(image.size) != (W, H):
        if image is not None:
            bpy.data.images.remove(image)
        image = bpy.data.images.new(APPLIED_PREFIX + copy.name, W, H, alpha=True,
                                    float_buffer=True)
        image.colorspace_settings.name = "Linear Rec.709"
        props.aged_image = image
    write_rgba(image, aged_pixels(copy, years))
    image["lightfade_years"] = float(years)
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
        user = _user_image_node(copy)                # sampled as the user's image is
        applied.interpolation = user.interpolation if user is not None else "Linear"
        applied.extension = _extension(copy)
        tree.links.new(applied.outputs["Color"], socket)
    return image


def write_aged_file(copy, years, path):
    """Write ``copy``'s aged pixels at ``years`` as an image file: ``.png`` (8-bit sRGB)
    or ``.exr`` (float, linear Rec.709), through Blender's own image writer."""
    rgba = aged_pixels(copy, years)
    H, W = rgba.shape[:2]
    exr = path.lower().endswith(".exr")
    image = bpy.data.images.new("LF_Export", W, H, alpha=True, float_buffer=exr)
    try:
        if exr:
            image.colorspace_settings.name = "Linear Rec.709"
            image.file_format = "OPEN_EXR"
        else:
            rgba = rgba.copy()
            rgba[..., :3] = srgb_encode(np.clip(rgba[..., :3], 0.0, 1.0))
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
    return {copy.name: apply_copy(copy, years) for copy in aged_copies(scene)}


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
