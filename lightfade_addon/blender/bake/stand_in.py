"""The stand-in an instanced source is baked as: one mesh holding it at every placement.

Built from the source's rendered mesh (modifiers applied) at each placement's world
matrix, its UVs moved into each placement's tile of the atlas (:mod:`.instances`), so
that one bake of one object gives the whole atlas.  While it exists the source is
invisible to every ray (its instances with it): neither shadows the stand-in twice.
"""

from __future__ import annotations

import bpy
import numpy as np

from .common import TEMP_PREFIX

#: Ray visibility flags an instance's source is hidden from while its stand-ins bake.
RAY_FLAGS = ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission",
             "visible_volume_scatter", "visible_shadow")


def _mesh_arrays(source, depsgraph, uv_name):
    """The source's mesh as rendered (object space): vertices (V, 3), faces (list of
    vertex tuples), UVs per loop (L, 2) in ``uv_name``, material index and smooth flag
    per face."""
    obj_eval = source.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
        mesh.vertices.foreach_get("co", co)
        loops = np.empty(len(mesh.loops), dtype=np.int64)
        mesh.loops.foreach_get("vertex_index", loops)
        start = np.empty(len(mesh.polygons), dtype=np.int64)
        total = np.empty(len(mesh.polygons), dtype=np.int64)
        mesh.polygons.foreach_get("loop_start", start)
        mesh.polygons.foreach_get("loop_total", total)
        uv = np.empty(len(mesh.loops) * 2, dtype=np.float64)
        mesh.uv_layers[uv_name].data.foreach_get("uv", uv)
        material = np.empty(len(mesh.polygons), dtype=np.int64)
        mesh.polygons.foreach_get("material_index", material)
        smooth = np.empty(len(mesh.polygons), dtype=bool)
        mesh.polygons.foreach_get("use_smooth", smooth)
    finally:
        obj_eval.to_mesh_clear()
    faces = [tuple(loops[a:a + n]) for a, n in zip(start, total)]
    return co.reshape(-1, 3), faces, uv.reshape(-1, 2), material, smooth


def stand_in_mesh(plan, depsgraph):
    """One mesh holding the source at every placement (world space), its UVs in
    ``plan.uv.uv_name`` moved into each placement's tile: baked once, it *is* the atlas."""
    uv_name = plan.uv.uv_name
    co, faces, uv, material, smooth = _mesh_arrays(plan.source, depsgraph, uv_name)
    n = len(plan.placements)
    homogeneous = np.c_[co, np.ones(len(co))]
    verts = np.concatenate([homogeneous @ np.array(p.matrix).T for p in plan.placements])[:, :3]
    rects = np.array([plan.rect(k) for k in range(n)])
    uvs = np.concatenate([uv * r[2] + r[:2] for r in rects])
    mesh = bpy.data.meshes.new(f"{TEMP_PREFIX}{plan.source.name}")
    mesh.from_pydata(verts.tolist(), [], [tuple(v + k * len(co) for v in f)
                                         for k in range(n) for f in faces])
    layer = mesh.uv_layers.new(name=uv_name)
    layer.data.foreach_set("uv", uvs.astype(np.float32).ravel())
    mesh.polygons.foreach_set("material_index", np.tile(material, n).astype(np.int32))
    mesh.polygons.foreach_set("use_smooth", np.tile(smooth, n))
    mesh.update()
    for slot in plan.source.material_slots:
        mesh.materials.append(slot.material)
    return mesh


def add_stand_in(state, scene, plan, depsgraph):
    """A temporary object holding the source at every placement (:func:`stand_in_mesh`),
    baked in their place; the source hidden from every ray meanwhile (its instances with
    it).  Both undone on exit of ``state``."""
    source = plan.source
    flags = {f: getattr(source, f) for f in RAY_FLAGS if hasattr(source, f)}
    for flag in flags:
        state.set(source, flag, False)
    mesh = stand_in_mesh(plan, depsgraph)
    obj = bpy.data.objects.new(mesh.name, mesh)
    for flag, value in flags.items():
        setattr(obj, flag, value)
    scene.collection.objects.link(obj)

    def remove():
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)

    state.push(remove)
    plan.stand_in = obj
    return obj
