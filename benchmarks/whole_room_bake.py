"""The whole furnished room: the default (adaptive) bake's cost against the fixed 8-sample
bake, side by side in one run, with the noise each object reached.

Usage (from the repository root; the assets are not part of the repository; about 10
minutes on 2 quiet cores)::

    python benchmarks/whole_room_bake.py ASSET_DIR [--seed 0] [--repeat 1]
    python benchmarks/whole_room_bake.py ASSET_DIR --targets 0.12,0.15,0.2   # the choice

``tools/furnished_room.py``'s room (Drake's furnished living room: 14 objects, about
13 M texels at the scene's default density, annual daylight at 52° N through one
window) is baked whole, first at the fixed 8 samples (the Custom quality, denoised: the
Final preset before the adaptive bake, issue 36's "today's default") and then with the
default Final preset, ``--repeat`` times alternated (after one small bake that warms the
sky map and Cycles' kernels).  Printed: each bake's wall and CPU seconds and the CPU
ratio (target: at most 1.6), the CPU by kind of work (the Cycles operator, the reading
back and denoising of each finished pass, the 3D filter, the raw bound and the measurement), and per object the noise the default bake reached
(p95 per lit texel, the error of its mean), its samples and passes, and whether it hit
the cap.  Only the CPU ratio counts on a shared machine.  ``--targets`` bakes the Final
preset once per per-texel noise target given (the fixed bake once, first) and prints,
for each, the CPU ratio, the Cycles calls and the samples and noise of every object:
what a looser or tighter target would cost.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402


@contextlib.contextmanager
def cpu_by_kind(totals):
    """Add the CPU seconds of the bake's Cycles calls (the operator), denoising (each
    finished pass), 3D filter, the raw bound of the first passes and measurement to
    ``totals`` while inside (the functions are wrapped, then put back)."""
    from lightfade_addon.blender.bake import filter3d, passes, state

    wrapped = [(state.BakeState, "bake", "Cycles"),
               (passes.Passes, "_denoised", "denoise"),
               (filter3d, "smooth_on_surface", "3D filter"),
               (passes.Passes, "_clean_by_raw", "raw bound"),
               (passes.Passes, "measure", "measure")]
    originals = [getattr(cls, name) for cls, name, _ in wrapped]

    def timed(fn, kind):
        def call(*args, **kwargs):
            totals[kind + " calls"] += 1
            start = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                totals[kind] += time.process_time() - start
        return call

    try:
        for (cls, name, kind), fn in zip(wrapped, originals):
            setattr(cls, name, timed(fn, kind))
        yield totals
    finally:
        for (cls, name, _), fn in zip(wrapped, originals):
            setattr(cls, name, fn)


def bake(scene, objects, quality, seed, target=None):
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure

    scene.lightfade_bake.quality = quality
    scene.lightfade.bake_samples = 8
    settings = BakeSettings.from_scene(scene)
    settings.seed = seed
    if target is not None:
        settings.noise_target = target
    kinds = collections.defaultdict(float)
    with cpu_by_kind(kinds):
        wall, cpu = time.perf_counter(), time.process_time()
        result = bake_exposure(scene, objects, settings, report=lambda m: None,
                               progress=lambda f, m: None)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return result, wall, cpu, kinds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("assets", help="directory of the glTF models (tools/furnished_room.py)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--repeat", type=int, default=1, help="alternated runs of each bake")
    parser.add_argument("--targets", default="",
                        help="comma-separated per-texel noise targets (p95, fractions) for "
                             "the Final bake: one bake each, against one fixed bake")
    args = parser.parse_args()

    from tools import furnished_room
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure, find_targets

    furnished_room.build(args.assets)
    scene = bpy.context.scene
    objects = list(find_targets(scene))
    bake_exposure(scene, objects[:1], BakeSettings.from_scene(scene),   # warm: sky, kernels
                  report=lambda m: None, progress=lambda f, m: None)
    if args.targets:
        return compare_targets(scene, objects, args.seed,
                               [float(t) for t in args.targets.split(",")])
    cost = {"fixed 8 (CUSTOM)": [0.0, 0.0, collections.Counter()],
            "default (FINAL)": [0.0, 0.0, collections.Counter()]}
    noise = {}
    for _ in range(max(args.repeat, 1)):
        for label, quality in (("fixed 8 (CUSTOM)", "CUSTOM"), ("default (FINAL)", "FINAL")):
            result, wall, cpu, kinds = bake(scene, objects, quality, args.seed)
            cost[label][0] += wall
            cost[label][1] += cpu
            cost[label][2].update(kinds)
            noise = result.get("noise") or noise
            print(f"  {label}: wall {wall:.1f} s, CPU {cpu:.1f} s", flush=True)
    print(f"\nFurnished room: {len(objects)} objects, {args.repeat} run(s) each, alternated")
    base = cost["fixed 8 (CUSTOM)"][1]
    kinds = sorted({k for _, _, c in cost.values() for k in c})
    print(f"{'bake':<20}{'wall s':>9}{'CPU s':>9}{'CPU ÷ fixed':>13}"
          + "".join(f"{k:>22}" for k in kinds))
    for label, (wall, cpu, by_kind) in cost.items():
        print(f"{label:<20}{wall:>9.1f}{cpu:>9.1f}{cpu / base:>13.2f}"
              + "".join(f"{by_kind[k]:>22.1f}" for k in kinds))
    print(f"\n{'object <- group':<48}{'p95':>7}{'mean':>8}{'spp':>6}{'passes':>8}  cap"
          "  (≤: a bound from the raw first passes, finished once)")
    for (obj, group), found in noise.items():
        p95 = "-" if found.p95 is None else f"{'≤' if found.bound else ''}{found.p95:.1%}"
        mean = "-" if found.mean is None else f"{found.mean:.2%}"
        print(f"{obj + ' <- ' + group:<48}{p95:>7}{mean:>8}{found.samples:>6}"
              f"{found.passes:>8}  {'hit' if found.capped else ''}")



def compare_targets(scene, objects, seed, targets):
    """The fixed bake once, then Final at each of ``targets``: cost ratio, calls, and
    each object's samples and noise per target."""
    _, _, base, kinds = bake(scene, objects, "CUSTOM", seed)
    print(f"  fixed 8: CPU {base:.1f} s ({kinds['Cycles calls']:.0f} Cycles calls)", flush=True)
    rows, found = [], {}
    for target in targets:
        result, wall, cpu, kinds = bake(scene, objects, "FINAL", seed, target)
        rows.append((target, cpu, kinds["Cycles calls"], kinds["denoise calls"]))
        found[target] = result["noise"]
        print(f"  Final at {target:.0%}: wall {wall:.1f} s, CPU {cpu:.1f} s", flush=True)
    print(f"\n{'per-texel target (p95)':<26}{'CPU s':>8}{'CPU ÷ fixed':>13}{'Cycles calls':>14}"
          f"{'denoisings':>12}")
    print(f"{'fixed 8':<26}{base:>8.1f}{1.0:>13.2f}")
    for target, cpu, calls, denoised in rows:
        print(f"{target:<26.0%}{cpu:>8.1f}{cpu / base:>13.2f}{calls:>14.0f}{denoised:>12.0f}")
    print(f"\n{'object <- group':<48}" + "".join(f"{t:>16.0%}" for t in targets)
          + "   (samples, p95 reached)")
    for key in found[targets[0]]:
        print(f"{key[0] + ' <- ' + key[1]:<48}" + "".join(
            f"{found[t][key].samples:>6} {found[t][key].p95 or 0.0:>8.1%} " for t in targets))


if __name__ == "__main__":
    main()
