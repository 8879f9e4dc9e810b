"""What drives a material's Base Color, and which albedo path it therefore takes.

The colour BSDF is found by walking the active Material Output's Surface input
upstream, through reroutes, Mix/Add Shader nodes and node groups (into the group's
active Group Output).  A Principled BSDF's ``Base Color`` or a Diffuse BSDF's ``Color``
is the socket LightFade ages.  Then :func:`material_plan` picks the albedo path:

``DIRECT``
    An Image Texture node straight into the socket (reroutes allowed) at the top level
    of the material, sampled with the object's exposure UV map, UVs inside the unit
    square, an sRGB or linear image: its pixels are read as they are, at full resolution.
``FLAT``
    A plain colour (the socket is not linked): a constant albedo.
``BAKED``
    Anything else — Mapping, procedurals, Mix and colour adjustments, attributes, a
    BSDF inside a node group, a different UV map: Cycles evaluates the socket into a
    float texture in the exposure UV map (:mod:`.albedo`).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..output import captured
from .bake.linked import is_local_copy
from .exposure import exposure_problem, exposure_uv
from .pixels import readable_colourspace

#: Colour BSDF node type -> the input LightFade ages.
COLOUR_SOCKETS = {"BSDF_PRINCIPLED": "Base Color", "BSDF_DIFFUSE": "Color"}
#: Largest image LightFade ages directly (texels); larger ones take the baked path.
MAX_DIRECT_TEXELS = 8192 * 8192


@dataclass(frozen=True)
class ColourSocket:
    """Where the aged colour goes: the socket ``socket`` of node ``node`` inside the
    tree reached through the group nodes named in ``groups`` (empty: the material's own
    tree).  Names, not pointers, so the same address works in a copy of the material."""

    groups: tuple
    node: str
    socket: str


@dataclass
class Plan:
    """The albedo path of one material on one object, and why (or what stops it)."""

    path: str = "BAKED"                 # DIRECT, BAKED or FLAT
    reason: str = ""
    problems: list = field(default_factory=list)
    colour: ColourSocket | None = None
    image: object = None                # bpy.types.Image on the direct path
    flat: tuple | None = None           # linear RGB on the flat path


def tree_at(tree, groups):
    """The node tree reached from ``tree`` through the group node names ``groups``."""
    for name in groups:
        tree = tree.nodes[name].node_tree
    return tree


def _upstream(socket):
    """The socket feeding ``socket`` through reroutes (None if unlinked)."""
    seen = 0
    while socket.is_linked and seen < 64:
        link = socket.links[0]
        if link.is_muted:
            return None
        node = link.from_node
        if node.type != "REROUTE":
            return link.from_socket
        socket = node.inputs[0]
        seen += 1
    return None


#: The Mix Shader of an aged copy's ray gate (:func:`.aging.copies.gate_rays`): its
#: second shader is the aged BSDF, its first a duplicate with the original colour.
GATE_MIX = "LightFade Ray Gate"
#: The Mix Shader of an aged copy's frame switch (:func:`.aging.frames.add_branch`): its
#: first shader is the live one, its second the BSDF fed by the frame image.
FRAME_MIX = "LightFade Frame Switch"


def _group_output(tree):
    outs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"]
    return next((n for n in outs if n.is_active_output), outs[0] if outs else None)


def colour_bsdfs(tree, groups=(), depth=0):
    """``[(groups, node)]``: the colour BSDFs whose closure reaches ``tree``'s output."""
    if depth == 0:
        out = tree.get_output_node("CYCLES") or tree.get_output_node("ALL")
        start = out.inputs["Surface"] if out is not None else None
    else:
        start = None
    return _walk(start, groups, depth) if start is not None else []


def _walk(socket, groups, depth):
    src = _upstream(socket)
    if src is None or depth > 16:
        return []
    node = src.node
    if node.mute:
        return []
    if node.type in COLOUR_SOCKETS:
        return [(groups, node)]
    if node.type == "MIX_SHADER" and node.name == GATE_MIX:
        return _walk(node.inputs[2], groups, depth)
    if node.type == "MIX_SHADER" and node.name == FRAME_MIX:
        return _walk(node.inputs[1], groups, depth)
    if node.type == "MIX_SHADER":
        return _walk(node.inputs[1], groups, depth) + _walk(node.inputs[2], groups, depth)
    if node.type == "ADD_SHADER":
        return _walk(node.inputs[0], groups, depth) + _walk(node.inputs[1], groups, depth)
    if node.type == "GROUP" and node.node_tree is not None:
        inner = _group_output(node.node_tree)
        sock = next((s for s in inner.inputs if s.identifier == src.identifier), None) \
            if inner is not None else None
        return _walk(sock, groups + (node.name,), depth + 1) if sock is not None else []
    return []


def find_colour_socket(material):
    """``(ColourSocket, problem)``: where Base Color is, or one line saying why not."""
    name = material.name
    if material.node_tree is None:
        return None, f"Material '{name}' has no node tree: enable Use Nodes"
    found = colour_bsdfs(material.node_tree)
    if not found:
        return None, (f"Material '{name}' has no Principled or Diffuse BSDF on its Material "
                      "Output: LightFade ages the Base Color of one of them")
    if len({(g, n.name) for g, n in found}) > 1:
        names = ", ".join(sorted({n.name for _g, n in found}))
        return None, (f"Material '{name}' mixes several colour BSDFs ({names}): LightFade ages "
                      "one Base Color; keep one colour BSDF on the output")
    groups, node = found[0]
    return ColourSocket(tuple(groups), node.name, COLOUR_SOCKETS[node.type]), None


def upstream_images(socket, limit=256):
    """Image Texture nodes anywhere upstream of ``socket`` (node groups included)."""
    found, stack, seen = [], [socket], set()
    while stack and len(seen) < limit:
        sock = stack.pop()
        for link in sock.links:
            node = link.from_node
            if node.as_pointer() in seen:
                continue
            seen.add(node.as_pointer())
            if node.type == "TEX_IMAGE" and node.image is not None:
                found.append(node)
            if node.type == "GROUP" and node.node_tree is not None:
                found += [n for n in node.node_tree.nodes if n.type == "TEX_IMAGE" and n.image]
            stack.extend(s for s in node.inputs if s.is_linked)
    return found


def image_problem(material, image):
    """One line if ``image`` has no pixels Cycles or LightFade could read, else None.

    What the image libraries print about a damaged file ("libpng error: IDAT: Read
    error: hit end of file in png reader") is said in that line, not before it.
    """
    if image.source in ("FILE", "SEQUENCE", "TILED") and image.packed_file is None:
        if image.source == "TILED":
            return None
        loaded, said = _load(image)
        if loaded:
            return None
        path = image.filepath_from_user()
        if os.path.isfile(path):
            why = f" ({said})" if said else ""
            return (f"Image '{image.name}' of material '{material.name}' cannot be read from "
                    f"{path}{why}: save it again, or relink it (File > External Data > "
                    "Find Missing Files)")
        return (f"Image '{image.name}' of material '{material.name}' has no pixels: the file "
                "is missing? Relink it (File > External Data > Find Missing Files) or pack it")
    return None


#: Blender's log prefix on a library's complaint: "00:00.507  image.read  | ERROR ".
_LOG_PREFIX = re.compile(r"^(\d+:\d+\.\d+\s+\S+\s+)?\|?\s*(ERROR\s+)?")


def _load(image):
    """``(has pixels, the first line the libraries printed while loading it)``; what they
    print is kept off the terminal when the load fails and written out when it works."""
    if image.has_data:
        return True, ""
    with captured((2, 1)) as said:      # stderr first: where the libraries complain
        try:
            image.pixels[0]
        except Exception:  # noqa: BLE001 (Blender raises various errors for missing files)
            pass
        loaded = bool(image.has_data)
    if loaded:
        said.replay()
    lines = [_LOG_PREFIX.sub("", x).strip() for x in said.all_lines()]
    return loaded, next((x for x in lines if x), "")


def _uv_name(obj, node):
    """The UV map an image node samples with ('' for a projection LightFade cannot follow)."""
    vector = node.inputs["Vector"]
    uv = obj.data.uv_layers
    render = next((layer.name for layer in uv if layer.active_render), uv[0].name if uv else "")
    if not vector.is_linked:
        return render
    src = _upstream(vector)
    if src is None or src.node.type != "UVMAP":
        return ""
    return src.node.uv_map or render


def _uvs_in_unit_square(mesh, uv_name):
    layer = mesh.uv_layers.get(uv_name)
    if layer is None or len(layer.uv) == 0:
        return False
    uv = np.empty(len(layer.uv) * 2, dtype=np.float32)
    layer.uv.foreach_get("vector", uv)
    return bool(uv.min() >= -1e-4 and uv.max() <= 1 + 1e-4)


def _direct_refusal(obj, node, image):
    """Why an image straight into Base Color cannot be read directly, or None."""
    if image.source not in ("FILE", "GENERATED"):
        return f"image '{image.name}' is a {image.source.lower()}"
    if node.projection != "FLAT":
        return f"image node '{node.name}' uses {node.projection.lower()} projection"
    if not readable_colourspace(image):
        return f"image '{image.name}' is in colour space '{image.colorspace_settings.name}'"
    if image.size[0] * image.size[1] > MAX_DIRECT_TEXELS:
        return f"image '{image.name}' is larger than 8192²"
    uv = _uv_name(obj, node)
    exposure = exposure_uv(obj)
    if not uv:
        src = _upstream(node.inputs["Vector"])
        what = src.node.bl_label if src is not None else "a muted link"
        return f"its coordinates come from {what}"
    if uv != exposure:
        return f"it samples UV map '{uv}', the exposure is in '{exposure}'"
    if not _uvs_in_unit_square(obj.data, uv):
        return f"UV map '{uv}' leaves the 0–1 square (the image repeats)"
    return None


def material_plan(scene, obj, material, need_exposure=True):
    """The :class:`Plan` of ``material`` on ``obj``: albedo path, reason and problems.

    Runs no Cycles work; every problem found is listed (object, material, what to do).
    With ``need_exposure=False`` (before a bake) a missing exposure is not a problem.
    """
    plan = Plan()
    if obj.type != "MESH":
        plan.problems.append(f"Object '{obj.name}' is a {obj.type.lower()}: LightFade ages "
                             "meshes (convert it: Object > Convert > Mesh)")
        return plan
    copy = is_local_copy(obj)           # Age Linked Instances: mesh and material only read
    if obj.library is not None or (obj.data.library is not None and not copy):
        plan.problems.append(f"Object '{obj.name}' is linked from a library: make it local "
                             "first (Object > Relations > Make Local)")
    if material.library is not None and not copy:
        plan.problems.append(f"Material '{material.name}' is linked from a library: make it "
                             "local first (Object > Relations > Make Local)")
    missing = exposure_problem(scene, obj)
    if missing and need_exposure:
        plan.problems.append(missing)
    colour, problem = find_colour_socket(material)
    if problem:
        plan.problems.append(problem)
        return plan
    plan.colour = colour
    tree = tree_at(material.node_tree, colour.groups)
    socket = tree.nodes[colour.node].inputs[colour.socket]
    for image_node in upstream_images(socket):
        problem = image_problem(material, image_node.image)
        if problem and problem not in plan.problems:
            plan.problems.append(problem)
    src = _upstream(socket)
    if src is None:
        plan.path = "FLAT"
        plan.flat = tuple(socket.default_value[:3])
        plan.reason = "a plain colour"
        return plan
    node = src.node
    if colour.groups:
        plan.reason = f"Base Color is inside node group '{colour.groups[-1]}': baked with Cycles"
    elif node.type == "TEX_IMAGE" and node.image is not None and src.name == "Color":
        refusal = None if missing else _direct_refusal(obj, node, node.image)
        if refusal is None and not missing:
            plan.path = "DIRECT"
            plan.image = node.image
            w, h = node.image.size
            plan.reason = f"image '{node.image.name}' straight into Base Color ({w}×{h}, full resolution)"
            return plan
        plan.reason = f"{refusal or 'no exposure UV map yet'}: baked with Cycles"
    else:
        plan.reason = f"Base Color comes from {node.bl_label} '{node.name}': baked with Cycles"
    return plan
