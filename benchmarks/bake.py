"""Time and memory of one exposure bake: a 1024² map, one object, one emitter, 64 samples.

Usage: ``python benchmarks/bake.py [--resolution 1024] [--samples 64] [--subdivisions 20]``

The scene is a subdivided 4 m floor with a box lying on it under a sun (Cycles CPU, all
cores Blender sees).  Prints the wall time of the bake alone (Cycles + the conversion to
lux + packing) and of the whole call, the peak resident memory, and the map's own size.
"""

import argparse
import math
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402
import addon_utils  # noqa: E402  (Blender's module: importable once bpy is)


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, default=1024)
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--subdivisions", type=int, default=20, help="floor grid cuts")
    args = parser.parse_args()

    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure

    bpy.ops.mesh.primitive_grid_add(x_subdivisions=args.subdivisions, y_subdivisions=args.subdivisions,
                                    size=4.0, calc_uvs=True)
    floor = bpy.context.active_object
    floor.name = "Floor"
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.5, 0.5, 0.4))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(35), 0, math.radians(20))
    bpy.context.scene.collection.objects.link(sun)

    rss0 = peak_rss_mb()
    settings = BakeSettings(resolution=args.resolution, samples=args.samples, margin=16)
    t0 = time.perf_counter()
    result = bake_exposure(bpy.context.scene, [floor], settings, report=print)
    wall = time.perf_counter() - t0
    image = result["maps"]["Floor"]["Sun"]
    map_mb = image.size[0] * image.size[1] * 4 * 4 / 1e6
    texels = image.size[0] * image.size[1]
    print(f"bake {args.resolution}² x {args.samples} samples, 1 object x 1 emitter: "
          f"{result['seconds']:.2f} s in bake_exposure, {wall:.2f} s wall "
          f"({texels * args.samples / wall / 1e6:.2f} M texel-samples/s)")
    print(f"peak RSS {peak_rss_mb():.0f} MB (before the bake {rss0:.0f} MB, +{peak_rss_mb() - rss0:.0f} MB); "
          f"map {map_mb:.1f} MB float RGBA + packed EXR {image.packed_file.size / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
