"""Many small objects baked together: one temporary mesh and one atlas for a batch.

Blender's bake operator runs Cycles once per selected object, and each run syncs the
whole scene (its BVH) again: N separate objects cost N scene syncs, a time that grows as
N² (100 small cubes: 41.6 s against 11.1 s for the same cubes as one mesh), and every
object's map is denoised and filtered alone (a compositor scene per map).  So the small
objects of a bake (maps at most :data:`BATCH_MAX_SIZE` wide) whose materials do not
depend on the object (:func:`material_batch_safe`) are baked as one temporary mesh per
batch: their evaluated meshes in world space, joined with their own materials and
corner normals, whose baked UV map puts each object's 0-1 square in its own cell of one
atlas (:func:`pack_cells`): cell ``(x, y)`` of width ``n`` holds the object's ``n × n``
map texel for texel (texel ``(r, c)`` of the map is texel ``(y + r, x + c)`` of the
atlas: the same texel centres, hence the same coverage, as baking the object alone).
Cells lie :func:`gap` texels apart, so the bake margin of one never reaches another.
The originals are hidden from render while the temporary mesh stands in for them, so
the light is what it was.  The atlas is denoised and filtered once, then cut into
each object's own map (:func:`crop`): aging, storing and re-baking see per-object maps
as before.

Another module bakes N objects together by passing them to one
:func:`.exposure.bake_exposure` call (or :class:`.exposure.ExposureBake`): batching is
automatic for the objects that qualify; ``batch=`` a width bakes together the objects
whose maps are at most that wide (``batch=4096``: every batch-safe object), ``False``
none.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import bpy
import numpy as np

from .common import TEMP_PREFIX
from .daylight import stamp
from .emitters import emission_sockets
from .uvmaps import evaluated_mesh, texel_geometry

#: Objects whose maps are at most this wide are baked in atlases (texels).
BATCH_MAX_SIZE = 256
#: Widest atlas (texels); more objects make more atlases.
ATLAS_MAX = 4096
#: Fewer small objects than this are baked each on its own, as before: the overhead of a
#: few separate objects is small (it grows as N²).
MIN_BATCH = 8
#: UV map of the temporary mesh that holds the atlas layout.
ATLAS_UV = "LightFadeAtlas"

#: Shader nodes whose output depends on the object or its mesh's attributes: a material
#: with one is baked on its own object (Generated coordinates, object info, attributes).
_OBJECT_NODES = {"ShaderNodeObjectInfo", "ShaderNodeAttribute", "ShaderNodeVertexColor",
                 "ShaderNodeUVMap", "ShaderNodeTexCoord", "ShaderNodeTangent",
                 "ShaderNodeParticleInfo", "ShaderNodeHairInfo", "ShaderNodePointInfo",
                 "ShaderNodeUVAlongStroke", "ShaderNodeWireframe", "ShaderNodeVectorDisplacement",
                 "ShaderNodeTexPointDensity"}
#: Textures that look up the UV map when their Vector input is unlinked (others use the
#: object's Generated coordinates).
_UV_TEXTURES = {"ShaderNodeTexImage", "ShaderNodeTexEnvironment", "ShaderNodeTexSky"}


@dataclass
class Atlas:
    """One batch: ``cells`` maps object name -> ``(x, y, n)`` (texels) in a ``size``² map."""

    name: str
    size: int
    cells: dict = field(default_factory=dict)


def _tree_batch_safe(tree, seen):
    for node in tree.nodes:
        if node.bl_idname in _OBJECT_NODES:
            return False
        if node.bl_idname == "ShaderNodeNormalMap" and (
                node.uv_map or node.space in ("OBJECT", "BLENDER_OBJECT")):
            return False
        if (node.bl_idname.startswith("ShaderNodeTex") and node.bl_idname not in _UV_TEXTURES
                and "Vector" in node.inputs and not node.inputs["Vector"].is_linked):
            return False
        if node.bl_idname == "ShaderNodeTexImage" and node.projection != "FLAT":
            return False
        sub = getattr(node, "node_tree", None)
        if sub is not None and sub.name not in seen:
            seen.add(sub.name)
            if not _tree_batch_safe(sub, seen):
                return False
    return True


def material_batch_safe(material):
    """Whether ``material`` shades the same on a joined copy of its object: no node reads
    the object (Object Info, Generated or Object coordinates, a procedural texture
    without a vector), its attributes (Attribute, Color Attribute, a named UV map,
    tangents) or its emission (an emitter is baked on its own).  None (an empty slot)
    is safe."""
    if material is None or material.node_tree is None:
        return True
    if emission_sockets(material):
        return False
    return _tree_batch_safe(material.node_tree, set())


def batchable(obj, size, safe=None, max_size=BATCH_MAX_SIZE):
    """Whether ``obj`` (its map ``size`` wide) may be baked in an atlas: a map at most
    ``max_size`` wide, no emitter, batch-safe materials.  ``safe``: a cache
    ``{material name: bool}``."""
    if size > max_size or obj.lightfade_emitter.enabled:
        return False
    safe = {} if safe is None else safe
    for slot in obj.material_slots:
        mat = slot.material
        key = None if mat is None else mat.name_full
        if key not in safe:
            safe[key] = material_batch_safe(mat)
        if not safe[key]:
            return False
    return True


def gap(margin):
    """Texels between cells: the bake margin, which extends each cell's islands outward."""
    return int(margin) + 1


def pack_cells(sizes, spacing, max_size=ATLAS_MAX):
    """Square cells of widths ``sizes`` (``{name: n}``) in rows, ``spacing`` texels apart,
    in atlases at most ``max_size`` wide.

    Returns ``[(side, {name: (x, y, n)})]``: each atlas's width (a multiple of 8) and
    its cells' lower-left texels.  Widest first; a row is as tall as its first cell.
    """
    order = sorted(sizes, key=lambda k: (-sizes[k], k))
    atlases = []
    while order:
        area = sum((sizes[k] + spacing) ** 2 for k in order)
        width = min(max_size, max(8, int(math.ceil(math.sqrt(area) * 1.03 / 8.0) * 8),
                                  sizes[order[0]]))
        cells, x, y, row, rest = {}, 0, 0, 0, []
        for name in order:
            n = sizes[name]
            if x + n > width:                   # next row
                x, y, row = 0, y + row + spacing, 0
            if y + n > max_size or n > width:
                rest.append(name)
                continue
            cells[name] = (x, y, n)
            x += n + spacing
            row = max(row, n)
        if not cells:
            raise ValueError(f"a {sizes[order[0]]}-texel cell does not fit a {max_size} atlas")
        used = max(max(x + n for x, _, n in cells.values()), max(y + n for _, y, n in cells.values()))
        atlases.append((int(math.ceil(used / 8.0) * 8), cells))
        order = rest
    return atlases


def plan_for(targets, sizes, groups, margin, batch=True):
    """The atlases of a bake: its ``targets`` (maps ``sizes`` wide by name) that are
    :func:`batchable`, not counted as lamps in any of ``groups``; ``batch`` True (maps
    up to :data:`BATCH_MAX_SIZE` wide), a width, or False (none)."""
    if not batch:
        return []
    members = {n for g in groups for n in g.member_names}
    safe = {}
    widest = BATCH_MAX_SIZE if batch is True else int(batch)
    small = {o.name: sizes[o.name] for o in targets
             if o.name not in members and batchable(o, sizes[o.name], safe, widest)}
    return plan_atlases(small, margin)


def plan_atlases(sizes, margin, max_size=ATLAS_MAX):
    """The :class:`Atlas` of each batch of the objects ``{name: map width}`` (all
    batchable); none for fewer than :data:`MIN_BATCH`."""
    if len(sizes) < MIN_BATCH:
        return []
    return [Atlas(f"{TEMP_PREFIX}Atlas{k}", side, cells)
            for k, (side, cells) in enumerate(pack_cells(sizes, gap(margin), max_size))]


# ----------------------------------------------------------------------- the joined mesh


def _corner_normals(mesh):
    n = np.empty(len(mesh.loops) * 3, dtype=np.float32)
    mesh.corner_normals.foreach_get("vector", n)
    return n.reshape(-1, 3)


def _uv(mesh, name):
    uv = np.empty(len(mesh.loops) * 2, dtype=np.float32)
    mesh.uv_layers[name].data.foreach_get("uv", uv)
    return uv.reshape(-1, 2)


def member_arrays(obj, depsgraph, uv_name):
    """``obj``'s mesh as rendered in world space: a dict of numpy arrays (vertices ``co``,
    loops ``vertex``, ``normal``, ``uv`` (of ``uv_name``), ``render_uv``, polygons
    ``loop_start``, ``loop_total``, ``material``)."""
    with evaluated_mesh(obj, depsgraph) as mesh:
        v, p = len(mesh.vertices), len(mesh.polygons)
        co = np.empty(v * 3, dtype=np.float64)
        mesh.vertices.foreach_get("co", co)
        vertex = np.empty(len(mesh.loops), dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", vertex)
        start, total, material = (np.empty(p, dtype=np.int32) for _ in range(3))
        mesh.polygons.foreach_get("loop_start", start)
        mesh.polygons.foreach_get("loop_total", total)
        mesh.polygons.foreach_get("material_index", material)
        normal = _corner_normals(mesh).astype(np.float64)
        uv = _uv(mesh, uv_name)
        render = next((layer.name for layer in mesh.uv_layers if layer.active_render), uv_name)
        render_uv = _uv(mesh, render)
    m = np.array(obj.matrix_world, dtype=np.float64)
    linear = m[:3, :3]
    co = co.reshape(-1, 3) @ linear.T + m[:3, 3]
    normal = normal @ np.linalg.inv(linear)          # (M^-T n)^T = n^T M^-1
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-20)
    arrays = {"co": co, "vertex": vertex, "normal": normal, "uv": uv, "render_uv": render_uv,
              "loop_start": start, "loop_total": total, "material": material}
    if np.linalg.det(linear) < 0:                  # mirrored: keep the faces' winding outward
        order = _reversed_loops(start, total)
        for key in ("vertex", "normal", "uv", "render_uv"):
            arrays[key] = arrays[key][order]
    return arrays


def _reversed_loops(start, total):
    """Loop order with each polygon's loops reversed (its first corner kept first)."""
    poly = np.repeat(np.arange(len(start)), total)
    k = np.arange(len(poly)) - np.repeat(start, total)
    back = np.where(k == 0, 0, total[poly] - k)
    return np.repeat(start, total) + back


def build_atlas_object(atlas, objects, uv_names, depsgraph, scene):
    """The temporary mesh of ``atlas``: ``objects`` (by name) as rendered, in world space,
    joined with their materials; UV map :data:`ATLAS_UV` (active, baked) puts each one's
    ``uv_names[name]`` map in its cell, and each one's render UV map is kept as
    ``UVMap`` (active for rendering: image textures read it).  Linked to ``scene``."""
    parts, materials, slot_of = [], [], {}
    for name, (x, y, n) in atlas.cells.items():
        obj = objects[name]
        part = member_arrays(obj, depsgraph, uv_names[name])
        part["uv"] = (np.array([x, y]) + part["uv"] * n) / atlas.size
        slots = [s.material for s in obj.material_slots] or [None]
        index = []
        for mat in slots:
            key = None if mat is None else mat.name_full
            if key not in slot_of:
                slot_of[key] = len(materials)
                materials.append(mat)
            index.append(slot_of[key])
        part["material"] = np.asarray(index, dtype=np.int32)[
            np.clip(part["material"], 0, len(index) - 1)]
        parts.append(part)
    join = {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}
    v_off = np.cumsum([0] + [len(p["co"]) for p in parts[:-1]])
    l_off = np.cumsum([0] + [len(p["vertex"]) for p in parts[:-1]])
    join["vertex"] = np.concatenate([p["vertex"] + o for p, o in zip(parts, v_off)])
    join["loop_start"] = np.concatenate([p["loop_start"] + o for p, o in zip(parts, l_off)])
    mesh = bpy.data.meshes.new(atlas.name)
    mesh.vertices.add(len(join["co"]))
    mesh.vertices.foreach_set("co", join["co"].astype(np.float32).ravel())
    mesh.loops.add(len(join["vertex"]))
    mesh.loops.foreach_set("vertex_index", join["vertex"])
    mesh.polygons.add(len(join["loop_start"]))
    mesh.polygons.foreach_set("loop_start", join["loop_start"])
    if bpy.app.version < (4, 0, 0):  # pragma: no cover (4.2 is the oldest supported)
        mesh.polygons.foreach_set("loop_total", join["loop_total"])
    mesh.polygons.foreach_set("material_index", join["material"])
    mesh.update(calc_edges=True)
    render = mesh.uv_layers.new(name="UVMap")
    render.data.foreach_set("uv", join["render_uv"].astype(np.float32).ravel())
    baked = mesh.uv_layers.new(name=ATLAS_UV)
    baked.data.foreach_set("uv", join["uv"].astype(np.float32).ravel())
    mesh.uv_layers.active = baked
    render.active_render = True
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), dtype=bool))
    mesh.normals_split_custom_set(join["normal"].astype(np.float32))
    for mat in materials:
        mesh.materials.append(mat)
    obj = bpy.data.objects.new(atlas.name, mesh)
    scene.collection.objects.link(obj)
    return obj


def stand_in(state, atlases, targets, uv_plans, depsgraph, scene):
    """Each atlas's temporary mesh standing in for its objects, which are hidden from
    render meanwhile (``state`` puts them back and removes the meshes on exit).
    Returns ``{atlas name: object}``."""
    by_name = {o.name: o for o in targets}
    uv_names = {name: plan.uv_name for name, plan in uv_plans.items()}
    made = {}
    for atlas in atlases:
        obj = build_atlas_object(atlas, by_name, uv_names, depsgraph, scene)
        state.push(lambda o=obj: remove_atlas_object(o))
        made[atlas.name] = obj
        for name in atlas.cells:
            state.set(by_name[name], "hide_render", True)
    return made


def cut(state, scene, atlas, entries):
    """Each object's maps cut from an atlas's finished maps.

    ``entries``: ``{group name: (group, atlas image, [object names baked for it])}``.
    Returns ``{object name: {group name: (group, image)}}`` (temporary images of
    ``state``); the atlas images are removed.
    """
    maps = {}
    n = atlas.size
    for group_name, (group, image, names) in entries.items():
        px = np.empty(n * n * 4, dtype=np.float32)
        image.pixels.foreach_get(px)
        px = px.reshape(n, n, 4)
        for name in names:
            cell = atlas.cells[name]
            part = state.new_image(f"{name}_{group_name}", cell[2])
            part.pixels.foreach_set(np.ascontiguousarray(crop(px, cell)).ravel())
            stamp(part, scene, group)
            maps.setdefault(name, {})[group_name] = (group, part)
        state.temp_images.remove(image)   # its texels are in the objects' maps
        bpy.data.images.remove(image)
    return maps


def remove_atlas_object(obj):
    """Delete a temporary atlas mesh and its object."""
    mesh = obj.data
    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(mesh)


def crop(pixels, cell):
    """The ``(n, n, C)`` map of one object cut from the atlas ``pixels`` (S, S, C)."""
    x, y, n = cell
    return pixels[y:y + n, x:x + n]


class Batches:
    """The atlases of one bake (:func:`plan_for`) and their temporary meshes."""

    def __init__(self, targets, sizes, groups, margin, batch):
        self.atlases = plan_for(targets, sizes, groups, margin, batch)
        self.of = {name: atlas for atlas in self.atlases for name in atlas.cells}
        self.objects = {}

    def stand_in(self, state, targets, uv_plans, depsgraph, scene, view_layer):
        """Build the temporary meshes (:func:`stand_in`); returns the depsgraph to use."""
        self.objects = stand_in(state, self.atlases, targets, uv_plans, depsgraph, scene)
        if not self.atlases:
            return depsgraph
        view_layer.update()
        return bpy.context.evaluated_depsgraph_get()

    def geometry(self, depsgraph, margin):
        """``{temporary object name: TexelGeometry}`` of each atlas."""
        return {self.objects[a.name].name: texel_geometry(
            self.objects[a.name], depsgraph, ATLAS_UV, a.size, margin) for a in self.atlases}

    def split(self, objects):
        """``objects`` baked on their own, and ``[(atlas, temporary object)]`` standing in
        for the others."""
        alone = [o for o in objects if o.name not in self.of]
        atlases = {self.of[o.name].name: self.of[o.name] for o in objects if o.name in self.of}
        return alone, [(a, self.objects[a.name]) for a in atlases.values()]

    def units(self, objects, sizes):
        """What one Cycles call bakes for ``objects``: ``[(key, baked object, map width,
        [object names])]``, each object on its own (key: its name) or an atlas's temporary
        object for those of ``objects`` in it (key: the temporary object's name)."""
        alone, atlases = self.split(objects)
        names = {o.name for o in objects}
        return [(o.name, o, sizes[o.name], [o.name]) for o in alone] + [
            (obj.name, obj, a.size, [n for n in a.cells if n in names]) for a, obj in atlases]

    def key(self, name):
        """The key of the maps object ``name`` is baked in (:meth:`units`)."""
        atlas = self.of.get(name)
        return name if atlas is None else self.objects[atlas.name].name

    def atlas_of(self, key):
        """The :class:`Atlas` baked as the temporary object ``key``; None for an object."""
        return next((a for a in self.atlases if self.objects[a.name].name == key), None)

    def regions(self):
        """``{temporary object name: {object name: (rows, columns)}}``: each object's
        cell of each atlas, as slices (:attr:`.passes.Passes.regions`)."""
        return {self.objects[atlas.name].name: {
            name: (slice(y, y + n), slice(x, x + n)) for name, (x, y, n) in atlas.cells.items()}
            for atlas in self.atlases}

    def per_object(self, by_key, baked, by_region=None):
        """``{(key, group): value}`` as ``{(object name, group): value}``: each object's
        own value in ``by_region`` (its cell of an atlas), else its key's
        (``baked[key][group]``: ``(group, image, names)``)."""
        by_region = by_region or {}
        return {(name, group): by_region.get((name, group), value)
                for (key, group), value in by_key.items() for name in baked[key][group][2]}
