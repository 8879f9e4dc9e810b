"""The numpy evaluator of the aging table against the slider path it replaces.

Prints milliseconds per megatexel for one years value, side by side:

* ``before``: the evaluator of ``TextureAger.age`` up to commit b660256 (float16 table,
  two 6-byte gathers per vertex, single-threaded), copied here verbatim in
  :func:`_before`, plus what ``apply.write_years`` did to its output (``nan_to_num``,
  ``clip``) — the per-texture work of every years change then;
* ``after``: :func:`lightfade_addon.core.aging.table.evaluate` (float32 table, row gathers,
  blocks on threads), what ``api.apply_aging`` runs once per texture now.

Both read the same random table and texels (K keys, S spectra, T = 65 dose nodes), so
the comparison is of the evaluators alone.

    ./run py -m benchmarks.evaluator            # 1 and 4 Mtexel, 1 and 2 spectra
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from lightfade_addon.core.colour.gamut import into_gamut_planes
from lightfade_addon.core.fading.lattice import mix_lattice
from lightfade_addon.core.aging.table import AgingTable, Texels, evaluate, texel_positions


def _before(values16, offsets, weights, sigma, T, XYZ, to_rgb, root, out):
    """TextureAger.age/_change of b660256 (linear encoding), block by block."""
    nodes = values16.view(np.dtype((np.void, 6))).ravel()
    n = sigma.shape[0]
    block = 1 << 18
    for s0 in range(0, n, block):
        s1 = min(s0 + block, n)
        k = s1 - s0
        pos = sigma[s0:s1] * np.float32(root)
        i = pos.astype(np.int32)
        np.minimum(i, T - 2, out=i)
        f = pos
        f -= i
        res = np.empty((3, k), dtype=np.float32)
        tmp = np.empty(k, dtype=np.float32)
        idx = np.empty(k, dtype=np.int32)
        acc = None if weights is None else np.zeros((3, k), dtype=np.float32)
        for v in range(offsets.shape[0]):
            np.add(offsets[v, s0:s1], i, out=idx)
            lo = np.take(nodes, idx).view(np.float16).reshape(k, 3).astype(np.float32)
            idx += 1
            hi = np.take(nodes, idx).view(np.float16).reshape(k, 3).astype(np.float32)
            for ch in range(3):
                np.subtract(hi[:, ch], lo[:, ch], out=tmp)
                tmp *= f
                np.add(tmp, lo[:, ch], out=res[ch])
            if acc is not None:
                res *= weights[v, s0:s1]
                acc += res
        result = res if acc is None else acc
        np.exp(result, out=result)
        result *= XYZ[:, s0:s1]
        rgb = into_gamut_planes(to_rgb @ result)
        out[s0:s1, :3] = rgb.T
    rgb = out[:, :3]                                   # apply.write_years of b660256
    np.nan_to_num(rgb, copy=False, nan=0.0, posinf=1.0, neginf=0.0)
    np.clip(rgb, 0.0, 1.0, out=rgb)


def case(n, S, keys=20000, q=4, T=65, repeats=3, seed=0):
    rng = np.random.default_rng(seed)
    curves = rng.normal(0, 0.05, (keys, mix_lattice(S, q).shape[0], T, 3)).astype(np.float32)
    table = AgingTable.from_curves(curves, 1e8, S, q)
    texels = Texels.from_linear(rng.integers(0, keys, n), rng.uniform(0, 1e6, (S, n)),
                                rng.uniform(0.05, 0.95, (n, 3)))
    positions = texel_positions(table, texels)
    sigma, rows, weights = positions
    # the old layout: lattice rows, not slots (same values)
    values16 = np.ascontiguousarray(table.values.reshape(-1, 3), dtype=np.float16)
    to_rgb = np.linalg.inv(np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                                     [0.0193, 0.1192, 0.9505]])).astype(np.float32)
    out = np.empty((n, 4), np.float32)
    t_before, t_after = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        _before(values16, rows, weights, sigma, T, texels.XYZ, to_rgb, 25.0 ** (1 / 3), out)
        t_before.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        evaluate(table, texels, 25.0, positions, out=out)
        t_after.append(time.perf_counter() - t0)
    mt = n / 1e6
    return 1e3 * min(t_before) / mt, 1e3 * min(t_after) / mt


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="1 Mtexel only")
    args = parser.parse_args(argv)
    sizes = [1 << 20] if args.quick else [1 << 20, 1 << 22]
    print(f"{'texels':>10} {'spectra':>7} {'before ms/Mtexel':>17} {'after ms/Mtexel':>16} "
          f"{'speed-up':>8}")
    for n in sizes:
        for S in (1, 2):
            before, after = case(n, S)
            print(f"{n:>10,} {S:>7} {before:>17.1f} {after:>16.1f} {before / after:>7.1f}x")


if __name__ == "__main__":
    main()
