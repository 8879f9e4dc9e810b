"""Speed of the colorimetry and spectra helpers on the paths the aging code runs per texel.

    python -m benchmarks.colour

Prints the median time of each call (1 M colours for the per-texel functions; the
load-time ones on the default grid, cache cleared each time) so that a change of
implementation can be compared before and after on the same machine.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from lightfade_addon.core.colour import colorimetry as cm
from lightfade_addon.core.fading import spectra as sp


def timed(fn, repeat=7):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def cold(fn, *caches):
    def run():
        for c in caches:
            c.cache_clear()
        fn()
    return run


def main():
    rng = np.random.default_rng(0)
    rgb = rng.random((1_000_000, 3)).astype(np.float32)
    XYZ = cm.linear_srgb_to_XYZ(rgb)
    Lab = cm.XYZ_to_Lab(XYZ)
    R = rng.random((100_000, sp.WAVELENGTHS.size))
    fine = np.arange(300.0, 831.0)
    values = rng.random((50, fine.size))
    cases = {
        "srgb_encode, 1 M x 3 float32": lambda: cm.srgb_encode(rgb),
        "srgb_decode, 1 M x 3 float32": lambda: cm.srgb_decode(rgb),
        "XYZ_to_Lab, 1 M x 3": lambda: cm.XYZ_to_Lab(XYZ),
        "delta_E_ab, 1 M": lambda: cm.delta_E_ab(Lab, Lab[::-1]),
        "delta_E_2000, 1 M": lambda: cm.delta_E_2000(Lab, Lab[::-1]),
        "reflectance_to_Lab, 100 k x 41": lambda: cm.reflectance_to_Lab(R, sp.WAVELENGTHS),
        "xyz_weights, cold": cold(lambda: cm.xyz_weights(sp.WAVELENGTHS), cm._weights_cached),
        "resample, 50 x 531 -> 41": lambda: sp.resample(fine, values, sp.WAVELENGTHS),
        "light_spectrum x 5, cold": cold(lambda: [sp.light_spectrum(n) for n in sp.LIGHTS],
                                         sp._fine_source, sp._light_cached),
        "light_spectrum x 5, warm": lambda: [sp.light_spectrum(n) for n in sp.LIGHTS],
        "illuminance, 100 k x 41": lambda: sp.illuminance(R),
    }
    width = max(map(len, cases))
    for name, fn in cases.items():
        fn()                                            # warm imports and caches
        print(f"{name:<{width}}  {timed(fn) * 1e3:9.2f} ms", flush=True)


if __name__ == "__main__":
    main()
