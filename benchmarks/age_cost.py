"""What Age costs against the bake on a fresh machine (tables built), and where it goes.

    ./run py -m benchmarks.age_cost                  # the ten-material room of live_room
    ./run py -m benchmarks.age_cost --size 512 --profile 25
    ./run py -m benchmarks.age_cost --default-bake   # also the room's default bake (minutes)

The room of :mod:`benchmarks.live_room` (ten 1k materials, Printed Paper and Dyed
Fabric, a sun and an incandescent lamp: two spectra), baked at its settings, then aged
with an empty table cache and a fresh process's caches (the tables and their unmixing
``Φ`` built), then aged again (the tables found on disk). Printed side by side, in one
process: wall and process time of the bake and of both Ages, and the ratio of the cold
Age to the bake (target <= 0.25x), in wall and in process time: the bake is this
benchmark's light one (CUSTOM, 16 samples a texel); with ``--default-bake`` the same
room is also baked at a new scene's defaults (the Final preset's adaptive bake, what a
user's bake costs) and the cold Age is set against that too. With ``--profile N``: the
cold Age's N costliest functions (cProfile, cumulative; the profiler slows it).

Age runs as it does in Blender, where the extension ships colour-science, scipy and
typing_extensions only: this environment also has matplotlib and pandas (for the docs'
figures and pvlib), and colour-science imports both when they are there (its plotting
and I/O), which doubles the first Age's import of it (1.1 s against 0.57 s). They are
hidden from this process unless ``--dev-imports``.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402,F401  (first: it puts Blender's modules on the path)

from benchmarks.live_room import build, default_bake  # noqa: E402

#: Packages of this environment that the extension does not ship (module docstring).
NOT_SHIPPED = ("matplotlib", "pandas")


def _timed(fn, profile=None):
    """(wall s, process s) of ``fn()``."""
    c0, w0 = time.process_time(), time.perf_counter()
    if profile is not None:
        profile.enable()
    try:
        fn()
    finally:
        if profile is not None:
            profile.disable()
    return time.perf_counter() - w0, time.process_time() - c0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024, help="texture side (px)")
    parser.add_argument("--density", type=float, default=48.0, help="exposure texels per metre")
    parser.add_argument("--profile", type=int, default=0, metavar="N",
                        help="print the cold Age's N costliest functions")
    parser.add_argument("--default-bake", action="store_true",
                        help="also bake the room at the scene's defaults (Final preset)")
    parser.add_argument("--dev-imports", action="store_true",
                        help="let colour-science import matplotlib and pandas (not shipped)")
    args = parser.parse_args(argv)
    if not args.dev_imports:
        for name in NOT_SHIPPED:                 # an import of them now raises ImportError
            sys.modules.setdefault(name, None)
    from lightfade_addon import api
    from lightfade_addon.core.fading import cache

    folder = tempfile.mkdtemp(prefix="lf_age_")
    cache.set_directory(os.path.join(folder, "cache"))         # an empty table cache
    scene = build(args.size)
    scene.lightfade_bake.texels_per_metre = args.density
    scene.lightfade.bake_samples = 16
    bake = _timed(lambda: api.bake(scene, quality="CUSTOM", samples=16))
    profile = cProfile.Profile() if args.profile else None
    cold = _timed(lambda: api.age_scene(scene, years=25.0), profile)
    warm = _timed(lambda: api.age_scene(scene, years=25.0))
    tables = [i for i in bpy.data.images if i.name.startswith("LF_Table_")]
    print(f"room: 10 materials of {args.size}² under 2 spectra, {len(tables)} colour tables")
    print(f"bake (CUSTOM, 16 samples a texel, {args.density:g} texels/m) {bake[0]:7.1f} s wall "
          f"({bake[1]:6.1f} s process)")
    print(f"Age with tables built {cold[0]:6.1f} s wall ({cold[1]:6.1f} s process) | Age with "
          f"tables cached {warm[0]:5.1f} s wall ({warm[1]:5.1f} s process)")
    print(f"Age with tables built / the 16-sample bake: {cold[0] / bake[0]:.3f}x wall, "
          f"{cold[1] / bake[1]:.3f}x process (target <= 0.25x); tables cached: "
          f"{warm[0] / bake[0]:.3f}x wall")
    if args.default_bake:
        default = default_bake(args.size)
        print(f"Age with tables built / the default bake ({default[2]}): {cold[0] / default[0]:.3f}x "
              f"wall, {cold[1] / default[1]:.3f}x process")
    if profile is not None:
        pstats.Stats(profile).sort_stats("cumulative").print_stats(args.profile)


if __name__ == "__main__":
    main()
