"""Speed of the physics core against the paper's Table 3 and its 6.3-hour grid.

    ./run py -m benchmarks.speed            # everything (~3-5 minutes on 2 cores)
    ./run py -m benchmarks.speed --quick    # skip the 1024 x 625 reference grid

Prints, side by side in one run (medians of repeated runs; the machines are shared):

* the 6 x 6 x 6 CMY grid (216 samples) at the paper's reference setting,
  1024 layers x 625 steps, 41 wavelengths — the paper took 6.3 hours;
* the same grid at the production default (``simulate``'s defaults);
* the time per sample for each cell of Table 3 (one batch of 216 samples divided
  by 216) next to the paper's per-sample time, and the speedup.

The concentrations are those of the grid; the colourants are the bundled CMY dyes.
"""

from __future__ import annotations

import argparse
import inspect
import statistics
import time

import numpy as np

from lightfade_addon.core import simulate

#: Paper, Table 3: seconds per sample on one 2.8 GHz Xeon E5462 core.
PAPER_TABLE3 = {
    (2, 5): 0.6, (2, 25): 2.9, (2, 125): 14.0,
    (4, 5): 0.7, (4, 25): 3.2, (4, 125): 15.4,
    (8, 5): 0.8, (8, 25): 3.6, (8, 125): 17.6,
    (16, 5): 1.0, (16, 25): 4.4, (16, 125): 21.5,
    (32, 5): 1.5, (32, 25): 6.3, (32, 125): 30.7,
    (64, 5): 3.5, (64, 25): 15.8, (64, 125): 76.6,
    (128, 5): 8.6, (128, 25): 36.8, (128, 125): 179.0,
}
PAPER_GRID_SECONDS = 6.3 * 3600


def grid_problem(m=6):
    """The m^3 CMY concentration grid with the bundled dyes on paper under D65."""
    from benchmarks.problem import cmy_problem

    problem = cmy_problem()
    axis = np.linspace(0.0, 1.0, m)
    c = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    return problem, c


def timed(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="skip the 1024 x 625 grid")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measurement")
    args = parser.parse_args(argv)

    problem, c = grid_problem()
    defaults = {k: v.default for k, v in inspect.signature(simulate).parameters.items()
                if k in ("layers", "steps", "scheme")}
    print(f"216 samples (6x6x6 CMY grid), {problem['wavelengths'].size} wavelengths")

    def run(**kw):
        return simulate(concentrations=c, **problem, **kw)

    t, all_t = timed(lambda: run(**defaults), max(5, args.repeat))
    print(f"\nproduction default {defaults}: median {t:.3f} s  "
          f"(runs: {', '.join(f'{x:.3f}' for x in all_t)}; target <= 0.5 s)")
    t1, _ = timed(lambda: run(workers=1, **defaults), max(5, args.repeat))
    print(f"  same on one thread: median {t1:.3f} s")

    print("\nper-sample time, ours (216-sample batch / 216) vs the paper's Table 3, scheme 'paper'")
    print(f"{'layers':>6} {'steps':>5} {'ours ms':>9} {'paper s':>8} {'speedup':>9}")
    for (L, T), paper in PAPER_TABLE3.items():
        reps = args.repeat if L * T <= 2000 else 1
        t, _ = timed(lambda: run(layers=L, steps=T, scheme="paper"), reps)
        print(f"{L:>6} {T:>5} {t / 216 * 1e3:>9.3f} {paper:>8.1f} {paper / (t / 216):>9.0f}x")

    if not args.quick:
        print("\nreference grid: 216 samples at 1024 layers x 625 steps, scheme 'paper'")
        t, _ = timed(lambda: run(layers=1024, steps=625, scheme="paper"), 1)
        print(f"  {t:.1f} s (target <= 60 s; the paper: {PAPER_GRID_SECONDS / 3600:.1f} h, "
              f"speedup {PAPER_GRID_SECONDS / t:.0f}x)")


if __name__ == "__main__":
    main()
