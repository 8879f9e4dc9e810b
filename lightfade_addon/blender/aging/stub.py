"""The aging group as a stub while a render reads the frame images (:mod:`.frames`).

A constant factor lets Cycles fold the live branch of an aged copy away, but the
folding is work: at every render Cycles' sync converts every node of the material's
tree, the aging group's included (about 160 in a copy, 20 ms of CPU per aged material
per frame), and only then folds them. So while a render shows a copy's frame image,
its *LightFade Aging* group node reads a **stub**: a copy of its group with the same
sockets (their identifiers, so that every link stays) and no nodes inside. The node
gets its own group back at the render's end, before a save and when LightFade is
disabled (:mod:`.frames`' handlers); the stub is removed.
"""

from __future__ import annotations

import bpy

from .copies import GROUP_NODE, walk

#: The aging group nodes reading a stub for the render in progress: node pointer ->
#: (node, its own group tree).
_STUBBED = {}


def stub_of(tree):
    """A group with ``tree``'s sockets (their identifiers too, so that every link of the
    node stays) and no nodes inside: what the render's folding would leave of it."""
    stub = tree.copy()
    stub.name = "LightFade Render Stub"
    for node in list(stub.nodes):
        if node.type not in {"GROUP_INPUT", "GROUP_OUTPUT"}:
            stub.nodes.remove(node)
    return stub


def hold(copy, on):
    """The aging group nodes of ``copy`` read a stub (``on``) or their own group again
    (a frame of an animation whose years went back to 0 renders the live side)."""
    for _tree, node in walk(copy.node_tree):
        if node.type != "GROUP" or node.name != GROUP_NODE or node.node_tree is None:
            continue
        key = node.as_pointer()
        if on and key not in _STUBBED:
            _STUBBED[key] = (node, node.node_tree)
            node.node_tree = stub_of(node.node_tree)
        elif not on and key in _STUBBED:
            _put_back(key)


def _put_back(key):
    """The stubbed node ``key`` reads its own group again; its stub is removed."""
    node, tree = _STUBBED.pop(key)
    stub = node.node_tree
    node.node_tree = tree
    if stub is not None and stub.users == 0:
        bpy.data.node_groups.remove(stub)


def release_all():
    """Every stubbed aging group node reads its own group again."""
    for key in list(_STUBBED):
        _put_back(key)


def forget():
    """Forget the stubbed nodes (file load, unregister: their trees are gone)."""
    _STUBBED.clear()
