"""Each object's own aged copy of a material, in object-linked slots.

Aging never edits the user's material: :func:`make_copy` copies it (and the node
groups on the way to its colour BSDF) for one object, :func:`assign` puts the copy in
that object's slots with ``slot.link = 'OBJECT'`` — so a material shared by a sunny and
a shaded object, or a mesh shared by linked duplicates, gives each object its own look
without making anything single user — and :func:`insert_group` puts the aging node
group between the copy's own Base Color graph and its BSDF.  :func:`remove_copy` puts the slots back exactly (link and
object-level material) and deletes the copy and the group trees made for it.

**The gate** (:func:`gate_rays`). The aging group costs far more per shading point
than the artist's own graph, so the copy's BSDF is duplicated once more with the
*original* colour, and a Mix Shader shows the aged one only where it can be seen or
differ: at years above 0 (not for a table with a history, whose 0 years is the
restoration) and on the rays the scene's *Aged Colour On* names
(``Scene.lightfade.aged_rays``): every ray (``ALL``, the default), every ray but
diffuse bounces (``VISIBLE``: mirrors, glossy and refraction show the aged colour too)
or camera rays (``CAMERA``). Cycles compiles a Mix Shader's two closures behind
``NODE_JUMP_IF_ONE`` / ``NODE_JUMP_IF_ZERO`` (``scene/svm.cpp``,
``generate_multi_closure``): with a factor of exactly 0 or 1 the other BSDF and the
nodes only it depends on (the whole aging group) are skipped, so 0 years costs what
the original costs. The ray choice leaves bounce light in the original colour, which
a room lit by its own walls shows (``benchmarks/live_room.py`` measures that error
beside the time it saves). The gate lives in the copy, so Reset, which deletes the
copy, undoes it exactly.
"""

from __future__ import annotations

import bpy

from ..source import GATE_MIX, tree_at
from .years import YEARS_PROP

AGED_PREFIX = "LF_Aged_"
#: Name of the group node that ages the Base Color in a copy.
GROUP_NODE = "LightFade Aging"
#: Name of the Image Texture node feeding applied (real) aged pixels (:mod:`.apply`).
APPLIED_NAME = "LightFade Applied Aging"
#: Custom property tagging node trees copied for a copy (removed with it).
TREE_TAG = "lightfade_copy"
#: Names of the ray gate's nodes (:func:`gate_rays`).
GATE_BSDF = "LightFade Original BSDF"
GATE_PATH = "LightFade Ray Type"
GATE_FAC = "LightFade Ray Choice"
GATE_YEARS = "LightFade Years"
GATE_AGED = "LightFade Years Above Zero"
GATE_BOTH = "LightFade Gate"
#: Node properties never copied onto the gate's duplicate BSDF.
_OWN = {"name", "label", "location", "location_absolute", "select", "parent", "dimensions",
        "width", "height", "show_options", "show_preview", "show_texture", "warning_propagation"}


def copy_name(material, obj):
    return f"{AGED_PREFIX}{material.name}.{obj.name}"


def copies_of(material=None, obj=None):
    """Aged copies in the file, optionally only those of ``material`` and/or ``obj``."""
    return [m for m in bpy.data.materials if m.lightfade.source is not None
            and (material is None or m.lightfade.source == material)
            and (obj is None or m.lightfade.aged_object == obj)]


def original(material):
    """The user's material behind ``material`` (itself unless it is an aged copy)."""
    return material.lightfade.source or material


def make_copy(obj, material, colour):
    """A copy of ``material`` for ``obj``, with private copies of the groups on the way
    to the colour BSDF (``colour.groups``) so wiring inside them touches nothing else."""
    copy = material.copy()
    copy.name = copy_name(material, obj)
    copy.use_fake_user = False
    props = copy.lightfade
    props.slot_backups.clear()               # a copy of a copy starts with no backups
    props.source = material
    props.aged_object = obj
    tree = copy.node_tree
    for name in colour.groups:
        node = tree.nodes[name]
        node.node_tree = node.node_tree.copy()
        node.node_tree[TREE_TAG] = True
        tree = node.node_tree
    return copy


def assign(obj, material, copy):
    """Show ``copy`` in every slot of ``obj`` showing ``material`` (object-linked)."""
    for index, slot in enumerate(obj.material_slots):
        if slot.material != material:
            continue
        backup = copy.lightfade.slot_backups.add()
        backup.index = index
        backup.link = slot.link
        if slot.link != "OBJECT":
            slot.link = "OBJECT"
        backup.material = slot.material          # the object-level material (usually none)
        slot.material = copy


def restore_slots(copy):
    """Put the slots :func:`assign` changed back: object-level material, then the link."""
    obj = copy.lightfade.aged_object
    if obj is None:
        return
    slots = obj.material_slots
    for backup in copy.lightfade.slot_backups:
        if backup.index >= len(slots):
            continue
        slot = slots[backup.index]
        if slot.link == "OBJECT" and slot.material == copy:
            slot.material = backup.material
            if slot.link != backup.link:
                slot.link = backup.link
    copy.lightfade.slot_backups.clear()


def _colour_socket(copy, colour):
    tree = tree_at(copy.node_tree, colour.groups)
    return tree, tree.nodes[colour.node].inputs[colour.socket]


def insert_group(copy, colour, group):
    """Put the aging group between the copy's Base Color graph and its BSDF.

    The graph's output (or the socket's own colour when unlinked) feeds the group's
    Color input.  Idempotent: a second call replaces the group node's tree.
    """
    tree, socket = _colour_socket(copy, colour)
    bsdf = tree.nodes[colour.node]
    node = tree.nodes.get(GROUP_NODE)
    if node is None:
        node = tree.nodes.new("ShaderNodeGroup")
        node.name = node.label = GROUP_NODE
        node.location = (bsdf.location.x - 240, bsdf.location.y + 40)
        node.width = 200
        feed = socket.links[0].from_socket if socket.links else None
        if feed is None:
            value = tuple(socket.default_value)
        node.node_tree = group
        if feed is not None:
            tree.links.new(feed, node.inputs[0])
        else:
            node.inputs[0].default_value = value
    else:
        old = node.node_tree
        node.node_tree = group
        if old is not None and old != group and old.users == 0:
            bpy.data.node_groups.remove(old)
    group[TREE_TAG] = True
    tree.links.new(node.outputs[0], socket)
    return node


def _duplicate(tree, node):
    """A new node of ``node``'s type with its settings, input values and input links."""
    dup = tree.nodes.new(node.bl_idname)
    for prop in node.bl_rna.properties:
        key = prop.identifier
        if prop.is_readonly or key in _OWN or key.startswith("bl_"):
            continue
        try:
            setattr(dup, key, getattr(node, key))
        except (AttributeError, TypeError, ValueError):
            pass                                  # a property this type only reads
    for source, target in zip(node.inputs, dup.inputs):
        if hasattr(source, "default_value"):
            target.default_value = source.default_value
        for link in source.links:
            tree.links.new(link.from_socket, target)
    return dup


def _math(tree, name, op, a, b, location):
    """A Math node ``op`` of sockets or numbers ``a``, ``b``; returns its output."""
    node = tree.nodes.new("ShaderNodeMath")
    node.name = node.label = name
    node.operation = op
    node.location = location
    for socket, value in zip(node.inputs, (a, b)):
        if isinstance(value, float):
            socket.default_value = value
        else:
            tree.links.new(value, socket)
    return node.outputs[0]


def _gate_factor(tree, rays, zero_years, at):
    """The gate's factor, exactly 0 or 1: the ray condition of ``rays`` times, with
    ``zero_years``, ``years > 0``; None when nothing is gated."""
    x, y = at
    factors = []
    if rays in ("VISIBLE", "CAMERA"):
        path = tree.nodes.new("ShaderNodeLightPath")
        path.name = path.label = GATE_PATH
        path.location = (x, y + 420)
        factors.append(path.outputs["Is Camera Ray"] if rays == "CAMERA" else
                       _math(tree, GATE_FAC, "SUBTRACT", 1.0, path.outputs["Is Diffuse Ray"],
                             (x + 150, y + 420)))
    if zero_years:
        years = tree.nodes.new("ShaderNodeAttribute")
        years.name = years.label = GATE_YEARS
        years.attribute_type, years.attribute_name = "VIEW_LAYER", YEARS_PROP
        years.location = (x, y + 260)
        factors.append(_math(tree, GATE_AGED, "GREATER_THAN", years.outputs["Fac"], 0.0,
                             (x + 150, y + 260)))
    if len(factors) == 2:
        return _math(tree, GATE_BOTH, "MULTIPLY", *factors, (x + 300, y + 340))
    return factors[0] if factors else None


def gate_rays(copy, colour, rays, zero_years=True):
    """Show the aged colour (the BSDF of ``colour``, fed by the aging group) only where
    it can be seen or differ: on the rays ``rays`` names and, with ``zero_years``, at
    years above 0; elsewhere a duplicate BSDF with the original colour.

    ``rays``: ``ALL``, ``VISIBLE`` (all but diffuse bounces) or ``CAMERA``.
    ``zero_years``: False for a table with a history (its 0 years is the restoration).
    Returns the gate's Mix Shader (None without one). Idempotent: a tree that has its
    gate keeps it.
    """
    tree, socket = _colour_socket(copy, colour)
    bsdf, node = tree.nodes[colour.node], tree.nodes.get(GROUP_NODE)
    shaders = [(out, list(out.links)) for out in bsdf.outputs if out.type == "SHADER"]
    if node is None or tree.nodes.get(GATE_MIX) is not None \
            or not any(links for _o, links in shaders):
        return None
    x, y = bsdf.location
    fac = _gate_factor(tree, rays, zero_years, (x, y))
    if fac is None:
        return None
    original = _duplicate(tree, bsdf)
    original.name = original.label = GATE_BSDF
    original.location = (x, y - 40)
    mine = original.inputs[list(bsdf.inputs).index(socket)]
    feed = node.inputs[0].links[0].from_socket if node.inputs[0].links else None
    if feed is not None:
        tree.links.new(feed, mine)
    else:
        mine.default_value = node.inputs[0].default_value
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.name = mix.label = GATE_MIX
    mix.location = (x + 450, y)
    tree.links.new(fac, mix.inputs["Fac"])
    for out, links in shaders:
        for link in links:
            tree.links.new(mix.outputs[0], link.to_socket)
    first = shaders[0][0]
    tree.links.new(original.outputs[first.identifier], mix.inputs[1])      # Fac 0
    tree.links.new(first, mix.inputs[2])                                   # Fac 1: aged
    return mix


def remove_copy(copy):
    """Restore the slots and delete the copy and the node groups copied for it."""
    restore_slots(copy)
    trees = [n.node_tree for _t, n in walk(copy.node_tree)
             if n.type == "GROUP" and n.node_tree is not None and n.node_tree.get(TREE_TAG)]
    bpy.data.materials.remove(copy)
    # private to the copy by construction, unless a copy of the copy shares them (Blender
    # 4.2 miscounts users, so the materials are asked)
    shared = {n.node_tree for m in bpy.data.materials for _t, n in walk(m.node_tree)
              if n.type == "GROUP" and n.node_tree is not None}
    for tree in trees:
        if tree not in shared:
            bpy.data.node_groups.remove(tree)


def walk(tree, depth=0):
    """Every node of ``tree`` and of the group trees inside it, as (tree, node); the
    aging group's own nodes are not entered."""
    if tree is None or depth > 16:
        return
    for node in tree.nodes:
        yield tree, node
        if node.type == "GROUP" and node.node_tree is not None and node.name != GROUP_NODE:
            yield from walk(node.node_tree, depth + 1)
