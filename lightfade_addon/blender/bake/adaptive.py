"""Adaptive exposure bakes: passes until each map reaches its noise target.

A fixed sample count is too few where light arrives by rare paths (the year's sun through
a small window onto a sofa, a bulb seen through frosted glass) and wasted everywhere
else.  So an adaptive bake (the Final preset) bakes each light group in **passes** of a
few samples, each pass with its own seed (:func:`pass_seed`), finishes every pass the
same way the bake finishes a map (denoised, the raw mean kept, 3D-filtered), and takes
the mean of the finished passes as the map.  Independent passes give the bake its own
error (:func:`noise`): the spread of the finished passes says how far their mean can be
from a converged bake.  After the first passes (:data:`MIN_PASSES`) each (object, group)
whose error is above the target gets more passes (:func:`passes_wanted`), until it
reaches the target or the cap on samples (or on time) that the artist sets.

The error of a mean of ``K`` independent passes ``F_k`` of equal variance ``σ²`` is
distributed as each Helmert contrast ``h_j / √K``::

    h_j = (Σ_{k<j} F_k − j F_j) / √(j (j + 1)),    j = 1 … K − 1      (var σ²)

so their pooled values, relative to the mean map at lit texels, give the 95th percentile
of the map's relative error directly, with no assumption on the shape of the noise
across texels.  The error of the object's mean lux is the standard deviation of the
passes' means over ``√K``.

Seeds depend only on the base seed, the group's name and the pass: a bake split by
object chunks (a farm) gives every object the passes, and so the maps, of the whole
bake; Cycles bakes each selected object on its own, so its noise does not depend on
which other objects share the call.  Pass 0 has the base seed: a one-pass bake is the
fixed bake of before.

No ``bpy`` here: arrays in, numbers out.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np

#: Passes every (object, group) gets before its error is measured (two: one contrast).
MIN_PASSES = 2
#: A round adds at most this factor of passes (the first estimates are rough).
MAX_GROWTH = 4
#: Lit texels: at least this share of the map's 99th percentile (as the benchmarks).
LIT_SHARE = 0.05
#: Fewer lit texels than this: no per-texel percentile (the object's mean still counts).
MIN_LIT = 64
#: Cycles' largest seed.
_SEED_MAX = 2 ** 31 - 1


def pass_seed(base, group, index):
    """Cycles seed of pass ``index`` of light group ``group`` (its name).

    Pass 0: ``base`` (a one-pass bake is the fixed bake); later passes: ``base`` plus a
    CRC-32 of the group's name and the pass index, the same in every run and on every
    machine (idempotent: a re-bake, or a farm's chunk, gives the same maps).
    """
    if index == 0:
        return int(base)
    return (int(base) + zlib.crc32(f"{group}\0{index}".encode())) % _SEED_MAX


@dataclass
class Noise:
    """The error one (object, group) map reached, from its passes.

    Attributes
    ----------
    passes, samples : int
        Passes baked and samples per texel they add up to.
    p95 : float or None
        95th percentile of the relative error at lit texels (a fraction); None with one
        pass (not measured).
    mean : float or None
        Relative standard error of the object's mean lux; None with one pass.
    capped : bool
        Stopped by the cap (samples or time) above the target.
    """

    passes: int
    samples: int
    p95: float | None = None
    mean: float | None = None
    capped: bool = False

    def text(self):
        if self.p95 is None:
            return f"{self.samples} spp (one pass: noise not measured)"
        cap = ", hit the cap" if self.capped else ""
        return (f"noise {self.p95:.1%} p95, mean ±{self.mean:.2%}, "
                f"{self.samples} spp in {self.passes} passes{cap}")


def error_contrasts(passes):
    """Helmert contrasts of ``K`` passes scaled by ``1/√K``: ``(K − 1, …)``, each
    distributed as the error of the passes' mean (module docstring)."""
    F = np.asarray(passes, dtype=np.float64)
    k = len(F)
    out = np.empty((k - 1,) + F.shape[1:])
    total = F[0].copy()
    for j in range(1, k):
        out[j - 1] = (total - j * F[j]) / math.sqrt(j * (j + 1) * k)
        total += F[j]
    return out


def noise(passes, covered, pass_samples):
    """:class:`Noise` of the mean of ``passes`` (finished maps, ``(K, H, W)``) over the
    ``covered`` texels.  Dark maps (nothing lit) have no error."""
    F = np.asarray(passes, dtype=np.float64)[:, np.asarray(covered, bool)]
    k = len(F)
    result = Noise(k, k * int(pass_samples))
    if k < 2:
        return result
    mean_map = F.mean(axis=0)
    top = np.percentile(mean_map, 99) if mean_map.size else 0.0
    if top <= 0:
        result.p95, result.mean = 0.0, 0.0
        return result
    lit = mean_map >= LIT_SHARE * top
    means = F.mean(axis=1)
    result.mean = float(means.std(ddof=1) / math.sqrt(k) / max(means.mean(), 1e-30))
    if np.count_nonzero(lit) < MIN_LIT:
        result.p95 = 0.0
        return result
    rel = np.abs(error_contrasts(F[:, lit])) / mean_map[lit]
    result.p95 = float(np.percentile(rel, 95))
    return result


def passes_wanted(found, target, mean_target, max_passes):
    """Passes the (object, group) of :class:`Noise` ``found`` should have in all.

    Error falls as ``1/√passes``: ``K · max(p95 / target, mean / mean_target)²``, at most
    :data:`MAX_GROWTH` × ``K`` in one round and ``max_passes`` in all.  ``found.passes``
    when it is at the target (or at the cap).
    """
    k = found.passes
    if found.p95 is None:
        return k
    ratio = max(found.p95 / target, found.mean / mean_target if mean_target else 0.0)
    if ratio <= 1.0:
        return k
    want = math.ceil(k * ratio ** 2)
    return int(max(k, min(want, MAX_GROWTH * k, max_passes)))
