"""Derive LightFade's worldwide monthly Linke turbidity climatology from pvlib's file.

Run from the repository root (pvlib and h5py are test dependencies; the extension itself
only reads the small file this writes, with numpy)::

    .venv/bin/python tools/linke_turbidity.py                    # pvlib's LinkeTurbidities.h5
    .venv/bin/python tools/linke_turbidity.py --source FILE.h5   # another copy of it
    .venv/bin/python tools/linke_turbidity.py --step 0.5         # a finer grid (bigger file)

Source: ``LinkeTurbidities.h5``, shipped in ``pvlib/data`` with pvlib-python (BSD 3-Clause
licence): one 2160 × 4320 × 12 uint8 array, 20 × the Linke turbidity (air mass 2) on a
5' grid (rows from 90° N southwards, columns from 180° W eastwards), January to December:
the worldwide climatology of Remund, Wald, Lefèvre, Ranchin & Page (2003), "Worldwide
Linke turbidity information", Proc. ISES Solar World Congress, Göteborg, distributed by
the SoDa service (Mines ParisTech) and Meteotest.

Written: ``lightfade_addon/core/data/linke_turbidity.npz`` with

* ``tl20``: uint8 ``(12, 180 / step, 360 / step)``, 20 × the turbidity (as the source),
  each cell the mean of the source's 5' cells in a ``step``° square, rounded;
  row 0 centred at ``90 - step / 2`` ° N, column 0 at ``-180 + step / 2`` ° E;
* ``step_deg``: the cell size, degrees;
* ``source``, ``licence``: the lines above, kept with the numbers.

At the default 1° the file is about 300 kB; the script prints its size and how far the
file's values, read by :func:`lightfade_addon.core.daylight.clearsky.linke_turbidity`, are from
pvlib's own lookup (the nearest 5' cell) at a set of cities.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

OUT = ROOT / "lightfade_addon" / "core" / "data" / "linke_turbidity.npz"
SOURCE = ("LinkeTurbidities.h5 from pvlib-python {version} (pvlib/data): Remund, Wald, "
          "Lefevre, Ranchin & Page (2003), Worldwide Linke turbidity information, Proc. ISES "
          "Solar World Congress, Goteborg; SoDa service (Mines ParisTech) and Meteotest. "
          "Resampled by tools/linke_turbidity.py: mean of the 5' cells in each {step} deg "
          "cell, rounded to the source's unit (1/20).")
LICENCE = ("Distributed with pvlib-python under its BSD 3-Clause licence "
           "(https://github.com/pvlib/pvlib-python/blob/main/LICENSE).")

#: Cities for the check printed at the end (latitude, longitude).
CITIES = {
    "Berlin": (52.52, 13.405), "Madrid": (40.4168, -3.7038), "Cairo": (30.0444, 31.2357),
    "Singapore": (1.2903, 103.8519), "Denver": (39.7392, -104.9903),
    "Sydney": (-33.8688, 151.2093), "Reykjavik": (64.1466, -21.9426),
    "Mumbai": (19.076, 72.8777), "Lima": (-12.0464, -77.0428), "Beijing": (39.9042, 116.4074),
}


def pvlib_file():
    import pvlib

    return Path(pvlib.__file__).parent / "data" / "LinkeTurbidities.h5", pvlib.__version__


def resample(source, step):
    """Block means of the (2160, 4320, 12) 5' grid over ``step``° cells: uint8 (12, H, W)."""
    factor = int(round(step * 12))
    if factor < 1 or 2160 % factor or abs(factor / 12 - step) > 1e-9:
        raise SystemExit(f"--step {step}: must be a multiple of 1/12 degree dividing 180")
    h, w = 2160 // factor, 4320 // factor
    blocks = source.reshape(h, factor, w, factor, 12).astype(np.float64).mean(axis=(1, 3))
    return np.moveaxis(np.rint(blocks).astype(np.uint8), -1, 0)


def check(path):
    """Largest monthly |ΔT_L| of the written file against pvlib's lookup, per city."""
    import pandas as pd
    import pvlib

    from lightfade_addon.core.daylight import clearsky

    clearsky._climatology.cache_clear()
    times = pd.date_range("2025-01-15", periods=12, freq=pd.DateOffset(months=1))
    months = np.arange(1, 13)
    for name, (lat, lon) in CITIES.items():
        ref = pvlib.clearsky.lookup_linke_turbidity(times, lat, lon, interp_turbidity=False)
        ours = clearsky.linke_turbidity(lat, lon, months)
        d = ours - ref.to_numpy()
        print(f"{name:<10} annual mean {ref.mean():.2f} (pvlib) {ours.mean():.2f} (file), "
              f"largest monthly difference {np.abs(d).max():.2f}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, help="LinkeTurbidities.h5 (default: pvlib's)")
    parser.add_argument("--step", type=float, default=1.0, help="cell size, degrees (default 1)")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    import h5py

    path, version = pvlib_file()
    path = args.source or path
    with h5py.File(path, "r") as f:
        source = f["LinkeTurbidity"][:]
    if source.shape != (2160, 4320, 12) or source.dtype != np.uint8:
        raise SystemExit(f"{path}: expected a (2160, 4320, 12) uint8 array 'LinkeTurbidity'")
    tl20 = resample(source, args.step)
    np.savez_compressed(args.out, tl20=tl20, step_deg=np.float64(args.step),
                        source=np.str_(SOURCE.format(version=version, step=args.step)),
                        licence=np.str_(LICENCE))
    print(f"wrote {args.out.relative_to(ROOT) if args.out.is_relative_to(ROOT) else args.out}: "
          f"{tl20.shape}, {args.out.stat().st_size / 1e3:.0f} kB")
    if args.out == OUT:
        check(args.out)


if __name__ == "__main__":
    main()
