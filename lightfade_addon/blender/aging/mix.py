"""The mixing group of a material with parts: masks, weights and the mix of one aging
group per recipe in use (:mod:`..parts` says what is mixed and why).

Per shading point, ``m_p`` each part's mask (:func:`_snap`), ``S = Σ m_p``,
``w_p = m_p / max(S, 1)``, the rest's weight ``1 - S / max(S, 1)``, ``W_k`` the sum of
the weights aging with lane k, and ``out = C + Σ_k W_k · (A_k - C)``.
"""

from __future__ import annotations

import bpy

from .graph import Graph, Sock

#: Mask values this close to 0 or 1 count as 0 or 1 (:func:`_snap`).
SNAP = 2.0 ** -10
#: Lanes per weights output (a vector: three lanes).
PER_IMAGE = 3


def _snap(m):
    """``m`` in [0, 1], values within :data:`SNAP` of 0 or 1 made exactly 0 or 1: a
    filtered mask of ones sums its texel weights to 0.99999994 at places."""
    return ((m - SNAP) * (1.0 / (1.0 - 2.0 * SNAP))).clamp(0.0, 1.0)


def _mask(g, part, index, gin):
    """The part's mask as a Sock in [0, 1] (:func:`_snap`)."""
    g.stage = f"mask {part.name}"
    if part.mask == "IMAGE":
        inputs = {}
        if part.uv_map:
            inputs["Vector"] = g.out(g.node("ShaderNodeUVMap", uv_map=part.uv_map), "UV")
        node = g.node("ShaderNodeTexImage", inputs, image=part.image, interpolation="Linear")
        colour, alpha = g.out(node, "Color"), g.out(node, "Alpha")
    elif part.mask == "ATTRIBUTE":
        node = g.node("ShaderNodeAttribute", attribute_type="GEOMETRY",
                      attribute_name=part.attribute)
        colour, alpha = g.out(node, "Color"), g.out(node, "Alpha")
    else:
        value = Sock(g, gin.outputs[f"Mask {index}"], 0)
        if gin.outputs[f"Mask {index}"].type == "VALUE":
            return _snap(value)
        colour, alpha = value, None
    if part.channel == "A":
        return _snap(alpha)
    return _snap(g.separate(colour)["RGB".index(part.channel)])


def _interface(tree, n_lanes, socket_types):
    tree.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    for index, kind in socket_types.items():
        tree.interface.new_socket(f"Mask {index}", in_out="INPUT", socket_type=kind)
    tree.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    for j in range(0, n_lanes, PER_IMAGE):
        tree.interface.new_socket(f"Weights {j // PER_IMAGE}", in_out="OUTPUT",
                                  socket_type="NodeSocketVector")


def mix_group(name, parts, part_lane, rest_lane, lanes, groups, socket_types):
    """A new group ``name`` mixing one aging group per lane by the parts' masks.

    ``parts``: the material's parts; ``part_lane`` each part's lane index (None: does
    not age), ``rest_lane`` the rest's; ``lanes`` the lane records (their recipe names
    the nodes), ``groups`` their aging groups (each ages the artist's colour itself);
    ``socket_types``: {part index: the group input type of a node-output mask}. Inputs Color and ``Mask <i>``; outputs Color and
    ``Weights <j>`` (lanes 3j..3j+2, for the bake of the numpy twin).
    """
    tree = bpy.data.node_groups.new(name, "ShaderNodeTree")
    _interface(tree, len(lanes), socket_types)
    g = Graph(tree)
    g.stage = "io"
    gin = g.node("NodeGroupInput", depth=0)
    colour = Sock(g, gin.outputs[0], 0)
    masks = [_mask(g, part, i, gin) for i, part in enumerate(parts)]
    g.stage = "weights"
    total = masks[0]
    for m in masks[1:]:
        total = total + m
    scale = 1.0 / total.max(1.0)
    weights = [None] * len(lanes)
    for m, k in zip(masks, part_lane):
        if k is not None:
            w = m * scale
            weights[k] = w if weights[k] is None else weights[k] + w
    if rest_lane is not None:
        w = 1.0 - total * scale
        weights[rest_lane] = w if weights[rest_lane] is None else weights[rest_lane] + w
    g.stage = "lanes"
    out = colour
    for k, (lane, group) in enumerate(zip(lanes, groups)):
        node = g.node("ShaderNodeGroup", (colour,), node_tree=group)
        node.label = f"{lane.recipe.title()} ({lane.name})"
        aged = g.out(node, 0)
        change = g.vector("SUBTRACT", aged, colour)
        out = g.vector("ADD", out, g.vector("SCALE", change, None, None, weights[k]))
    g.stage = "io"
    zero = 0.0
    packed = [g.combine(*(weights[j + i] if j + i < len(lanes) else zero for i in range(3)))
              for j in range(0, len(lanes), PER_IMAGE)]
    gout = g.node("NodeGroupOutput", (out, *packed))
    gout.is_active_output = True
    return tree
