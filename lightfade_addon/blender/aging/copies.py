"""Each object's own aged copy of a material, in object-linked slots.

Aging never edits the user's material: :func:`make_copy` copies it (and the node
groups on the way to its colour BSDF) for one object, :func:`assign` puts the copy in
that object's slots with ``slot.link = 'OBJECT'`` — so a material shared by a sunny and
a shaded object, or a mesh shared by linked duplicates, gives each object its own look
without making anything single user — and :func:`insert_group` puts the aging node
group between the copy's own Base Color graph and its BSDF.  :func:`remove_copy` puts the slots back exactly (link and
object-level material) and deletes the copy and the group trees made for it.
"""

from __future__ import annotations

import bpy

from ..source import tree_at

AGED_PREFIX = "LF_Aged_"
#: Name of the group node that ages the Base Color in a copy.
GROUP_NODE = "LightFade Aging"
#: Name of the Image Texture node feeding applied (real) aged pixels (:mod:`.apply`).
APPLIED_NAME = "LightFade Applied Aging"
#: Custom property tagging node trees copied for a copy (removed with it).
TREE_TAG = "lightfade_copy"


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
