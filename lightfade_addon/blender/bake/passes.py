"""The passes of each (object, light group) map of a bake, finished as the map would be.

After each Cycles call a pass is read back and summed with the other passes of its map
in the round (an adaptive bake's first round has two); after an object's last call of
a round, each of its maps' round is finished once: the raw mean denoised (:mod:`.denoise`:
OIDN guided by the islands, capped by the raw neighbours, the raw bake's local mean
kept), averaged over its 3D neighbours on the surface (:mod:`.filter3d`: one neighbour
search for all the object's maps) and extended over the margin.  A map is the mean of
its finished rounds weighted by their samples; an adaptive bake (:mod:`.adaptive`)
measures each map's error from them, from the first round's raw contrasts (3D-filtered
with the map's own weights) while it has one, and the error of its mean from the raw
passes (:class:`.adaptive.RawSpread`).
"""

from __future__ import annotations

import numpy as np

from . import adaptive
from . import denoise as _denoise
from . import filter3d
from .common import LUX_PER_BAKE_UNIT, luminance


class Passes:
    """Finished passes per object and group: ``passes[object][group] = [(samples, map)]``
    (maps in bake units, luminance), and the :class:`.adaptive.Noise` measured."""

    def __init__(self, settings, geometry, regions=None):
        self.settings, self.geometry = settings, geometry
        #: ``{map key: {name: (row slice, column slice)}}``: the parts of a shared map (an
        #: atlas's objects, an instanced source's tiles) that each must reach the target
        self.regions = regions or {}
        self.colours, self.pending, self.passes, self.noise = {}, {}, {}, {}
        self.region_noise = {}   # (region name, group) -> adaptive.Noise
        self.spread = {}   # (map key, group) -> adaptive.RawSpread of its raw passes
        #: (map key, group) -> the first round's raw contrasts, 3D-filtered (K - 1, H, W)
        self.first = {}

    def add(self, obj_name, group, samples, image):
        """A pass just baked into ``image``: summed with the other passes of its map in
        this round (the first round has two), pending its object's finish."""
        n = image.size[0]
        px = np.empty(n * n * 4, dtype=np.float32)
        image.pixels.foreach_get(px)
        rgb = px.reshape(n, n, 4)[..., :3]
        raw = luminance(rgb)
        if self.settings.adaptive:
            self.spread.setdefault((obj_name, group), adaptive.RawSpread()).add(raw, samples)
        now = self.pending.setdefault(obj_name, {}).get(group)
        if now is None:
            self.pending[obj_name][group] = _Round(rgb * np.float32(samples), samples)
        else:
            now.add(rgb, raw, samples)

    def finish(self, obj_name):
        """Finish the object's pending passes, one map per group and round: the round's
        raw passes summed, denoised once (OIDN with the island guide, guarded, the raw
        mean kept), averaged over their 3D neighbours on the surface (across islands;
        one neighbour search for every group) and over the bake margin: it joins the
        map's finished passes.  The raw passes' contrasts of the round go through the
        same 3D weights (the map's own range weight): the first round's error, before
        a second pass is finished (:func:`.adaptive.noise`)."""
        rounds = self.pending.pop(obj_name, {})
        if not rounds:
            return
        groups = list(rounds)
        geo = self.geometry.get(obj_name)
        maps = [self._denoised(obj_name, rounds[g]) for g in groups]
        contrasts = [(i, c) for i, g in enumerate(groups) for c in rounds[g].contrasts()]
        filtered = [c for _, c in contrasts]
        if self.settings.denoise:
            Y = filter3d.smooth_on_surface(np.stack(maps + filtered), np.stack(maps),
                                           geo.position, geo.normal, geo.covered, geo.texel,
                                           guide_of=list(range(len(groups)))
                                           + [i for i, _ in contrasts])
            maps = [filter3d.extend_over_margin(y, geo.covered, geo.island >= 0)
                    for y in Y[:len(groups)]]
            filtered = list(Y[len(groups):])
        for i, group in enumerate(groups):
            self.passes.setdefault(obj_name, {}).setdefault(group, []).append(
                (rounds[group].samples, maps[i]))
            mine = [c for (j, _), c in zip(contrasts, filtered) if j == i]
            if mine:
                self.first[(obj_name, group)] = np.stack(mine)

    def _denoised(self, obj_name, round_):
        """The round's raw mean as luminance, denoised when the settings say so."""
        rgb = round_.rgb / np.float32(round_.samples)
        raw = luminance(rgb)
        if not self.settings.denoise:
            return raw.astype(np.float32)
        geo = self.geometry[obj_name]
        if obj_name not in self.colours:
            self.colours[obj_name] = _denoise.island_colours(geo.island)
        denoised = _denoise.denoise(rgb, self.colours[obj_name])
        return _denoise.preserve_mean(luminance(_denoise.guard(denoised, rgb)), raw,
                                      geo.island >= 0).astype(np.float32)

    def measure(self, obj_name, group):
        """:class:`.adaptive.Noise` of the map so far (kept for the report); ``capped``
        while it is above the target.  A map shared by several regions (:attr:`regions`)
        is measured in each (kept in :attr:`region_noise`), and its noise is the worst
        region's: a dim object in an atlas of bright ones gets the samples it needs."""
        passes = self.passes[obj_name][group]
        maps, samples = [y for _, y in passes], [n for n, _ in passes]
        covered = self.geometry[obj_name].covered
        regions = self.regions.get(obj_name)
        spread = self.spread.get((obj_name, group))
        first = self.first.get((obj_name, group)) if len(maps) == 1 else None
        if not regions:
            found = self._measured(maps, covered, samples, spread, first)
        else:
            found = None
            for name, cell in regions.items():
                part = self._measured([y[cell] for y in maps], covered[cell], samples,
                                      spread.part(cell) if spread is not None else None,
                                      None if first is None else first[(slice(None),) + cell])
                self.region_noise[(name, group)] = part
                if found is None or self._excess(part) > self._excess(found):
                    found = part
        self.noise[(obj_name, group)] = found
        return found

    def _measured(self, maps, covered, samples, spread=None, first=None):
        s = self.settings
        found = adaptive.noise(maps, covered, samples, spread, first,
                               adaptive.DENOISE_GAIN if s.denoise else 1.0)
        if found.p95 is not None:
            found.capped = found.p95 > s.noise_target or (
                s.mean_target > 0 and found.mean > s.mean_target)
        return found

    def _excess(self, found):
        """How far ``found`` is above the target (its error over the target's)."""
        s = self.settings
        if found.p95 is None:
            return 0.0
        return max(found.p95 / s.noise_target,
                   found.mean / s.mean_target if s.mean_target else 0.0)

    def wanted(self, objects):
        """Measure every map of ``objects``; those above the target, by the pass they
        would add: ``{(group, pass index, samples): [objects]}``."""
        s, more = self.settings, {}
        for obj in objects:
            for group in self.passes.get(obj.name, {}):
                found = self.measure(obj.name, group)
                want = adaptive.samples_wanted(found, s.noise_target, s.mean_target,
                                               s.cap_samples, s.samples_per_pass())
                if want > found.samples:
                    more.setdefault((group, found.passes, want - found.samples), []).append(obj)
        return more

    def record(self, item, obj_name, group):
        """The noise and samples of a map on its record (:mod:`.records`)."""
        found = self.noise.get((obj_name, group))
        item.samples = sum(n for n, _ in self.passes.get(obj_name, {}).get(group, ()))
        item.noise = found.p95 if found is not None and found.p95 is not None else 0.0

    def write(self, image, obj_name, group):
        """The map into ``image``: the weighted mean of its passes, in lux (RGB = lux,
        A = 1)."""
        passes = self.passes[obj_name][group]
        n = image.size[0]
        px = np.empty((n, n, 4), dtype=np.float32)
        mean = adaptive.mean_map([y for _, y in passes], [k for k, _ in passes])
        px[..., :3] = (np.maximum(mean, 0.0) * LUX_PER_BAKE_UNIT)[..., None]
        px[..., 3] = 1.0
        image.pixels.foreach_set(px.ravel())


class _Round:
    """The raw passes of one map in one round: their sample-weighted RGB sum and their
    Helmert contrasts (luminance, in the units of one sample's error,
    :class:`.adaptive.RawSpread`)."""

    def __init__(self, rgb_sum, samples):
        self.rgb, self.samples, self._contrasts = rgb_sum, int(samples), []

    def add(self, rgb, raw, samples):
        mean = luminance(self.rgb) / np.float32(self.samples)
        self._contrasts.append((mean - raw) / np.float32(
            np.sqrt(1.0 / self.samples + 1.0 / samples)))
        self.rgb += rgb * np.float32(samples)
        self.samples += int(samples)

    def contrasts(self):
        """Each distributed as the error of the round's mean (:func:`.adaptive.error_contrasts`)."""
        scale = np.float32(np.sqrt(1.0 / self.samples))
        return [(c * scale).astype(np.float32) for c in self._contrasts]
