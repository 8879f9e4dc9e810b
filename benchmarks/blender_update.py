"""Years-slider latency through Blender's image API, end to end.

    ./run py -m benchmarks.blender_update [--size 2048] [--lights 1]

A plane with a ``size``² photograph-like albedo, a box and a sun (plus a lamp with
``--lights 2``); exposure baked at 256² (resampled to the albedo), aged once; then the
years value is changed repeatedly through the same path as the slider
(``apply.update_scene``: the dose lookup, ``Image.pixels.foreach_set`` and
``Image.update``). Prints the median latency next to the pixel write alone, the
one-time preparation, and the process's peak memory.
"""

import argparse
import math
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402
import addon_utils  # noqa: E402

from benchmarks.problem import synthetic_photo  # noqa: E402


def build(size, lights):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    floor = bpy.context.active_object
    mat = bpy.data.materials.new("Print")
    image = bpy.data.images.new("Photo", size, size)
    rgba = np.ones((size, size, 4), np.float32)
    rgba[..., :3] = synthetic_photo(size, size)
    image.pixels.foreach_set(rgba.ravel())
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    mat.node_tree.links.new(tex.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    mat.lightfade.enabled = True
    floor.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.8, 0.8, 0.5))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 5.0
    sun.rotation_euler = (math.radians(35), 0, 0)
    bpy.context.scene.collection.objects.link(sun)
    if lights > 1:
        lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
        lamp.data.energy = 200.0
        lamp.data.lightfade.spectrum = "INCANDESCENT"
        lamp.location = (-1.0, -1.0, 1.5)
        bpy.context.scene.collection.objects.link(lamp)
    scene = bpy.context.scene
    scene.lightfade.bake_resolution = 256
    scene.lightfade.bake_samples = 8
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    return scene, mat


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=2048)
    parser.add_argument("--lights", type=int, default=1, choices=(1, 2))
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    from lightfade_addon.blender import apply
    from lightfade_addon.blender.copies import copies_of

    scene, mat = build(args.size, args.lights)
    t0 = time.perf_counter()
    bpy.ops.lightfade.bake_exposure()
    bake = time.perf_counter() - t0
    t0 = time.perf_counter()
    bpy.ops.lightfade.age(years=1.0)
    prep = time.perf_counter() - t0
    years = iter(np.linspace(2, 60, args.repeat))
    update = [apply.update_scene(scene, next(years)) for _ in range(args.repeat)]
    image = copies_of(mat)[0].lightfade.aged_image
    buf = np.empty(args.size * args.size * 4, np.float32)
    write = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        image.pixels.foreach_set(buf)
        image.update()
        write.append(time.perf_counter() - t0)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{args.size}² texture, {args.lights} light spectrum(s)")
    print(f"  exposure bake at 256², 8 samples: {bake:.1f} s")
    print(f"  Age (preparation, grid, first write): {prep:.1f} s")
    print(f"  slider update, end to end: median {statistics.median(update) * 1e3:.0f} ms "
          f"(target <= 300 ms)")
    print(f"  of which the pixel write (foreach_set + update): median "
          f"{statistics.median(write) * 1e3:.0f} ms")
    print(f"  peak memory of the process: {peak:.0f} MB")


if __name__ == "__main__":
    main()
