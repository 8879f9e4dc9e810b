"""A scatter of small objects baked as geometry-nodes instances against the same objects
made real (linked duplicates, one bake target each), side by side in one run.

    ./run py -m benchmarks.instances [--counts 50 500] [--samples 16]

A 10 m floor under a sun; a 6 cm box with its own UVs and an aged material scattered on
a grid by geometry nodes.  For each count the scatter is baked as instances (one stand-in
object holding every placement, its map the atlas: one Cycles bake per light group) and
then as real objects (the instances made real: one linked duplicate per instance, as a
user would have to before issue 37).  Printed: the texels each bakes, the estimate before
the bake, the seconds, and the ratios.  The instances' time should follow their texels;
the real objects' adds each object's overhead in Cycles' bake loop.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)
import addon_utils  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "blender"))
from conftest import add_sun, reset_file  # noqa: E402

from scenes.instanced_chairs import _box  # noqa: E402


def _pebble():
    verts, faces, uvs = [], [], []
    _box(verts, faces, uvs, (0.0, 0.0, 0.03), (0.06, 0.06, 0.06), (0, 3))
    mesh = bpy.data.meshes.new("Pebble")
    mesh.from_pydata(verts, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    layer.data.foreach_set("uv", [c for uv in uvs for c in uv])
    mat = bpy.data.materials.new("Pebble Paint")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    mat.lightfade.enabled = True
    mesh.materials.append(mat)
    obj = bpy.data.objects.new("Pebble", mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.hide_viewport = obj.hide_render = True
    return obj


def _scatter(source, count):
    side = math.ceil(math.sqrt(count))
    tree = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    for io in ("INPUT", "OUTPUT"):
        tree.interface.new_socket("Geometry", in_out=io, socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    grid = nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Size X"].default_value = grid.inputs["Size Y"].default_value = 8.0
    grid.inputs["Vertices X"].default_value = grid.inputs["Vertices Y"].default_value = side
    info = nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = source
    info.inputs["As Instance"].default_value = True
    place = nodes.new("GeometryNodeInstanceOnPoints")
    links.new(grid.outputs["Mesh"], place.inputs["Points"])
    links.new(info.outputs["Geometry"], place.inputs["Instance"])
    links.new(place.outputs[0], nodes.new("NodeGroupOutput").inputs[0])
    obj = bpy.data.objects.new("Scatter", bpy.data.meshes.new("Scatter"))
    bpy.context.scene.collection.objects.link(obj)
    obj.modifiers.new("Scatter", "NODES").node_group = tree
    return obj


def _scene(count, samples):
    reset_file()
    addon_utils.enable("lightfade_addon", default_set=True)
    bpy.ops.mesh.primitive_plane_add(size=10.0)
    add_sun()
    scene = bpy.context.scene
    scene.lightfade_bake.quality = "CUSTOM"
    scene.lightfade_bake.denoise = False
    scene.lightfade.bake_samples = samples
    source = _pebble()
    return scene, _scatter(source, count), source


def _bake(scene):
    from lightfade_addon.blender.bake import BakeSettings, ExposureBake

    job = ExposureBake(scene, settings=BakeSettings.from_scene(scene), report=lambda m: None,
                       progress=lambda f, m: None)
    job.plan()
    estimate = job.estimate()
    t0 = time.perf_counter()
    with job:
        while job.step():
            pass
        job.commit()
    return time.perf_counter() - t0, estimate


def _made_real(scene, scatter, source):
    """The scatter's instances as real objects sharing the source's mesh."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    matrices = [i.matrix_world.copy() for i in depsgraph.object_instances
                if i.is_instance and i.parent and i.parent.original == scatter]
    scatter.hide_viewport = scatter.hide_render = True
    for k, m in enumerate(matrices):
        obj = bpy.data.objects.new(f"Pebble.{k:04d}", source.data)
        scene.collection.objects.link(obj)
        obj.matrix_world = m
    return len(matrices)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[50, 500])
    parser.add_argument("--samples", type=int, default=16)
    args = parser.parse_args(argv)
    rows = []
    for count in args.counts:
        scene, scatter, source = _scene(count, args.samples)
        t_inst, est_inst = _bake(scene)
        n = _made_real(scene, scatter, source)
        t_real, est_real = _bake(scene)
        rows.append((n, est_inst, t_inst, est_real, t_real))
        print(f"{n:5d} instances: {est_inst.texels / 1e6:6.2f} Mtexels in "
              f"{est_inst.calls} Cycles call(s), {t_inst:6.1f} s  |  made real: "
              f"{est_real.texels / 1e6:6.2f} Mtexels, {t_real:6.1f} s  |  real / instances "
              f"{t_real / t_inst:4.1f}x", flush=True)
    if len(rows) > 1:
        (n0, e0, t0, _, r0), (n1, e1, t1, _, r1) = rows[0], rows[-1]
        print(f"{n1}/{n0} instances: texels x{e1.texels / e0.texels:.1f}, instances' time "
              f"x{t1 / t0:.1f}, real objects' time x{r1 / r0:.1f}")


if __name__ == "__main__":
    main()
