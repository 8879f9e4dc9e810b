"""The passes of each (object, light group) map of a bake, finished as the map would be.

After each Cycles call a pass is read back and denoised (:mod:`.denoise`: OIDN guided by
the islands, capped by the raw neighbours, the raw bake's local mean kept); after an
object's last call of a round its new passes are averaged over their 3D neighbours on
the surface together (:mod:`.filter3d`: one neighbour search; each pass with the range
weight of its own values, so that passes stay independent) and extended over the
margin.  A map is the mean of its finished passes weighted by their samples; an adaptive
bake (:mod:`.adaptive`) measures each map's error from them, and the error of its mean
from the raw passes (:class:`.adaptive.RawSpread`).

An adaptive bake's first passes wait raw until the object's round is baked: where the
spread of their raw values, averaged over the 3D neighbours, already bounds the map's
error within the target (:func:`.adaptive.raw_bound`), the map is their mean finished
once, as a fixed bake finishes its one pass; elsewhere each is finished by itself.
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
        self.first = {}    # map key -> [(group, samples, rgb, luminance)]: first passes, raw
        self.bound = {}    # (map key, group) -> adaptive.Noise: finished once, clean by raw
        self._trees = {}   # map key -> its neighbour search tree, during one finish()

    def add(self, obj_name, group, samples, image, index=None):
        """A pass just baked into ``image``: denoised (when the settings say so; the raw
        mean kept object by object in a shared map, :attr:`regions`), pending its
        object's 3D filter.  An adaptive bake's first passes (``index`` below
        :attr:`.settings.BakeSettings.first_passes`) wait raw for the object's
        :meth:`finish`: a map their raw spread already proves clean is denoised once,
        as their mean (:meth:`_clean_by_raw`)."""
        n = image.size[0]
        px = np.empty(n * n * 4, dtype=np.float32)
        image.pixels.foreach_get(px)
        rgb = px.reshape(n, n, 4)[..., :3]
        raw = luminance(rgb)
        s = self.settings
        if s.adaptive:
            self.spread.setdefault((obj_name, group), adaptive.RawSpread()).add(raw, samples)
            if s.denoise and index is not None and index < s.first_passes:
                self.first.setdefault(obj_name, []).append((group, samples, rgb.copy(), raw))
                return
        if s.denoise:
            raw = self._denoised(obj_name, rgb, raw)
        self.pending.setdefault(obj_name, []).append((group, samples, raw.astype(np.float32)))

    def _denoised(self, obj_name, rgb, raw):
        """OIDN guided by the islands, capped by the raw neighbours, the raw bake's local
        mean kept (object by object in a shared map): luminance (H, W)."""
        geo = self.geometry[obj_name]
        if obj_name not in self.colours:
            self.colours[obj_name] = _denoise.island_colours(geo.island)
        denoised = _denoise.denoise(rgb, self.colours[obj_name])
        cells = self.regions.get(obj_name)
        return _denoise.preserve_mean(luminance(_denoise.guard(denoised, rgb)), raw,
                                      geo.island >= 0,
                                      parts=list(cells.values()) if cells else None)

    def _first_passes(self, obj_name):
        """The object's first passes, waiting raw (:meth:`add`), into :attr:`pending`: per
        group, their mean denoised once where their raw spread proves the map clean,
        else each pass denoised by itself (the passes whose spread measures the map)."""
        groups = {}
        for group, samples, rgb, raw in self.first.pop(obj_name, []):
            groups.setdefault(group, []).append((samples, rgb, raw))
        for group, items in groups.items():
            samples = [n for n, _, _ in items]
            raws = [y for _, _, y in items]
            if len(items) >= 2 and self._clean_by_raw(obj_name, group, raws, samples):
                rgb = adaptive.mean_map([c for _, c, _ in items], samples).astype(np.float32)
                items = [(sum(samples), rgb, luminance(rgb))]
            for n, rgb, raw in items:
                y = self._denoised(obj_name, rgb, raw)
                self.pending.setdefault(obj_name, []).append((group, n, y.astype(np.float32)))

    def _clean_by_raw(self, obj_name, group, raw, samples):
        """Whether the raw first passes alone prove the map within its target: the error
        contrast of their raw values, averaged over the 3D neighbours as the map will be
        (the weights of the raw mean's values, at a sample of the texels), is an upper
        bound of the finished map's error where the denoiser takes off at least what the
        3D filter does (:data:`.adaptive.RAW_BOUND`); if it is within the target in
        every region of the map (and the mean's error within its own), the map is
        finished once, from the passes' mean, and its noise is that bound
        (:attr:`bound`)."""
        geo = self.geometry[obj_name]
        mean = adaptive.mean_map(raw, samples).astype(np.float32)
        contrasts = adaptive.error_contrasts(raw, samples).astype(np.float32)
        query = adaptive.sample_mask(geo.covered)
        values = filter3d.smooth_at(np.concatenate([mean[None], contrasts]),
                                    np.broadcast_to(mean, (1 + len(contrasts),) + mean.shape),
                                    geo.position, geo.normal, geo.covered, query, geo.texel,
                                    tree=self._tree(obj_name))
        rows, cols = np.nonzero(query & np.asarray(geo.covered, bool))
        spread = self.spread.get((obj_name, group))
        cells = self.regions.get(obj_name) or {None: (slice(None), slice(None))}
        found = {}
        for name, (ys, xs) in cells.items():
            inside = _within(rows, ys) & _within(cols, xs)
            part = spread if name is None or spread is None else spread.part((ys, xs))
            mean_error = part.mean_error(geo.covered[ys, xs]) if part is not None else 0.0
            found[name] = adaptive.raw_bound(values[0][inside], values[1:, inside], samples,
                                             mean_error)
            if not self._within_target(found[name]):
                return False
        for name, noise in found.items():
            if name is not None:
                self.region_noise[(name, group)] = noise
        self.bound[(obj_name, group)] = max(found.values(), key=self._excess)
        return True

    def _within_target(self, found):
        s = self.settings
        return found.p95 <= s.noise_target and not (s.mean_target > 0
                                                     and found.mean > s.mean_target)

    def finish(self, obj_name):
        """Average the object's pending passes over their 3D neighbours on the surface
        (across islands; one neighbour search for all, every group and pass; each pass
        with the range weight of its own values), then over the bake margin: they join
        its finished passes.

        Each pass is guided by itself, not by the mean of its group's passes: the range
        weight keeps what the guide shows as an edge, so a guide shared by two passes
        keeps the blotches of their mean (its error) and smooths their difference (the
        bake's estimate of that error) away.  Measured on the furnished room's round one
        (four seeds, each map's own estimate against the error of its 8-sample map from
        the other three): with the shared guide the estimate read 1.06-1.37x low on all
        14 maps (sofa 19.7 % against 24.0 %, bookshelf 16.2 % against 22.2 %); each pass
        by itself: sofa 25.2 % against 24.7 %, bookshelf 26.1 % against 25.4 %
        (docs/bake.md).
        """
        self._first_passes(obj_name)
        pending = self.pending.pop(obj_name, [])
        if not pending:
            return
        Y = [y for _, _, y in pending]
        if self.settings.denoise:
            geo = self.geometry[obj_name]
            stack = np.stack(Y)
            Y = filter3d.smooth_on_surface(stack, stack, geo.position, geo.normal, geo.covered,
                                           geo.texel, tree=self._tree(obj_name))
            Y = [filter3d.extend_over_margin(y, geo.covered, geo.island >= 0) for y in Y]
        for (group, samples, _), y in zip(pending, Y):
            self.passes.setdefault(obj_name, {}).setdefault(group, []).append((samples, y))
        self._trees.pop(obj_name, None)

    def _tree(self, obj_name):
        """The object's neighbour search tree (:func:`.filter3d.search_tree`), kept while
        one :meth:`finish` needs it."""
        if obj_name not in self._trees:
            geo = self.geometry[obj_name]
            self._trees[obj_name] = filter3d.search_tree(geo.position, geo.covered)
        return self._trees[obj_name]

    def measure(self, obj_name, group):
        """:class:`.adaptive.Noise` of the map so far (kept for the report); ``capped``
        while it is above the target.  A map shared by several regions (:attr:`regions`)
        is measured in each (kept in :attr:`region_noise`), and its noise is the worst
        region's: a dim object in an atlas of bright ones gets the samples it needs."""
        passes = self.passes[obj_name][group]
        if len(passes) == 1 and (obj_name, group) in self.bound:   # clean by its raw passes
            found = self.noise[(obj_name, group)] = self.bound[(obj_name, group)]
            return found
        maps, samples = [y for _, y in passes], [n for n, _ in passes]
        covered = self.geometry[obj_name].covered
        regions = self.regions.get(obj_name)
        spread = self.spread.get((obj_name, group))
        if not regions:
            found = self._measured(maps, covered, samples, spread)
        else:
            found = None
            for name, cell in regions.items():
                part = self._measured([y[cell] for y in maps], covered[cell], samples,
                                      spread.part(cell) if spread is not None else None)
                self.region_noise[(name, group)] = part
                if found is None or self._excess(part) > self._excess(found):
                    found = part
        self.noise[(obj_name, group)] = found
        return found

    def _measured(self, maps, covered, samples, spread=None):
        s = self.settings
        found = adaptive.noise(maps, covered, samples, spread)
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
                                               s.cap_samples,
                                               s.first_passes * s.samples_per_pass())
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


def _within(index, part):
    """Which of ``index`` (int array) lie in the slice ``part``."""
    start, stop, _ = part.indices(int(index.max()) + 1 if index.size else 0)
    return (index >= start) & (index < stop)
