"""Geometry-nodes instances' tiles: an instance attribute written by a LightFade modifier.

An instance made by geometry nodes has no object of its own to hold a custom property;
what the material reads per instance is an attribute of the instance domain.  LightFade
adds one modifier, *LightFade Tiles*, after the artist's (their node tree untouched): for
each source the instancer scatters, it stores the attribute :func:`.instances.tile_attribute`
of that source on every instance, sampled by the instance's index from a small LightFade
mesh whose vertex ``i`` is the tile ``(u0, v0, s)`` of instance ``i`` (an object in no
scene, read by an Object Info node).  Reset removes the modifier, its tree and the data.
"""

from __future__ import annotations

import bpy
import numpy as np

#: The modifier's name, and the prefix of its node tree and of the data objects.
MODIFIER = "LightFade Tiles"
DATA_PREFIX = "LF_Tiles_"
#: Custom properties of a data object: its instancer and the attribute it fills.
OF_KEY = "lightfade_tiles_of"
NAME_KEY = "lightfade_attribute"


def data_objects(instancer=None):
    """LightFade's tile data objects (of ``instancer``, or all)."""
    return [o for o in bpy.data.objects if o.get(OF_KEY) is not None
            and (instancer is None or o.get(OF_KEY) == instancer)]


def write(instancer, name, rects):
    """Instances ``i`` of ``instancer`` read ``rects[i]`` (``(N, 3)``) under ``name``."""
    data = next((o for o in data_objects(instancer) if o.get(NAME_KEY) == name), None)
    mesh = bpy.data.meshes.new(f"{DATA_PREFIX}{instancer.name}")
    mesh.vertices.add(len(rects))
    mesh.vertices.foreach_set("co", np.asarray(rects, dtype=np.float32).ravel())
    if data is None:
        data = bpy.data.objects.new(mesh.name, mesh)
        data[OF_KEY], data[NAME_KEY] = instancer, name
    else:
        old, data.data = data.data, mesh
        bpy.data.meshes.remove(old)
    _modifier(instancer)


def _tree(instancer):
    """The modifier's node tree: one Store Named Attribute per data object, in a chain."""
    name = f"{DATA_PREFIX}{instancer.name}"
    tree = bpy.data.node_groups.get(name) or bpy.data.node_groups.new(name, "GeometryNodeTree")
    tree.nodes.clear()
    if not tree.interface.items_tree:
        for side in ("INPUT", "OUTPUT"):
            tree.interface.new_socket("Geometry", in_out=side, socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    gin, gout = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    geometry = gin.outputs[0]
    for k, data in enumerate(data_objects(instancer)):
        info = nodes.new("GeometryNodeObjectInfo")
        info.transform_space = "ORIGINAL"
        info.inputs["Object"].default_value = data
        sample = nodes.new("GeometryNodeSampleIndex")
        sample.data_type, sample.domain = "FLOAT_VECTOR", "POINT"
        links.new(info.outputs["Geometry"], sample.inputs["Geometry"])
        links.new(nodes.new("GeometryNodeInputPosition").outputs[0], sample.inputs["Value"])
        links.new(nodes.new("GeometryNodeInputIndex").outputs[0], sample.inputs["Index"])
        store = nodes.new("GeometryNodeStoreNamedAttribute")
        store.data_type, store.domain = "FLOAT_VECTOR", "INSTANCE"
        store.inputs["Name"].default_value = data[NAME_KEY]
        links.new(geometry, store.inputs["Geometry"])
        links.new(sample.outputs[0], store.inputs["Value"])
        store.location = (300 * (k + 1), 0)
        geometry = store.outputs[0]
    gout.location = (300 * (len(data_objects(instancer)) + 1), 0)
    links.new(geometry, gout.inputs[0])
    return tree


def _modifier(instancer):
    """The modifier, last on ``instancer`` (made anew after the artist's)."""
    old = instancer.modifiers.get(MODIFIER)
    if old is not None:
        instancer.modifiers.remove(old)
    mod = instancer.modifiers.new(MODIFIER, "NODES")
    mod.node_group = _tree(instancer)
    return mod


def remove(names):
    """Reset: the data objects filling ``names`` (attributes) go; a modifier left with
    none goes with its tree."""
    instancers = set()
    for data in data_objects():
        if data.get(NAME_KEY) in names:
            instancers.add(data[OF_KEY])
            mesh = data.data
            bpy.data.objects.remove(data)
            bpy.data.meshes.remove(mesh)
    for instancer in instancers:
        if instancer is None:
            continue
        if data_objects(instancer):
            _modifier(instancer)
            continue
        mod = instancer.modifiers.get(MODIFIER)
        tree = mod.node_group if mod is not None else None
        if mod is not None:
            instancer.modifiers.remove(mod)
        if tree is not None and tree.name.startswith(DATA_PREFIX):
            bpy.data.node_groups.remove(tree)
