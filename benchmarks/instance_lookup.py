"""What the geometry-nodes tile lookup costs: a scatter evaluated with and without the
*LightFade Tiles* modifier (Sample Nearest by position), side by side, and the bake's
reading of the instances' positions.

    ./run py -m benchmarks.instance_lookup --counts 529 5041

Prints, per count, the best of ``--repeat`` evaluations of the scatter alone and with
the lookup (every instance given a tile), their ratio, and the time to read the
positions (:func:`lightfade_addon.blender.bake.instance_tiles.evaluated_instances`).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / "tests" / "blender"),
                str(Path(__file__).resolve().parents[1])]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks.instances import _scene  # noqa: E402


def _evaluate(obj, repeat):
    """Best time (ms) of re-evaluating ``obj`` ``repeat`` times."""
    times = []
    for _ in range(repeat):
        obj.update_tag()
        t0 = time.perf_counter()
        bpy.context.evaluated_depsgraph_get().update()
        times.append(time.perf_counter() - t0)
    return 1000.0 * min(times)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[529, 5041])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    from lightfade_addon.blender.bake import instance_tiles

    for count in args.counts:
        _scene_, scatter, _source = _scene(count, 4)
        plain = _evaluate(scatter, args.repeat)
        t0 = time.perf_counter()
        positions, _ = instance_tiles.evaluated_instances(scatter)
        read = 1000.0 * (time.perf_counter() - t0)
        rects = np.random.default_rng(0).random((len(positions), 3))
        instance_tiles.write(scatter, "lf_tile_bench", positions, rects)
        tiled = _evaluate(scatter, args.repeat)
        _, back = instance_tiles.evaluated_instances(scatter, ("lf_tile_bench",))
        assert np.allclose(back["lf_tile_bench"], rects, atol=1e-6), "a tile was not found"
        print(f"{len(positions):6d} instances: scatter {plain:6.1f} ms, with the lookup "
              f"{tiled:6.1f} ms ({tiled / max(plain, 1e-6):.1f}x); positions read in "
              f"{read:5.1f} ms; every instance found its own tile")


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:])
