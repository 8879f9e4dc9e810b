"""Adaptive exposure bakes: passes until each map reaches its noise target.

A fixed sample count is too few where light arrives by rare paths (the year's sun through
a small window onto a sofa, a bulb seen through frosted glass) and wasted everywhere
else.  So an adaptive bake (the Final preset) bakes each light group in **passes** of a
few samples, each pass with its own seed (:func:`pass_seed`), finishes every pass the
same way the bake finishes a map (denoised, the raw mean kept, 3D-filtered), and takes
the mean of the finished passes as the map.  Independent passes give the bake its own
error (:func:`noise`): the spread of the finished passes says how far their mean can be
from a converged bake; the error of the object's mean lux comes from the raw passes,
texel by texel (:class:`RawSpread`).  After the first passes (:data:`MIN_PASSES`, of a
few samples each) each (object, group) whose error is above the target gets one more
pass per round, of the samples it lacks aimed a little under the target
(:func:`samples_wanted`), until it reaches the target or the cap on samples (or on
time) that the artist sets: a few rounds, so a few denoisings, however many samples.
Measured on a furnished room's sofa under a window's annual daylight (docs/bake.md):
20 samples where 8 left it twice the error target.

The error of a mean of ``K`` independent passes ``F_k`` of equal variance ``σ²`` is
distributed as each Helmert contrast ``h_j / √K``::

    h_j = (Σ_{k<j} F_k − j F_j) / √(j (j + 1)),    j = 1 … K − 1      (var σ²)

so their pooled values, relative to the mean map at lit texels, give the 95th percentile
of the map's relative error directly, with no assumption on the shape of the noise
across texels (passes of different samples: the mean weighted by them, each pass against
the weighted mean of those before it, :func:`error_contrasts`).  The error of the
object's mean lux is the root mean square of the same contrasts of the passes' means.

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
#: A round at most multiplies a map's samples by this (the first estimates are rough).
MAX_GROWTH = 4
#: A map above its target is given the samples that bring its error to this share of
#: the target: aimed at the target itself, the next estimate lands above it one time in
#: two and costs a round (a Cycles call and a denoising for a few samples; the
#: furnished room's cabinets and bookshelf took up to five passes of +4 samples).
AIM = 0.9
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
    bound : bool
        ``p95`` is an upper bound from the raw first passes (:func:`raw_bound`): the map
        was finished once, from their mean.
    """

    passes: int
    samples: int
    p95: float | None = None
    mean: float | None = None
    capped: bool = False
    bound: bool = False

    def text(self):
        if self.p95 is None:
            return f"{self.samples} spp (one pass: noise not measured)"
        cap = ", hit the cap" if self.capped else ""
        noise = (f"noise at most {self.p95:.1%} p95 (its raw passes)" if self.bound
                 else f"noise {self.p95:.1%} p95")
        return (f"{noise}, mean ±{self.mean:.2%}, "
                f"{self.samples} spp in {self.passes} passes{cap}")


def error_contrasts(passes, samples=None):
    """Helmert contrasts of ``K`` passes, each distributed as the error of the passes'
    mean: ``(K − 1, …)`` (module docstring).

    ``samples``: the samples of each pass (default equal); the mean is then weighted by
    them and pass ``j`` is compared with the weighted mean of the passes before it,
    ``(M_j − F_j) √((1/N) / (1/S_j + 1/n_j))`` (``S_j`` their samples, ``N`` all), the
    noise of a pass taken as ∝ 1/√samples.
    """
    F = np.asarray(passes, dtype=np.float64)
    n = np.ones(len(F)) if samples is None else np.asarray(samples, dtype=np.float64)
    total = n.sum()
    out = np.empty((len(F) - 1,) + F.shape[1:])
    acc, weight = n[0] * F[0], n[0]
    for j in range(1, len(F)):
        out[j - 1] = (acc / weight - F[j]) * math.sqrt((1.0 / total) / (1.0 / weight + 1.0 / n[j]))
        acc += n[j] * F[j]
        weight += n[j]
    return out


def mean_map(passes, samples):
    """The map: the passes' mean, weighted by their samples."""
    n = np.asarray(samples, dtype=np.float64)
    return np.tensordot(n / n.sum(), np.asarray(passes, dtype=np.float64), axes=1)


class RawSpread:
    """The spread of a map's *raw* passes (as baked, before any denoising), texel by
    texel: the error of the object's mean lux (:meth:`mean_error`).

    A raw texel's samples are independent of every other texel's, so the variance of
    the object's raw mean is the sum of its texels' variances over the texel count
    squared; each texel's is estimated from the Helmert contrasts of its passes (one
    per pass after the first; :func:`error_contrasts` in the units of one sample)::

        g_j = (M_j − F_j) / √(1/S_j + 1/n_j),    var g_j = s²  (one sample's variance)
        var(object mean) ≈ Σ_i mean_j(g_ij²) / N / n²

    (``N`` samples in all, ``n`` texels).  The finishing keeps the raw bake's local
    mean (:func:`.denoise.preserve_mean`) and the 3D filter and the margin average, so
    the finished map's mean has the raw mean's error (the pendant's poster in the
    lampshade room read 6.7 % at 8 samples where two seeds' means differed by 3.9 %).
    With two
    passes this estimate has as many degrees of freedom as the map has texels, where
    the contrast of the passes' means has one (its square is a χ²₁: a map at half the
    target read above it one time in twenty and was sent to more passes).
    """

    def __init__(self):
        self.sum, self.samples, self.square, self.contrasts = None, 0, None, 0

    def add(self, raw, samples):
        """Pass ``raw`` (an (H, W) map, any unit) of ``samples`` samples per texel."""
        raw = np.asarray(raw, dtype=np.float32)
        n = float(samples)
        if self.sum is None:
            self.sum, self.square = raw * np.float32(n), np.zeros(raw.shape, np.float32)
        else:
            g = (self.sum / np.float32(self.samples) - raw) / np.float32(
                math.sqrt(1.0 / self.samples + 1.0 / n))
            self.square += g * g
            self.sum += raw * np.float32(n)
            self.contrasts += 1
        self.samples += n

    def mean_error(self, covered):
        """Relative standard error of the mean over the ``covered`` texels; None before
        the second pass, 0 where nothing is lit."""
        if self.contrasts == 0:
            return None
        covered = np.asarray(covered, bool)
        total = float(self.sum[covered].sum(dtype=np.float64)) / self.samples
        if total <= 0.0:
            return 0.0
        variance = (float(self.square[covered].sum(dtype=np.float64))
                    / self.contrasts / self.samples)
        return math.sqrt(variance) / total

    def part(self, cell):
        """The spread of the texels ``cell`` (a (row slice, column slice)) alone."""
        out = RawSpread()
        out.samples, out.contrasts = self.samples, self.contrasts
        if self.sum is not None:
            out.sum, out.square = self.sum[cell], self.square[cell]
        return out


def noise(passes, covered, samples, spread=None):
    """:class:`Noise` of the mean of ``passes`` (finished maps, ``(K, H, W)``; ``samples``
    per pass, a list, or one number for all) over the ``covered`` texels: the error per
    texel from the Helmert contrasts of the finished passes; the error of the object's
    mean from ``spread`` (:class:`RawSpread` of the same passes, raw) where given, else
    from the contrasts of the passes' means (one degree of freedom per contrast).  Dark
    maps (nothing lit) have no error; one pass: not measured (``p95`` None)."""
    cov = np.asarray(covered, bool)
    F = np.asarray(passes, dtype=np.float64)[:, cov]
    k = len(F)
    n = np.broadcast_to(np.asarray(samples, dtype=np.float64), (k,))
    result = Noise(k, int(n.sum()))
    if k < 2:
        return result
    mean = mean_map(F, n)
    top = np.percentile(mean, 99) if mean.size else 0.0
    if top <= 0:
        result.p95, result.mean = 0.0, 0.0
        return result
    lit = mean >= LIT_SHARE * top
    if spread is not None:
        result.mean = float(spread.mean_error(covered) or 0.0)
    else:
        means = F.mean(axis=1)
        result.mean = float(np.sqrt(np.mean(error_contrasts(means, n) ** 2))
                            / max(float(mean_map(means, n)), 1e-30))
    if np.count_nonzero(lit) < MIN_LIT:
        result.p95 = 0.0
        return result
    rel = np.abs(error_contrasts(F[:, lit], n)) / mean[lit]
    result.p95 = float(np.percentile(rel, 95))
    return result


#: The finished map's error over the raw contrasts' error after the 3D filter's average
#: (the denoiser's "gain") that :func:`raw_bound` takes at most: measured 0.07-0.46 on
#: the lampshade room's maps and 0.24-1.02 on the furnished room's, with the weights of
#: the finished map (docs/bake.md); the raw mean's weights, which the bound uses, average
#: less and read the contrasts higher still.
RAW_BOUND = 1.0
#: Texels :func:`sample_mask` keeps about (every k-th row and column).
BOUND_TEXELS = 8192


def sample_mask(covered, texels=BOUND_TEXELS):
    """A regular sample of the ``covered`` texels (every ``k``-th row and column, ``k``
    such that about ``texels`` remain; all of them in a small map): where
    :func:`raw_bound`'s contrasts are filtered."""
    covered = np.asarray(covered, bool)
    k = max(1, int(math.sqrt(np.count_nonzero(covered) / float(texels))))
    mask = np.zeros_like(covered)
    mask[k // 2::k, k // 2::k] = True
    return mask & covered


def raw_bound(mean, contrasts, samples, mean_error):
    """:class:`Noise` of a map from its raw first passes, before any denoising: ``mean``
    (q,) and their Helmert ``contrasts`` (K − 1, q) (:func:`error_contrasts`), both
    averaged over the texels' 3D neighbours as the map will be, at a sample of its
    texels; the 95th percentile of ``|contrast| / mean`` at lit texels times
    :data:`RAW_BOUND`.  The denoiser takes off at least what a linear average over the
    same neighbours does, so the map finished from the passes' mean is no further from
    a converged bake than this (an upper bound, not an estimate: a map above it is
    measured from its finished passes).  ``mean_error``: the object's mean's, from
    :class:`RawSpread`."""
    result = Noise(len(contrasts) + 1, int(np.sum(samples)), mean=float(mean_error or 0.0),
                   bound=True)
    mean = np.asarray(mean, dtype=np.float64)
    top = np.percentile(mean, 99) if mean.size else 0.0
    if top <= 0:
        result.p95 = 0.0
        return result
    lit = mean >= LIT_SHARE * top
    if np.count_nonzero(lit) < MIN_LIT:      # too few to prove anything: measure it
        result.p95 = math.inf
        return result
    rel = np.abs(np.asarray(contrasts, dtype=np.float64)[:, lit]) / mean[lit]
    result.p95 = RAW_BOUND * float(np.percentile(rel, 95))
    return result


def samples_wanted(found, target, mean_target, max_samples, step=8):
    """Samples per texel the (object, group) of :class:`Noise` ``found`` should have in
    all.  Error falls as ``1/√samples``, so it lacks ``N · (max(p95 / target, mean /
    mean_target) / AIM)² − N``; the pass that adds them carries a multiple of ``step``
    (the first round's samples: maps that lack about as many share one Cycles call, and
    a call costs the scene's sync whatever its samples), at most :data:`MAX_GROWTH` ×
    ``N`` in all after the round and ``max_samples`` in all; ``found.samples`` when it
    is at the target (or the cap).
    """
    have = found.samples
    if found.p95 is None:
        return have
    ratio = max(found.p95 / target, found.mean / mean_target if mean_target else 0.0)
    if ratio <= 1.0:
        return have
    lack = have * (ratio / AIM) ** 2 - have
    extra = step * max(1, math.ceil(lack / step - 1e-9))
    return int(max(have, min(have + extra, MAX_GROWTH * have, max_samples)))


def noise_note(noise, settings):
    """The bake's report: one line per map (``noise``: ``{(object, group): Noise}``) with
    the noise it reached and the samples it took; then the maps that hit the cap above
    the target, named.  '' without maps."""
    if not noise:
        return ""
    s = settings
    cap = f"{s.cap_samples} spp" + (
        f" or {_seconds(s.max_seconds)}" if s.max_seconds else "")
    lines = [f"Noise reached (target {s.noise_target:.0%} p95 per texel, object mean "
             f"±{s.mean_target:.1%}; cap {cap}):"]
    for (obj, group), found in noise.items():
        lines.append(f"  \"{obj}\" <- {group}: {found.text()}")
    capped = [f"\"{obj}\" <- {group}" for (obj, group), f in noise.items() if f.capped]
    if capped:
        lines.append(f"Hit the cap ({cap}) above the target: {', '.join(capped)}; raise "
                     "Max Samples or Max Minutes to bake them further")
    return "\n".join(lines)


def _seconds(s):
    return f"{s:.0f} s" if s < 90 else f"{s / 60:.1f} min"
