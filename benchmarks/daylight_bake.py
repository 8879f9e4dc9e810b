"""Annual daylight bake against a one-sun bake of the same objects at the same quality.

Usage (from the repository root; about 2 minutes on 2 cores)::

    python benchmarks/daylight_bake.py [--quick] [--density 128] [--sky-width 512]

The room of ``scenes/daylight_room.py`` (4 × 4 m, a mullioned south window, a box and a
rug on the floor; floor, rug and box baked), 52° N, clear sky.  Baked with the scene's
default quality (Final: 8 samples, denoised), twice each with different seeds:

* ``one sun``: a sun lamp at noon at the equinox (38° up, due south), no place;
* ``annual``: the same objects and settings with the place set: one bake of the annual
  sky (the sky map itself is computed once per place and cached; its cost is printed
  on its own line);
* ``annual, 2× samples``: the same at 16 samples.

Printed per setting: wall and CPU time of the bake call (all threads), the ratio to the
one-sun bake, and the noise on the floor (standard deviation of the difference of the
two seeds over √2, relative to the mean, over texels above 20 % of the floor's maximum).
"""

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402


def timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def setup(density, sky_width):
    from scenes import daylight_room

    names = daylight_room.build()
    addon_utils.enable("lightfade_addon", default_set=True)
    scene = bpy.context.scene
    scene.lightfade_bake.texels_per_metre = density
    scene.lightfade.bake_resolution = 1024
    scene.lightfade_daylight.sky_width = sky_width
    bpy.context.view_layer.update()
    return scene, [scene.objects[names[k]] for k in ("floor", "rug", "box")]


def bake_twice(scene, objects, samples):
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure

    maps, walls, cpus = [], [], []
    for seed in (1, 2):
        settings = BakeSettings.from_scene(scene)
        settings.samples, settings.seed = samples, seed
        result, wall, cpu = timed(lambda s=settings: bake_exposure(
            scene, objects, s, report=lambda m: None, progress=lambda f, m: None))
        floor = result["maps"]["Floor"]
        image = next(iter(floor.values()))
        w, h = image.size
        px = np.empty(w * h * 4, np.float32)
        image.pixels.foreach_get(px)
        maps.append(px.reshape(h, w, 4)[..., 0].astype(np.float64))
        walls.append(wall)
        cpus.append(cpu)
    a, b = maps
    lit = (a + b) / 2 > 0.2 * ((a + b) / 2).max()
    noise = np.std((a - b)[lit]) / math.sqrt(2) / np.mean(((a + b) / 2)[lit])
    return np.mean(walls), np.mean(cpus), noise, a.shape


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="density 32/m, a 128-wide sky")
    parser.add_argument("--density", type=float, default=128.0, help="texels per metre")
    parser.add_argument("--sky-width", type=int, default=512)
    args = parser.parse_args()
    density, sky_width = (32.0, 128) if args.quick else (args.density, args.sky_width)

    from lightfade_addon import api
    from lightfade_addon.blender.daylight import place
    from scenes import daylight_room

    scene, objects = setup(density, sky_width)
    samples = 8 if scene.lightfade_bake.quality == "FINAL" else scene.lightfade.bake_samples
    daylight_room.static_sun()
    bpy.context.view_layer.update()
    rows = [("one sun", *bake_twice(scene, objects, samples))]
    api.set_daylight(scene, **daylight_room.PLACE)
    _, sky_wall, sky_cpu = timed(lambda: place.annual_sky(scene))
    rows.append(("annual", *bake_twice(scene, objects, samples)))
    rows.append(("annual, 2× samples", *bake_twice(scene, objects, 2 * samples)))

    shape = rows[0][4]
    print(f"\nRoom 4 m, mullioned south window, 52° N clear sky; floor {shape[0]}², rug, box; "
          f"{samples} samples, denoised; 2 seeds each")
    print(f"annual sky map {sky_width}×{sky_width // 2}: {sky_wall:.2f} s wall, "
          f"{sky_cpu:.2f} s CPU (once per place, cached)")
    print("{:<22}{:>8}{:>8}{:>12}{:>12}{:>12}".format("bake", "wall s", "CPU s", "÷ one sun",
                                                      "CPU ÷ sun", "noise"))
    sun_wall, sun_cpu = rows[0][1], rows[0][2]
    for name, wall, cpu, noise, _ in rows:
        print(f"{name:<22}{wall:>8.2f}{cpu:>8.2f}{wall / sun_wall:>12.2f}{cpu / sun_cpu:>12.2f}"
              f"{noise:>12.2%}")


if __name__ == "__main__":
    main()
