"""CPU time per years change and per frame: the material's aging against pixel writes.

    ./run py -m benchmarks.scrub            # 1, 5, 30 textures at 1024² and 2048²
    ./run py -m benchmarks.scrub --full     # and 4096²

For each texture size one plane gets a real aged copy (a photograph-like albedo, a box,
a sun and an incandescent lamp: two light spectra, exposure baked at 256², Age). For
N textures the plane and its aged copy are duplicated N times (each duplicate a real
aged copy of its own object, sharing the data images). Printed side by side:

* **new** — the years are one scene custom property the aged materials read: the
  process CPU time of ``api.set_years`` (it also checks every copy for staleness), of
  the slider (``scene.lightfade.years = y``) and of ``scene.frame_set`` with keyframed
  years, medians over 9 changes;
* **apply** — ``api.apply_aging`` now: the numpy evaluator (its blocks on two threads)
  and the pixel write, once per texture, when real aged images are wanted; CPU time of
  the process and wall time.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)
import addon_utils  # noqa: E402

from benchmarks.problem import synthetic_photo  # noqa: E402


def build(size):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    floor = bpy.context.active_object
    mat = bpy.data.materials.new("Print")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    image = bpy.data.images.new("Photo", size, size)
    rgba = np.ones((size, size, 4), np.float32)
    rgba[..., :3] = synthetic_photo(size, size)
    image.pixels.foreach_set(rgba.ravel())
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    mat.node_tree.links.new(tex.outputs["Color"],
                            mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    mat.lightfade.enabled = True
    floor.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.8, 0.8, 0.5))
    scene = bpy.context.scene
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 5.0
    sun.rotation_euler = (math.radians(35), 0, 0)
    scene.collection.objects.link(sun)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 200.0
    lamp.data.lightfade.spectrum = "INCANDESCENT"
    lamp.location = (-1.0, -1.0, 1.5)
    scene.collection.objects.link(lamp)
    scene.lightfade_bake.texels_per_metre = 64.0
    scene.lightfade.bake_samples = 8
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    bpy.ops.lightfade.bake_exposure()
    bpy.ops.lightfade.age(years=1.0)
    return scene, floor


def duplicate(scene, floor, n):
    """``n`` aged planes in all: linked duplicates of ``floor`` with their own aged copy."""
    from lightfade_addon.blender.aging.copies import copies_of

    (copy,) = copies_of(obj=floor)
    for k in range(n - 1):
        obj = floor.copy()
        obj.name = f"Floor.{k:03d}"
        scene.collection.objects.link(obj)
        twin = copy.copy()
        twin.lightfade.aged_object = obj
        twin.lightfade.signature = copy.lightfade.signature
        obj.material_slots[0].link = "OBJECT"
        obj.material_slots[0].material = twin


def cpu(fn, repeat=9):
    times = []
    for k in range(repeat):
        t0 = time.process_time()
        fn(k)
        times.append(time.process_time() - t0)
    return statistics.median(times)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="also 4096² textures")
    args = parser.parse_args(argv)
    from lightfade_addon import api

    sizes = (1024, 2048, 4096) if args.full else (1024, 2048)
    counts = (1, 5, 30)
    print(f"{'textures':>8} {'size':>6} {'new set_years':>13} {'new slider':>10} "
          f"{'new frame':>9} {'apply':>8}")
    for size in sizes:
        scene, floor = build(size)
        t0 = time.process_time()
        api.apply_aging(scene, 10.0)                 # reads the data images once
        first = time.process_time() - t0
        apply = cpu(lambda k: api.apply_aging(scene, 5.0 + k), repeat=3)
        walls = []
        for k in range(3):
            t0 = time.perf_counter()
            api.apply_aging(scene, 8.0 + k)
            walls.append(time.perf_counter() - t0)
        wall = min(walls)
        api.live_aging(scene)
        mt = size * size / 1e6
        print(f"{size}²: apply_aging {first:.2f} s the first time (table read), then "
              f"{apply * 1e3:.0f} ms CPU / {wall * 1e3:.0f} ms wall ({wall * 1e3 / mt:.0f} ms "
              f"per megatexel)")
        made = 1
        for n in counts:
            duplicate(scene, floor, n - made + 1) if n > made else None
            made = n
            years = np.linspace(2, 60, 9)
            t_set = cpu(lambda k: api.set_years(scene, years[k]))

            def slide(k):
                scene.lightfade.years = years[k]

            t_slider = cpu(slide)
            api.keyframe_years(scene, [(1, 0.0), (100, 60.0)])
            t_frame = cpu(lambda k: scene.frame_set(1 + 11 * k))
            scene.animation_data_clear()
            print(f"{n:>8} {size:>5}² {t_set * 1e3:>10.1f} ms {t_slider * 1e3:>7.2f} ms "
                  f"{t_frame * 1e3:>6.1f} ms {apply * n:>6.1f} s")
    print("target: a years change <= 50 ms CPU (issue 20);")
    print("apply = N x api.apply_aging of one texture, warm (numpy evaluator + pixel write).")


if __name__ == "__main__":
    main()
