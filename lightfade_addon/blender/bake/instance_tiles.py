"""Geometry-nodes instances' tiles: an instance attribute written by a LightFade modifier.

An instance made by geometry nodes has no object of its own to hold a custom property;
what the material reads per instance is an attribute of the instance domain.  LightFade
adds one modifier, *LightFade Tiles*, after the artist's (their node tree untouched): for
each source the instancer scatters, it stores the attribute :func:`.instances.tile_attribute`
of that source on every instance, looked up **by the instance's position** (in the
instancer's space) in a small LightFade mesh whose vertices stand where the baked
instances stood, each holding its tile ``(u0, v0, s)`` in the attribute
:data:`TILE_ATTRIBUTE` (an object in no scene, read by an Object Info node): Sample
Nearest finds the vertex, Sample Index reads its tile.

The position, not the index, is the instance's identity: an instance keeps its tile when
others are added before it (a higher density, a longer line) or the scatter is evaluated
again with the same seed.  An instance that appeared or moved since the bake reads the
tile of the nearest baked one (the panel says it is stale).  The positions are read from
the evaluated instances themselves (:func:`evaluated_instances`), so the lookup matches
them exactly.  Reset removes the modifier, its tree and the data.
"""

from __future__ import annotations

from contextlib import contextmanager

import bpy
import numpy as np

from .common import TEMP_PREFIX

#: The modifier's name, and the prefix of its node tree and of the data objects.
MODIFIER = "LightFade Tiles"
DATA_PREFIX = "LF_Tiles_"
#: Custom properties of a data object: its instancer and the attribute it fills.
OF_KEY = "lightfade_tiles_of"
NAME_KEY = "lightfade_attribute"
#: The data mesh's point attribute holding each baked instance's tile ``(u0, v0, s)``.
TILE_ATTRIBUTE = "lightfade_tile"


def data_objects(instancer=None):
    """LightFade's tile data objects (of ``instancer``, or all)."""
    return [o for o in bpy.data.objects if o.get(OF_KEY) is not None
            and (instancer is None or o.get(OF_KEY) == instancer)]


def data_tiles(data):
    """``(positions (N, 3), tiles (N, 3))`` held by the data object ``data``."""
    mesh = data.data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    rects = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.attributes[TILE_ATTRIBUTE].data.foreach_get("vector", rects)
    return co.reshape(-1, 3), rects.reshape(-1, 3)


def write(instancer, name, positions, rects):
    """Instances of ``instancer`` at ``positions`` (``(N, 3)``, the instancer's space, as
    evaluated) read ``rects[j]`` (``(N, 3)``) under ``name``; any other instance reads the
    tile of the nearest of them.  Of positions given twice, the first one's tile is kept."""
    positions = np.asarray(positions, dtype=np.float32).reshape(-1, 3)
    _, first = np.unique(positions, axis=0, return_index=True)
    first = np.sort(first)
    data = next((o for o in data_objects(instancer) if o.get(NAME_KEY) == name), None)
    mesh = bpy.data.meshes.new(f"{DATA_PREFIX}{instancer.name}")
    mesh.vertices.add(len(first))
    mesh.vertices.foreach_set("co", positions[first].ravel())
    tiles = mesh.attributes.new(TILE_ATTRIBUTE, "FLOAT_VECTOR", "POINT")
    tiles.data.foreach_set("vector", np.asarray(rects, dtype=np.float32)[first].ravel())
    if data is None:
        data = bpy.data.objects.new(mesh.name, mesh)
        data[OF_KEY], data[NAME_KEY] = instancer, name
    else:
        old, data.data = data.data, mesh
        bpy.data.meshes.remove(old)
    _modifier(instancer)


def _new_tree(name):
    tree = bpy.data.node_groups.new(name, "GeometryNodeTree")
    for side in ("INPUT", "OUTPUT"):
        tree.interface.new_socket("Geometry", in_out=side, socket_type="NodeSocketGeometry")
    return tree


def _tree(instancer):
    """The modifier's node tree: per data object, the tile of the nearest baked instance
    stored on each instance (Sample Nearest, Sample Index, Store Named Attribute)."""
    name = f"{DATA_PREFIX}{instancer.name}"
    tree = bpy.data.node_groups.get(name)
    if tree is None:
        tree = _new_tree(name)
    tree.nodes.clear()
    nodes, links = tree.nodes, tree.links
    gin, gout = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    geometry = gin.outputs[0]
    datas = data_objects(instancer)
    for k, data in enumerate(datas):
        info = nodes.new("GeometryNodeObjectInfo")
        info.transform_space = "ORIGINAL"
        info.inputs["Object"].default_value = data
        nearest = nodes.new("GeometryNodeSampleNearest")
        nearest.domain = "POINT"
        links.new(info.outputs["Geometry"], nearest.inputs["Geometry"])
        links.new(nodes.new("GeometryNodeInputPosition").outputs[0],
                  nearest.inputs["Sample Position"])
        tile = nodes.new("GeometryNodeInputNamedAttribute")
        tile.data_type = "FLOAT_VECTOR"
        tile.inputs["Name"].default_value = TILE_ATTRIBUTE
        sample = nodes.new("GeometryNodeSampleIndex")
        sample.data_type, sample.domain = "FLOAT_VECTOR", "POINT"
        links.new(info.outputs["Geometry"], sample.inputs["Geometry"])
        links.new(tile.outputs["Attribute"], sample.inputs["Value"])
        links.new(nearest.outputs["Index"], sample.inputs["Index"])
        store = nodes.new("GeometryNodeStoreNamedAttribute")
        store.data_type, store.domain = "FLOAT_VECTOR", "INSTANCE"
        store.inputs["Name"].default_value = data[NAME_KEY]
        links.new(geometry, store.inputs["Geometry"])
        links.new(sample.outputs[0], store.inputs["Value"])
        store.location = (300 * (k + 1), 0)
        geometry = store.outputs[0]
    gout.location = (300 * (len(datas) + 1), 0)
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


@contextmanager
def _probe(instancer):
    """A temporary last modifier turning ``instancer``'s top-level instances into one
    vertex each (index order, their attributes kept); removed on exit."""
    tree = _new_tree(f"{TEMP_PREFIX}probe")
    nodes, links = tree.nodes, tree.links
    gin, gout = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    points = nodes.new("GeometryNodeInstancesToPoints")
    verts = nodes.new("GeometryNodePointsToVertices")
    links.new(gin.outputs[0], points.inputs["Instances"])
    links.new(points.outputs["Points"], verts.inputs["Points"])
    links.new(verts.outputs["Mesh"], gout.inputs[0])
    mod = instancer.modifiers.new(f"{TEMP_PREFIX}probe", "NODES")
    try:
        mod.node_group = tree
        yield
    finally:
        instancer.modifiers.remove(mod)
        bpy.data.node_groups.remove(tree)


def evaluated_instances(instancer, names=("id",)):
    """``(positions (N, 3) float32, {name: array (N, ...)})``: the position of each of
    ``instancer``'s top-level instances as evaluated (the instancer's space, index order)
    and those of the instance attributes ``names`` it has (``id``: Blender's persistent
    id of the instance where unique)."""
    with _probe(instancer):
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        evaluated = instancer.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        try:
            n = len(mesh.vertices)
            co = np.empty(n * 3, dtype=np.float32)
            mesh.vertices.foreach_get("co", co)
            out = {}
            for name in names:
                attr = mesh.attributes.get(name)
                if attr is None or attr.domain != "POINT":
                    continue
                if attr.data_type == "INT":
                    values = np.empty(n, dtype=np.int64)
                    attr.data.foreach_get("value", values)
                else:
                    values = np.empty(n * 3, dtype=np.float32)
                    attr.data.foreach_get("vector", values)
                    values = values.reshape(n, 3)
                out[name] = values
        finally:
            evaluated.to_mesh_clear()
    return co.reshape(-1, 3), out


def positions(instancer, ids, matrices):
    """``{id: (row, position)}`` of ``instancer``'s geometry-nodes instances ``ids`` (the
    last level of Blender's persistent id: the instance's ``id`` attribute where it has
    one, else its index) as evaluated: their index and position in the instancer's space.
    An id Blender had to make unique (two instances with one ``id``) is left out: that
    instance reads its nearest baked neighbour's tile.  An instancer Blender gives no
    mesh of (hair curves) falls back on ``matrices`` (``{id: world matrix}`` of the
    placements): right for instances of an object, whose matrix is the instance's."""
    try:
        positions, attributes = evaluated_instances(instancer)
    except RuntimeError:                          # "Object does not have geometry data"
        inverse = instancer.matrix_world.inverted()
        return {i: (i, np.array((inverse @ m).translation, dtype=np.float32))
                for i, m in matrices.items()}
    rows = {}
    if "id" in attributes:
        for row, value in enumerate(attributes["id"].tolist()):
            rows.setdefault(value, row)
    else:
        rows = dict(zip(range(len(positions)), range(len(positions))))
    return {i: (rows[i], positions[rows[i]]) for i in ids if i in rows}


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
