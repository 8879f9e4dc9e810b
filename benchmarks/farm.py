"""The farm job's figures: its tasks, their times and the one-machine bake, side by side.

Usage (from the repository root)::

    python benchmarks/farm.py [--scenes room hall] [--task-minutes M] [--hall-objects N]
        [--out out/farm_bench]

For each scene, saved to ``--out``:

* ``room``: the demo's room (``scenes/room.py``, tagged as ``scenes/demo.py`` does:
  annual daylight through the window, the table lamp), its maps at most 384 px as in
  the demo, the default quality (Final: 8 samples, denoised);
* ``hall``: a generated hall of ``--hall-objects`` objects (boxes, cylinders and
  spheres on plinths in rows) lit by a sun and two lamp groups (three light groups),
  64 texels per metre, the default quality.

the script runs, each in a process of its own as a farm would (``python -m
lightfade_addon scene ...``, the same code as ``blender -c lightfade``):

1. ``farm-job --task-minutes M``: the tasks and the estimate of each (from the bake's
   calibrated estimate, ``bake/sizing.py``);
2. every Bake task (``farm-bake``) one after the other, timed (wall clock, the process's
   start included), then ``farm-merge``;
3. the one-machine bake of the same file (``bake``), timed the same way;

and prints per scene: the tasks, their estimated and measured times, the sum of the
tasks against the one-machine bake (the cost of splitting: each task starts Blender,
opens the file and plans), the farm's wall time with one worker per task (the longest
task plus Merge), and the merged maps against the one-machine maps (mean ratio; the
largest difference of a texel).  Timings on a shared machine are noisy: the ratios in
one run are the figures to quote; ``--scenes hall`` alone keeps other work off the cores.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402

ADDON = "lightfade_addon"


def _enable():
    addon_utils.enable(ADDON, default_set=True)


def build_room(path):
    """The demo's room, tagged, with the demo's largest map size."""
    from scenes import room
    from scenes.tags import apply_tags

    room.build(resolution=256)
    _enable()
    scene = bpy.context.scene
    apply_tags(scene)
    scene.lightfade.bake_resolution = 384
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)


def _material(name, colour):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*colour, 1.0)
    mat.lightfade.enabled = True
    return mat


def _lamp(name, kind, energy, location, hours):
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    data.lightfade.hours_per_day = hours
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    return obj


def build_hall(path, count):
    """A hall of ``count`` objects in rows on plinths: a sun (8 h a day) and two lamp
    groups (ceiling lamps 12 h, spotlights on the first row 4 h)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    _enable()
    mats = [_material(f"Paint{i}", c) for i, c in enumerate(
        [(0.8, 0.2, 0.2), (0.2, 0.5, 0.8), (0.9, 0.8, 0.3), (0.3, 0.7, 0.3)])]
    cols = 8
    rows = math.ceil(count / cols)
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0, 0, 0))
    floor = bpy.context.active_object
    floor.name = "Floor"
    floor.scale = (cols * 1.5 + 2, rows * 1.5 + 2, 1)
    bpy.ops.object.transform_apply(scale=True)
    floor.data.materials.append(mats[0])
    shapes = (bpy.ops.mesh.primitive_cube_add, bpy.ops.mesh.primitive_cylinder_add,
              bpy.ops.mesh.primitive_uv_sphere_add)
    for i in range(count):
        x = (i % cols - (cols - 1) / 2) * 1.5
        y = (i // cols - (rows - 1) / 2) * 1.5
        shapes[i % 3](location=(x, y, 0.45))
        obj = bpy.context.active_object
        obj.name = f"Piece{i:03d}"
        obj.scale = (0.4, 0.4, 0.4)
        obj.data.materials.append(mats[(i + 1) % len(mats)])
    sun = _lamp("Sun", "SUN", 3.0, (0, 0, 10), 8.0)
    sun.rotation_euler = (math.radians(35), 0, math.radians(20))
    for k in range(max(1, rows // 2)):
        _lamp(f"Ceiling{k}", "AREA", 400.0, (0, (k - rows / 4) * 3.0, 4.0), 12.0)
    for k in range(min(cols, 4)):
        _lamp(f"Spot{k}", "POINT", 150.0, ((k - 1.5) * 3.0, -rows * 0.75, 2.0), 4.0)
    scene = bpy.context.scene
    scene.lightfade_bake.texels_per_metre = 64.0
    scene.lightfade.bake_resolution = 256
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)


def _run(args, cwd):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", ADDON, "scene", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, args[:2]))} failed:\n{proc.stdout[-3000:]}\n"
                         f"{proc.stderr[-3000:]}")
    return seconds, proc.stdout


def _plan(bundle):
    import yaml

    template = yaml.safe_load((bundle / "template.yaml").read_text())
    merge = next(s for s in template["steps"] if s["name"] == "Merge")
    return json.loads(merge["script"]["embeddedFiles"][0]["data"])


def _maps(path):
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    found = {}
    for obj in bpy.context.scene.objects:
        for item in obj.lightfade.exposure_maps if obj.type == "MESH" else ():
            w, h = item.image.size
            px = np.empty(w * h * 4, dtype=np.float32)
            item.image.pixels.foreach_get(px)
            found[obj.name, item.name] = px.reshape(h, w, 4)[..., 0]
    return found


def measure(name, blend, task_minutes, out):
    folder = blend.parent
    t_job, said = _run(["farm-job", blend, "--out", out / f"{name}_job", "--task-minutes",
                        task_minutes], folder)
    plan = _plan(out / f"{name}_job")
    (out / f"{name}_plan.json").write_text(json.dumps(plan))
    maps_dir = out / f"{name}_job" / "work" / "maps"
    tasks = []
    for group, _members in plan["groups"]:
        for chunk in range(len(plan["chunks"])):
            s, _ = _run(["farm-bake", blend, "--plan", out / f"{name}_plan.json", "--group",
                         group, "--chunk", chunk, "--maps", maps_dir], folder)
            tasks.append((group, chunk, plan["seconds"][chunk], s))
            print(f"  {name}: Bake task Group={group} Chunk={chunk}: estimated "
                  f"{plan['seconds'][chunk]:.1f} s of bake, took {s:.1f} s", flush=True)
    merged = out / f"{name}_merged.blend"
    t_merge, _ = _run(["farm-merge", blend, "--plan", out / f"{name}_plan.json", "--maps",
                       maps_dir, "--output", merged], folder)
    t_one, _ = _run(["bake", blend, "--output", out / f"{name}_one.blend"], folder)
    farm, one = _maps(merged), _maps(out / f"{name}_one.blend")
    ratios = [float(farm[k].mean() / one[k].mean()) for k in one if one[k].mean() > 0]
    diff = max(float(np.abs(farm[k] - one[k]).max() / max(one[k].max(), 1e-9)) for k in one)
    measured = [t[3] for t in tasks]
    return {"scene": name, "objects": sum(len(c) for c in plan["chunks"]),
            "groups": len(plan["groups"]), "chunks": len(plan["chunks"]), "tasks": len(tasks),
            "estimate_task_max": max(plan["seconds"]), "task_min": min(measured),
            "task_median": float(np.median(measured)), "task_max": max(measured),
            "tasks_sum": sum(measured), "merge": t_merge, "job": t_job, "one_machine": t_one,
            "farm_wall": max(measured) + t_merge, "maps": len(one),
            "mean_ratio_min": min(ratios), "mean_ratio_max": max(ratios), "max_diff": diff,
            "same_keys": sorted(farm) == sorted(one),
            "identical": sum(bool(np.array_equal(farm[k], one[k])) for k in one)}


def report(rows, task_minutes):
    print(f"\nfarm job figures (--task-minutes {task_minutes:g}; wall clock, processes):")
    head = ("scene", "objects", "groups", "chunks", "tasks", "task s min/med/max", "tasks sum",
            "one machine", "sum/one", "merge", "farm wall*", "maps", "mean farm/one")
    print("  " + " | ".join(head))
    for r in rows:
        print("  " + " | ".join([
            r["scene"], str(r["objects"]), str(r["groups"]), str(r["chunks"]), str(r["tasks"]),
            f"{r['task_min']:.1f}/{r['task_median']:.1f}/{r['task_max']:.1f}",
            f"{r['tasks_sum']:.1f} s", f"{r['one_machine']:.1f} s",
            f"{r['tasks_sum'] / r['one_machine']:.2f}x", f"{r['merge']:.1f} s",
            f"{r['farm_wall']:.1f} s", str(r["maps"]),
            f"{r['mean_ratio_min']:.4f}-{r['mean_ratio_max']:.4f} (max texel diff "
            f"{r['max_diff']:.2%} of the map's peak)"]))
    print("  * one worker per task: the longest Bake task, then Merge")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scenes", nargs="+", default=["room", "hall"], choices=["room", "hall"])
    p.add_argument("--task-minutes", type=float, default=0.5)
    p.add_argument("--hall-objects", type=int, default=48)
    p.add_argument("--out", default="out/farm_bench")
    args = p.parse_args(argv)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in args.scenes:
        blend = out / f"{name}.blend"
        if name == "room":
            build_room(blend)
        else:
            build_hall(blend, args.hall_objects)
        print(f"{name}: built {blend}", flush=True)
        rows.append(measure(name, blend, args.task_minutes, out))
    report(rows, args.task_minutes)
    (out / "figures.json").write_text(json.dumps(rows, indent=1))
    sys.stdout.flush()
    os._exit(0)   # the bpy 4.x module crashes at exit once the add-on is registered


if __name__ == "__main__":
    main()
