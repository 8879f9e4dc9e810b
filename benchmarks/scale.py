"""What a scene's size costs: many objects, many UV islands, an apartment; side by side.

Usage (from the repository root)::

    python benchmarks/scale.py [--objects 10,100,300,1000] [--alone-max 100]
                               [--islands 10,100,1000,5000] [--apartment] [--quick]

Each case runs in its own process (so its peak memory is its own) and prints one row:

* ``objects N``: N small aged cubes (0.12 m, Blender's cube UVs) as separate objects on
  a floor under one sun, Preview quality, baked as the bake does it (small objects in
  atlases: ``bake/batch.py``); ``alone`` the same without batching (one Cycles object,
  map, denoise and filter per cube, as before: up to ``--alone-max`` objects, it grows
  as N²); ``one mesh`` the same cubes joined into one mesh with unique UVs, its map
  sized for the same texel density (the texels match within the atlas gaps).
* ``islands N``: one mesh of N cubes sharing one UV layout (a realized scatter):
  planning, making ``LightFadeUV`` (overlap checks, unwrap of folded islands, one pack),
  then the bake.
* ``apartment``: rooms of furniture-like boxes and small objects (hundreds), lamps in
  several light groups, annual daylight through windows (``scale_scenes.apartment``).

Columns: ``plan`` (checks, sizes, UV plans, atlases), ``prepare`` (UV maps made,
temporary meshes, texel geometry), ``bake`` (Cycles, denoising, 3D filter, storing),
``Age`` (aged copies, node groups), ``years`` (CPU of one years change), ``peak`` (the
process's peak memory), ``Mtexels`` (texels of the objects' maps), atlases, objects,
light groups, and the wall and CPU time (all threads: what a shared machine's load
does not change) against the one mesh's.  ``--quick``: 10 and 100 objects, 10 and 1000 islands, no apartment.
"""

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
# benchmarks/colour.py would hide the colour-science package the aging imports
sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != HERE]
sys.path.insert(0, str(HERE.parent))


def _fresh():
    import addon_utils
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)


def _clock():
    return time.perf_counter(), time.process_time()


def _since(start):
    wall, cpu = _clock()
    return round(wall - start[0], 3), round(cpu - start[1], 3)


def _bake(objects, batch=True, max_size=None, unwrap=False, density=None):
    """Plan, prepare, bake and store; times of each."""
    import bpy

    from lightfade_addon.blender.bake import BakeSettings, ExposureBake

    scene = bpy.context.scene
    scene.lightfade_bake.quality = "PREVIEW"
    if max_size:
        scene.lightfade.bake_resolution = max_size
    if density:
        scene.lightfade_bake.texels_per_metre = density
    settings = BakeSettings.from_scene(scene, unwrap=unwrap)
    out = {}
    t = _clock()
    job = ExposureBake(scene, objects, settings, report=lambda m: None,
                       progress=lambda f, m: None, batch=batch).plan()
    out["plan"] = _since(t)
    t = _clock()
    with job:
        out["prepare"] = _since(t)
        t = _clock()
        while job.step():
            pass
        job.commit()
    out["bake"] = _since(t)
    out["Mtexels"] = round(sum(job.sizes[o.name] ** 2 for o in job.targets) / 1e6, 3)
    out["atlases"] = len(job.batches.atlases)
    out["groups"] = len(job.groups)
    out["targets"] = len(job.targets)
    return out


def _age(out):
    import bpy

    from lightfade_addon import api

    t = _clock()
    api.age_scene(years=10.0)
    out["Age"] = _since(t)
    api.set_years(years=20.0)
    cpu = time.process_time()
    api.set_years(years=30.0)
    out["years_cpu_ms"] = round((time.process_time() - cpu) * 1000, 2)
    assert bpy.context.scene.lightfade.years == 30.0


def case(kind, n, density=None):
    """One row (a dict): run in a process of its own."""
    from benchmarks import scale_scenes

    _fresh()
    if kind == "objects":
        out = _bake(scale_scenes.separate_cubes(n))
    elif kind == "alone":
        out = _bake(scale_scenes.separate_cubes(n), batch=False)
    elif kind == "onemesh":
        obj = scale_scenes.joined_cubes(n)
        out = _bake([obj], max_size=8192)
    elif kind == "islands":
        obj = scale_scenes.joined_cubes(n, unique=False)
        out = _bake([obj], unwrap=True)
    elif kind == "apartment":
        objects = scale_scenes.apartment(rooms=n)
        out = _bake(objects, density=density)
    else:
        raise ValueError(kind)
    if kind != "islands":
        _age(out)
    out["peak_MB"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    out.update(kind=kind, n=n)
    return out


def run_case(kind, n, density=0):
    proc = subprocess.run([sys.executable, __file__, "--case", f"{kind}:{n}:{density}"],
                          capture_output=True, text=True)
    for line in proc.stdout.splitlines():
        if line.startswith("ROW "):
            return json.loads(line[4:])
    sys.stderr.write(proc.stdout[-3000:] + proc.stderr[-3000:])
    return {"kind": kind, "n": n, "error": proc.returncode}


STAGES = ("plan", "prepare", "bake")


def _total(row, which):
    return sum(row[k][which] for k in STAGES)


def _fmt(row, reference=None):
    if "error" in row:
        return f"{row['kind']:>9} {row['n']:>5}  failed (exit {row['error']})"
    cell = lambda key: (f"{row[key][0]:7.2f}/{row[key][1]:<6.2f}" if key in row else " " * 14)
    wall, cpu = _total(row, 0), _total(row, 1)
    ratio = (f"{wall / _total(reference, 0):5.2f}x /{cpu / _total(reference, 1):5.2f}x"
             if reference else "")
    years = f"{row['years_cpu_ms']:7.1f}" if "years_cpu_ms" in row else " " * 7
    return (f"{row['kind']:>9} {row['n']:>5} {cell('plan')} {cell('prepare')} {cell('bake')} "
            f"{cell('Age')} {years} {row['peak_MB']:7d} {row['Mtexels']:7.2f} "
            f"{row.get('atlases', 0):3d} {row.get('targets', 0):5d} {row.get('groups', 0):3d} "
            f"{wall:7.2f}/{cpu:<7.2f} {ratio}")


HEADER = (f"{'case':>9} {'N':>5} {'plan s wall/cpu':>14} {'prepare':>14} {'bake':>14} "
          f"{'Age':>14} {'yrs ms':>7} {'peak MB':>7} {'Mtexels':>7} {'atl':>3} {'objs':>5} "
          f"{'grp':>3} {'total wall/cpu':>15} {'vs one mesh wall / cpu'}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--objects", default="10,100,300,1000")
    parser.add_argument("--alone-max", type=int, default=100)
    parser.add_argument("--islands", default="10,100,1000,5000")
    parser.add_argument("--apartment", type=int, default=4, help="rooms (0: none)")
    parser.add_argument("--apartment-density", type=float, default=64.0,
                        help="texels per metre of the apartment's maps (the default 256 "
                        "bakes 16 times the texels)")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--case", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        kind, n, density = args.case.split(":")
        print("ROW " + json.dumps(case(kind, int(n), float(density) or None)), flush=True)
        return
    if args.quick:
        args.objects, args.islands, args.apartment = "10,100", "10,1000", 0
    print(HEADER)
    for n in [int(x) for x in args.objects.split(",") if x]:
        one = run_case("onemesh", n)
        ref = one if "error" not in one else None
        print(_fmt(one), flush=True)
        print(_fmt(run_case("objects", n), ref), flush=True)
        if n <= args.alone_max:
            print(_fmt(run_case("alone", n), ref), flush=True)
    for n in [int(x) for x in args.islands.split(",") if x]:
        print(_fmt(run_case("islands", n)), flush=True)
    if args.apartment:
        print(_fmt(run_case("apartment", args.apartment, args.apartment_density)), flush=True)


if __name__ == "__main__":
    main()
