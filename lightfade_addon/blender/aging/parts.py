"""Several recipes in one material, by mask: each part ages as its own recipe would.

The artist lists parts in ``Material.lightfade.parts`` (:mod:`..parts.properties`): a
recipe (or *Does Not Age*) and a mask each, plus what the rest of the material does.
An aged copy with parts then evaluates the aging **once per recipe in use** (a *lane*:
parts with the same recipe and sensitivity share one) and mixes the results by the
masks. Per shading point, with ``m_p`` each part's mask clamped to [0, 1] (values
within 1/1024 of 0 or 1 taken as 0 or 1: filtering never leaks a trace) and
``S = Σ m_p``:

    w_p = m_p / max(S, 1)             (overlaps share; the weights never pass 1)
    w_rest = 1 - S / max(S, 1)        (what no part claims)
    W_k = Σ of w over the parts (and the rest) aging with lane k
    out = C + Σ_k W_k · (A_k - C)

``C`` is the artist's colour and ``A_k`` lane k's aging group's output. The weights of
all parts and the rest sum to one; where every aging weight is 0 (a part that does not
age) ``out`` is ``C`` exactly, at every years, and at 0 years every ``A_k`` is ``C``
(the group passes the colour through; a material with a history, *Already Aged*, shows
its aging parts restored to new), so the whole material is its original.

**The seam.** :func:`wire` takes one aging node group per lane — any group with a
Color input and a Color output that ages the colour with that lane's recipe — and
builds the mix around them; it knows nothing of how a group evaluates the aging.
:func:`prepare` gives each lane the shared aging group of its recipe
(:func:`.runtime.aging_group`: the colour table of that recipe under the object's light
spectra, shared by every material using it, read at the artist's colour and the
exposure maps), so a lane has no images of its own. The numpy twin
(:func:`aged_pixels`, Apply to Images and exported aged files) evaluates each lane's
table (:func:`.runtime.evaluator`) and mixes them with the same weights, baked by Cycles
when first needed (:func:`ensure_weights`: any mask, image, attribute or node output,
evaluated as the renderer does) at the texture's resolution.
"""

from __future__ import annotations

import bpy
import numpy as np

from . import data as agingdata, runtime
from ..albedo import bake_albedos
from .copies import GROUP_NODE, TREE_TAG, insert_group, walk
from ..errors import AgingError
from ..exposure import exposure_uv
from .group import GROUP_VERSION, VERSION_KEY
from .mix import PER_IMAGE, mix_group
from ..parts.properties import KEEP, part_recipe_key, parts_digest
from ..pixels import read_rgba
from ..source import ColourSocket, find_colour_socket, image_problem, tree_at

#: Prefix of the mixing group (one per copy with parts) and of the baked weights.
MIX_PREFIX = "LF_Parts_"
WEIGHTS_PREFIX = "LF_Weights_"
#: The node a weights bake reads (a reroute fed by the mixing group's weights).
WEIGHTS_NODE = "LightFade Part Weights"
#: Socket types a node-output mask may have: one value, or a colour/vector with channels.
_VALUE_SOCKETS = {"VALUE", "INT", "BOOLEAN"}
_CHANNEL_SOCKETS = {"RGBA": "NodeSocketColor", "VECTOR": "NodeSocketVector"}


# --------------------------------------------------------------------------- the data


def has_parts(material):
    return len(material.lightfade.parts) > 0


def recipes_in_use(material):
    """``[(key, settings)]``: each recipe that ages in ``material``, once (the rest's
    first when it ages, then the parts' in order); ``settings`` carries ``recipe``,
    ``sensitivity_mode``, ``blue_wool`` and ``beta``."""
    props = material.lightfade
    found = {}
    if props.rest != KEEP:
        found[part_recipe_key(props)] = props
    for part in props.parts:
        if part.recipe != KEEP:
            found.setdefault(part_recipe_key(part), part)
    return list(found.items())


def lane_indices(material):
    """``(per part: its lane index or None, the rest's lane index or None)``."""
    keys = [key for key, _s in recipes_in_use(material)]
    props = material.lightfade
    parts = [keys.index(part_recipe_key(p)) if p.recipe != KEEP else None for p in props.parts]
    rest = keys.index(part_recipe_key(props)) if props.rest != KEEP else None
    return parts, rest


def _said(settings):
    """``bare-wood, Blue Wool 2`` (as ``info`` says a material's recipe)."""
    sensitivity = (f"beta {settings.beta:g}e-6" if settings.sensitivity_mode == "BETA"
                   else f"Blue Wool {settings.blue_wool}")
    return f"{settings.recipe.lower().replace('_', '-')}, {sensitivity}"


def describe(material):
    """``[(name, recipe, mask)]`` of each part and the rest, for reports."""
    rows = []
    for part in material.lightfade.parts:
        source = {"IMAGE": f"image '{part.image.name if part.image else ''}'"
                           + (f" (UV '{part.uv_map}')" if part.uv_map else ""),
                  "ATTRIBUTE": f"attribute '{part.attribute}'",
                  "SOCKET": f"node '{part.node}' output '{part.socket or '(first)'}'"}
        rows.append((part.name, "does not age" if part.recipe == KEEP else _said(part),
                     f"{source[part.mask]}, channel {part.channel}"))
    props = material.lightfade
    rows.append(("(rest)", "does not age" if props.rest == KEEP else _said(props),
                 "what no part claims"))
    return rows


# --------------------------------------------------------------------------- checks


def _mask_output(tree, part):
    """The output socket a node-output mask names, or None."""
    node = tree.nodes.get(part.node)
    if node is None:
        return None
    if not part.socket:
        return next((s for s in node.outputs if s.enabled), None)
    return next((s for s in node.outputs if s.name == part.socket and s.enabled), None)


def _part_problem(obj, material, tree, part):
    where = f"Material '{material.name}', part '{part.name}'"
    if part.mask == "IMAGE":
        if part.image is None:
            return f"{where}: no mask image: pick one (Material Properties > LightFade > Parts)"
        layers = [layer.name for layer in obj.data.uv_layers]
        if part.uv_map and part.uv_map not in layers:
            return (f"{where}: UV map '{part.uv_map}' is not on mesh '{obj.data.name}' (it has "
                    f"{', '.join(layers) or 'none'}): pick one, or leave it empty")
        return image_problem(material, part.image)
    if part.mask == "ATTRIBUTE":
        names = [a.name for a in obj.data.attributes if not a.name.startswith(".")]
        if part.attribute not in names:
            return (f"{where}: attribute '{part.attribute}' is not on mesh '{obj.data.name}' "
                    f"(it has {', '.join(names)}): paint it or fix the name")
        return None
    node = tree.nodes.get(part.node)
    if node is None:
        return (f"{where}: no node named '{part.node}' in the node tree of its colour BSDF: "
                "give the mask node that name (Node Editor > N > Node > Name)")
    socket = _mask_output(tree, part)
    if socket is None:
        outputs = ", ".join(s.name for s in node.outputs if s.enabled)
        return f"{where}: node '{part.node}' has no output '{part.socket}' (it has {outputs})"
    if socket.type not in _VALUE_SOCKETS and socket.type not in _CHANNEL_SOCKETS:
        return (f"{where}: output '{socket.name}' of node '{part.node}' is a "
                f"{socket.type.lower()}: pick a colour or value output")
    if part.channel == "A":
        return (f"{where}: a node output has no alpha channel: pick channel R, G or B")
    return None


def part_problems(obj, material, colour):
    """Every problem of ``material``'s parts on ``obj`` (one line each; [] without parts)."""
    if not has_parts(material):
        return []
    problems = []
    if not recipes_in_use(material):
        problems.append(f"Material '{material.name}': no part ages (every part and the rest "
                        "are 'Does Not Age'): give one a recipe, or untick Age this Material")
    tree = tree_at(material.node_tree, colour.groups)
    for part in material.lightfade.parts:
        problem = _part_problem(obj, material, tree, part)
        if problem and problem not in problems:
            problems.append(problem)
    return problems


# --------------------------------------------------------------------------- preparing


def colour_socket(copy):
    """The copy's :class:`.source.ColourSocket` (found again, as for its source)."""
    colour, problem = find_colour_socket(copy)
    if problem:
        raise AgingError(problem)
    return colour


def make_lanes(copy):
    """One lane per recipe in use of the copy's source (its parts as they are now)."""
    props = copy.lightfade
    remove(copy)
    for k, (_key, settings) in enumerate(recipes_in_use(props.source)):
        lane = props.lanes.add()
        lane.name = str(k)
        lane.recipe = settings.recipe
        lane.sensitivity_mode = settings.sensitivity_mode
        lane.blue_wool = settings.blue_wool
        lane.beta = settings.beta
        lane.fastness = getattr(settings, "fastness", "")       # a part has none
    props.parts_key = parts_digest(props.source.lightfade)


def prepare(scene, copy, colour, progress=None):
    """Age ``copy``'s colour socket by its parts: one lane per recipe in use, each the
    shared aging group of its recipe (:func:`.runtime.aging_group`, with the material's
    history), mixed by the masks (:func:`wire`); returns the mixing group node."""
    props = copy.lightfade
    obj, source = props.aged_object, props.source
    if obj is None or source is None:
        raise AgingError(f"Aged material '{copy.name}' lost its object or source: press Reset")
    make_lanes(copy)
    prior = runtime.material_prior(source)
    lanes, groups = list(props.lanes), []
    for k, lane in enumerate(lanes):
        def step(f, msg, k=k, lane=lane):
            if progress is not None:
                progress((k + f) / len(lanes), f"{lane.recipe.lower()}: {msg}")
        group, image, table = runtime.aging_group(
            scene, obj, runtime.settings_recipe(lane), prior,
            f"{runtime.GROUP_PREFIX}{copy.name}~{lane.name}", step)
        lane.table_image = image
        if table is not None or prior is not None:
            lane.lost_texels = runtime.lost_texels(copy, table or agingdata.read_table(image))
        groups.append(group)
    props.table_image = None                         # the lanes hold the tables
    props.lost_texels = sum(lane.lost_texels for lane in lanes)
    node = wire(copy, colour, groups)
    props.signature = runtime.signature(scene, copy)
    runtime.forget(copy)
    return node


def remove(copy):
    """Remove the copy's lanes: their weights and aging groups, unless a copy of the copy
    shares them (the shared tables stay while some copy reads them,
    :func:`.agingdata.purge_tables`)."""
    props = copy.lightfade
    others = [m for m in bpy.data.materials if m != copy and len(m.lightfade.lanes)]
    kept = {lane.weight_image for m in others for lane in m.lightfade.lanes}
    kept.update(tree for m in others for tree in _lane_groups(m))
    weights = {lane.weight_image for lane in props.lanes if lane.weight_image is not None}
    for image in weights - kept:
        bpy.data.images.remove(image)
    for tree in set(_lane_groups(copy)) - kept:
        bpy.data.node_groups.remove(tree)
    props.lanes.clear()


def _mix_node(copy):
    node = next((n for _t, n in walk(copy.node_tree) if n.name == GROUP_NODE), None)
    return node if node is not None and node.type == "GROUP" else None


def _lane_groups(copy):
    node = _mix_node(copy)
    if node is None or node.node_tree is None or not node.node_tree.name.startswith(MIX_PREFIX):
        return []
    return [n.node_tree for n in node.node_tree.nodes
            if n.type == "GROUP" and n.node_tree is not None and n.node_tree.get(TREE_TAG)]


# --------------------------------------------------------------------------- the mix


def wire(copy, colour, groups):
    """Age ``copy``'s colour by its parts; ``groups``: one aging node group per lane
    (``copy.lightfade.lanes`` order), each Color in → Color out.

    The mixing group goes between the artist's Base Color graph and the BSDF as the node
    ``GROUP_NODE`` (so Apply to Images, Live Aging and Reset treat it as any aging
    group); node-output masks are linked into it. Idempotent: a second call replaces
    the mix and the lane groups it held.
    """
    source = copy.lightfade.source
    tree = tree_at(copy.node_tree, colour.groups)
    outputs, kinds = {}, {}
    for i, part in enumerate(source.lightfade.parts):
        if part.mask == "SOCKET":
            socket = _mask_output(tree, part)
            outputs[i] = socket
            kinds[i] = "NodeSocketFloat" if socket.type in _VALUE_SOCKETS \
                else _CHANNEL_SOCKETS[socket.type]
    old = _lane_groups(copy)
    part_lane, rest_lane = lane_indices(source)
    mix = mix_group(MIX_PREFIX + copy.name, list(source.lightfade.parts), part_lane, rest_lane,
                    list(copy.lightfade.lanes), groups, kinds)
    mix[VERSION_KEY] = GROUP_VERSION                 # the copy's group is as new as its lanes'
    node = insert_group(copy, colour, mix)
    for tree_ in old:
        if tree_ not in groups:
            bpy.data.node_groups.remove(tree_)
    for group in groups:
        group[TREE_TAG] = True
    for i, socket in outputs.items():
        tree.links.new(socket, node.inputs[f"Mask {i}"])
    return node


# --------------------------------------------------------------------------- the twin


def ensure_weights(scene, view_layer, copy, shape):
    """The lanes' weights at ``shape`` (H, W): baked by Cycles (the copy's own mask
    nodes) when not at hand at that size."""
    props = copy.lightfade
    if all(lane.weight_image is not None and tuple(lane.weight_image.size)[::-1] == shape
           for lane in props.lanes):
        return
    colour, problem = find_colour_socket(copy)
    if problem:
        raise AgingError(problem)
    bake_weights(scene, view_layer, copy, colour, shape)


def bake_weights(scene, view_layer, copy, colour, shape):
    """Bake the lanes' weights (Cycles, the copy's own mask nodes) at ``shape`` (H, W)."""
    props = copy.lightfade
    obj = props.aged_object
    H, W = shape
    tree = tree_at(copy.node_tree, colour.groups)
    node = tree.nodes[GROUP_NODE]
    for j in range(0, len(props.lanes), PER_IMAGE):
        name = f"{WEIGHTS_PREFIX}{copy.name}~{j // PER_IMAGE}"
        old = bpy.data.images.get(name)
        if old is not None:
            bpy.data.images.remove(old)
        image = bpy.data.images.new(name, W, H, alpha=True, float_buffer=True)
        image.colorspace_settings.name = "Non-Color"
        reroute = tree.nodes.new("NodeReroute")
        reroute.name = WEIGHTS_NODE
        try:
            tree.links.new(node.outputs[f"Weights {j // PER_IMAGE}"], reroute.inputs[0])
            target = ColourSocket(colour.groups, reroute.name, reroute.inputs[0].name)
            bake_albedos(scene, view_layer, obj, [(copy, target, image)], exposure_uv(obj),
                         scene.lightfade.bake_margin)
        except BaseException:
            bpy.data.images.remove(image)
            raise
        finally:
            tree.nodes.remove(reroute)
        for lane in list(props.lanes)[j:j + PER_IMAGE]:
            lane.weight_image = image


def mix_pixels(original, aged, weights):
    """``original + Σ_k W_k · (aged[k] - original)`` on (N, 3) colours (the shader's mix,
    in the same order); ``weights`` (K, N) the lanes' weights as baked.

    Where they sum past one they are shared out, ``W_k = w_k / max(Σ_k w_k, 1)``, as
    the node group shares the masks: weights read back from images (baked in groups of
    :data:`.mix.PER_IMAGE` lanes, filtered at the margins) must not age a texel more than
    once, whatever their rounding. Where they sum to less, the remainder stays the
    original (the mix group gives the rest's weight to its lane).
    """
    weights = np.asarray(weights, dtype=np.float32)
    share = np.float32(1.0) / np.maximum(weights.sum(axis=0), np.float32(1.0))
    out = original.copy()
    for a, w in zip(aged, weights):
        out += (w * share)[:, None] * (a - original)
    return out


def aged_pixels(scene, view_layer, copy, original, years):
    """(H, W, 4) float32 linear aged colour of a copy with parts (the numpy twin): each
    lane's table evaluated at the artist's colour ``original`` (H, W, 4) and the
    exposure maps, mixed with the baked weights (:func:`mix_pixels`)."""
    lanes = list(copy.lightfade.lanes)
    if not lanes:
        raise AgingError(f"Aged material '{copy.name}' lost its parts' recipes: press Age")
    H, W = original.shape[:2]
    ensure_weights(scene, view_layer, copy, (H, W))
    rgba = original.reshape(H * W, 4).copy()
    aged, weights = [], []
    for k, lane in enumerate(lanes):
        a = runtime.aged_rgb(scene, copy, original.copy(), years, lane).reshape(H * W, 4)
        aged.append(a[:, :3])
        w = read_rgba(lane.weight_image)[..., k % PER_IMAGE]
        weights.append(np.clip(w, 0.0, 1.0).reshape(-1).astype(np.float32))
    rgba[:, :3] = mix_pixels(rgba[:, :3], aged, weights)
    return rgba.reshape(H, W, 4)
