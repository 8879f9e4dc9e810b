"""Exposure bake: the defaults against the old settings, side by side in one run.

Usage (from the repository root; about 5 minutes on 2 cores)::

    python benchmarks/bake.py [--quick]

Part 1, the floor of issue 12: a 4 m floor with a 0.8 m box under a sun, baked with

* ``old``: 1024², 64 samples, no denoising (LightFade's former default);
* ``final``, ``preview``: the quality presets (texel density 256/m gives the 4 m floor
  1024² texels, as before).

Each is baked twice with different seeds.  Printed per setting: wall time, CPU time (all
threads), noise in the sunlit part and in the shadow only bounce light reaches (standard
deviation of the difference of the two seeds over √2, relative to the mean), bias of the
mean in both regions against the two old bakes averaged (128 samples), the 10-90 % width
of the shadow's side edge (texels, averaged along the edge), and seam bleed (bias of the
texels within 3 texels of the floor's UV island border).

Part 2, a small room: 5 objects, 5 lamps in 3 light groups.  Printed: the default bake
(one Cycles call per group, denoised), the same without denoising, a bare probe that calls
Cycles once per group with the same images and settings (the floor of what grouping can
cost), and the old way (one bake per object and lamp) at the same samples and sizes.
"""

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402
import addon_utils  # noqa: E402  (Blender's module: importable once bpy is)
import numpy as np  # noqa: E402


def timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def lux_of(image):
    w, h = image.size
    a = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(a)
    return a.reshape(h, w, 4)[..., 0].astype(np.float64)


def fresh():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)


def add_lamp(kind, name, energy, location=(0, 0, 0), rotation=(0, 0, 0), hours=8.0):
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    if kind == "SUN":
        data.angle = math.radians(0.5)
    else:
        data.shadow_soft_size = 0.05
    data.lightfade.hours_per_day = hours
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location, obj.rotation_euler = location, rotation
    return obj


def add_box(name, size, location, colour=None):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = size
    bpy.ops.object.transform_apply(scale=True)
    if colour is not None:
        mat = bpy.data.materials.new(name)
        if bpy.app.version < (5, 0, 0):
            mat.use_nodes = True
        mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*colour, 1.0)
        obj.data.materials.append(mat)
    return obj


# ----------------------------------------------------------------------- part 1: floor


def floor_scene():
    fresh()
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=20, y_subdivisions=20, size=4.0, calc_uvs=True)
    floor = bpy.context.active_object
    floor.name = "Floor"
    add_box("Box", (0.8, 0.8, 0.8), (0.5, 0.5, 0.4))
    add_lamp("SUN", "Sun", 3.0, rotation=(math.radians(35), 0, 0))
    return floor


def regions(n):
    """Masks on the 4 m floor: open sun, bounce-lit shadow, the edge rows, the island rim."""
    c = (np.arange(n) + 0.5) / n * 4 - 2
    y, x = np.meshgrid(c, c, indexing="ij")
    lit = (y < -0.5) & (np.abs(x) < 1.8) & (y > -1.8)
    # The box spans x, y in [0.1, 0.9]; the sun (35° toward +y) casts its shadow to
    # y = 0.9 + 0.8 tan 35° = 1.46.
    shadow = (x > 0.2) & (x < 0.8) & (y > 0.95) & (y < 1.4)
    edge_rows = (y > 1.0) & (y < 1.35)
    rim = np.zeros((n, n), bool)
    rim[:3], rim[-3:], rim[:, :3], rim[:, -3:] = True, True, True, True
    near_rim = np.zeros((n, n), bool)
    near_rim[8:11, 8:-8] = near_rim[-11:-8, 8:-8] = True
    return x, lit, shadow, edge_rows, rim & ~((np.abs(y) > 1.9) & (np.abs(x) > 1.9)), near_rim


def edge_width(lux, x, rows):
    """10-90 % width (texels) of the shadow's side edge at x = 0.9, rows averaged."""
    profile = lux[rows.any(axis=1)][:, :].mean(axis=0)
    xs = x[0]
    lo = profile[(xs > 0.6) & (xs < 0.8)].mean()
    hi = profile[(xs > 1.0) & (xs < 1.2)].mean()
    band = (xs > 0.7) & (xs < 1.1)
    p, q = (profile[band] - lo) / (hi - lo), np.arange(len(xs))[band]
    cross = [np.interp(level, np.maximum.accumulate(p), q) for level in (0.1, 0.9)]
    return cross[1] - cross[0]


def part_floor(quick):
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure

    floor = floor_scene()
    scene = bpy.context.scene
    configs = {
        "old 1024²/64": BakeSettings(resolution=1024, samples=64, margin=16, denoise=False),
        "final": BakeSettings.from_scene(scene),
        "preview": BakeSettings.from_scene(scene),
    }
    scene.lightfade_bake.quality = "PREVIEW"
    configs["preview"] = BakeSettings.from_scene(scene)
    if quick:
        configs["old 1024²/64"].samples = 16
    maps, stats = {}, {}
    for name, settings in configs.items():
        runs = []
        for seed in (1, 2):
            settings.seed = seed
            result, wall, cpu = timed(lambda s=settings: bake_exposure(
                scene, [floor], s, progress=lambda f, m: None))
            runs.append((lux_of(result["maps"]["Floor"]["Sun"]), wall, cpu))
        maps[name] = [r[0] for r in runs]
        stats[name] = (np.mean([r[1] for r in runs]), np.mean([r[2] for r in runs]))
        print(f"  baked {name}: {stats[name][0]:.1f} s", flush=True)
    ref = sum(maps["old 1024²/64"]) / 2
    n = ref.shape[0]
    x, lit, shadow, rows, rim, near_rim = regions(n)
    old_wall, old_cpu = stats["old 1024²/64"]
    print()
    print(f"Floor 4 m, box, sun; {n}² texels; 2 seeds each; reference = the two old bakes averaged")
    head = ("setting", "wall s", "CPU s", "x time", "noise lit", "noise shadow", "bias lit",
            "bias shadow", "edge px", "seam bleed")
    print("{:<14}{:>8}{:>8}{:>8}{:>11}{:>14}{:>10}{:>13}{:>9}{:>12}".format(*head))
    for name, (a, b) in maps.items():
        wall, cpu = stats[name]
        noise = [np.std((a - b)[m]) / math.sqrt(2) / np.mean(a[m]) for m in (lit, shadow)]
        mean = (a + b) / 2
        bias = [np.mean(mean[m]) / np.mean(ref[m]) - 1 for m in (lit, shadow)]
        bleed = np.mean(mean[rim]) / np.mean(mean[near_rim]) - np.mean(ref[rim]) / np.mean(ref[near_rim])
        print(f"{name:<14}{wall:>8.1f}{cpu:>8.1f}{wall / old_wall:>8.2f}{noise[0]:>11.2%}"
              f"{noise[1]:>14.2%}{bias[0]:>+10.2%}{bias[1]:>+13.2%}"
              f"{edge_width(mean, x, rows):>9.2f}{bleed:>+12.2%}")
    print("(bias and seam bleed of 'old' are against itself: 0 by construction)")


# ----------------------------------------------------------------------- part 2: room


def room_scene():
    fresh()
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    bpy.context.active_object.name = "Floor"
    bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0, 2, 1.25), rotation=(math.radians(90), 0, 0))
    wall = bpy.context.active_object
    wall.name = "Wall"
    wall.scale = (1, 0.625, 1)
    add_box("Sofa", (2.0, 0.9, 0.8), (0.0, 1.4, 0.4), colour=(0.1, 0.5, 0.15))
    add_box("Table", (1.0, 0.6, 0.7), (0.3, -0.3, 0.35), colour=(0.5, 0.3, 0.15))
    add_box("Shelf", (0.4, 0.3, 1.6), (-1.6, 1.7, 0.8), colour=(0.8, 0.8, 0.75))
    add_lamp("SUN", "Sun", 3.0, rotation=(math.radians(-40), 0, math.radians(15)))
    add_lamp("SUN", "Sun.001", 1.0, rotation=(math.radians(-30), 0, math.radians(-10)))
    add_lamp("POINT", "Bulb", 60.0, location=(-1.0, 0.0, 2.3))
    add_lamp("POINT", "Bulb.001", 60.0, location=(1.0, 0.0, 2.3))
    add_lamp("SPOT", "Reading", 40.0, location=(1.5, 1.0, 2.0), hours=2.0)
    objects = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    return objects


def probe(job):
    """One bare Cycles call per group with the job's images and settings (no checks,
    no denoising, nothing stored): what grouping costs at the least."""
    from lightfade_addon.blender.bake.emitters import isolate
    from lightfade_addon.blender.bake.state import BakeState
    from lightfade_addon.blender.bake.targets import attach_targets

    scene, layer = job.scene, job.view_layer
    with BakeState(scene, layer) as state:
        state.configure(job.settings.samples, job.settings.margin, job.settings.seed)
        nodes = attach_targets(state, job.targets)
        for step in (s for s in job.steps if s.index == 0):  # one call per group
            with BakeState(scene, layer) as inner:
                isolate(inner, scene, step.group)
                for obj in step.objects:
                    image = state.new_image(obj.name, job.sizes[obj.name])
                    for node in nodes[obj.name]:
                        node.image = image
                inner.select_only(step.objects)
                state.bake()


def part_room(quick):
    from lightfade_addon.blender.bake import BakeSettings, ExposureBake, bake_exposure

    objects = room_scene()
    scene = bpy.context.scene
    settings = BakeSettings.from_scene(scene)
    settings.texels_per_metre = 64 if quick else 128
    quiet = {"progress": lambda f, m: None, "report": lambda m: None}
    job = ExposureBake(scene, objects, settings, **quiet).plan()
    groups = [(s.group.name, len(s.objects)) for s in job.steps]
    texels = sum(job.sizes[o.name] ** 2 for o in objects)
    print()
    print(f"Room: {len(objects)} objects, {len(job.emitters)} lamps in {len(job.groups)} groups "
          f"{groups}; {texels / 1e6:.2f} M texels, {settings.samples} samples")
    rows = []
    _, wall, cpu = timed(lambda: bake_exposure(scene, objects, settings, **quiet))
    rows.append(("default (denoised)", wall, cpu, len(job.steps)))
    plain = BakeSettings(**{**settings.__dict__, "denoise": False})
    _, wall, cpu = timed(lambda: bake_exposure(scene, objects, plain, **quiet))
    rows.append(("same, no denoise", wall, cpu, len(job.steps)))
    _, wall, cpu = timed(lambda: probe(job))
    rows.append(("Cycles probe", wall, cpu, len(job.steps)))
    lamps = [o for o in scene.objects if o.type == "LIGHT"]
    for i, lamp in enumerate(lamps):  # every lamp its own group: the old way
        lamp.data.lightfade.days_per_year = 365 - 0.01 * i

    def per_lamp():
        for obj in objects:
            bake_exposure(scene, [obj], plain, **quiet)

    _, wall, cpu = timed(per_lamp)
    rows.append(("old: per object×lamp", wall, cpu, len(objects) * len(lamps)))
    probe_wall = rows[2][1]
    print("{:<24}{:>8}{:>8}{:>8}{:>12}".format("room bake", "wall s", "CPU s", "calls", "÷ probe"))
    for name, wall, cpu, calls in rows:
        print(f"{name:<24}{wall:>8.1f}{cpu:>8.1f}{calls:>8}{wall / probe_wall:>12.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="16 instead of 64 old samples, a coarser room (a smoke run)")
    parser.add_argument("--part", choices=("floor", "room", "all"), default="all")
    args = parser.parse_args()
    if args.part in ("floor", "all"):
        part_floor(args.quick)
    if args.part in ("room", "all"):
        part_room(args.quick)


if __name__ == "__main__":
    main()
