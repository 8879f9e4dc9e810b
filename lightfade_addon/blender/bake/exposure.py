"""The exposure bake: one illuminance map (lux) per object and light group, with Cycles.

For each light group (:mod:`.emitters`) every other emitter is switched off and one
Cycles call bakes the DIFFUSE pass (direct + indirect light, no colour) of all target
objects at once, each into its own float image through a node added to its real
materials (:mod:`.targets`), whose baked texels read as a Lambertian (:mod:`.surface`):
the light arriving, whatever the material.  Each map is then denoised (:mod:`.denoise`), turned into
the luminance of the irradiance in lux (:mod:`.common`) and, once every group is done,
stored on the objects (:mod:`.maps`).  Everything the bake changes is put back by
:class:`.state.BakeState`, also on error or cancel; a cancelled bake stores nothing.

Before any Cycles work, every object is checked (:mod:`.uvmaps`) and all problems are
reported at once.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import bpy
import numpy as np

from . import daylight as _daylight
from . import denoise as _denoise
from . import filter3d
from . import instances as _instances
from . import panes as _panes
from . import portals as _portals
from . import sizing
from .common import LUX_PER_BAKE_UNIT, BakeCancelled, LightFadeBakeError, luminance
from .emitters import (
    bakes_sky,
    group_emitters,
    find_emitters,
    isolate,
    uncounted_emissive,
    uncounted_note,
)
from .maps import members, prune_maps, store_map
from .settings import BakeSettings
from .stand_in import add_stand_in
from .state import BakeState
from .targets import attach_targets, check_bake_result, find_targets, validate_targets
from .sizing import planned_map
from .uvmaps import make_unique_uv, texel_geometry


@dataclass
class _Step:
    group: object
    objects: list


def scene_and_layer(context_or_scene):
    if isinstance(context_or_scene, bpy.types.Scene):
        scene = context_or_scene
        layer = bpy.context.view_layer if bpy.context.scene == scene else scene.view_layers[0]
        return scene, layer
    return context_or_scene.scene, context_or_scene.view_layer


class ExposureBake:
    """A bake in steps (one Cycles call per light group), for operators that stay
    responsive: :meth:`plan`, then ``with job:`` :meth:`step` until it returns False, then
    :meth:`commit`.  :func:`bake_exposure` runs it all."""

    def __init__(self, context_or_scene, objects=None, settings=None, report=None,
                 progress=None, only_changed=False):
        self.scene, self.view_layer = scene_and_layer(context_or_scene)
        self.settings = settings or BakeSettings.from_scene(self.scene)
        self.report = report or print
        self.progress = progress
        self.only_changed = only_changed
        self.objects = list(objects or [])
        self.skipped, self.notes = [], []
        self.state = None
        self.maps = {}  # object name -> {group name: temp image}
        self.reused = {}  # object name -> group names kept as they were

    # ------------------------------------------------------------------ planning
    def plan(self):
        """Every check that can refuse, before any Cycles work; all problems at once."""
        scene, layer = self.scene, self.view_layer
        layer.update()  # objects linked by scripts join view_layer.objects on update
        depsgraph = bpy.context.evaluated_depsgraph_get()
        plans = _instances.find_placements(depsgraph, layer, self.objects, self._warn)
        instancers = {p.instancer for plan in plans.values() for p in plan.placements}
        objects = [o for o in (self.objects or find_targets(scene))
                   if o not in plans and o not in instancers]
        if not objects and not plans:
            raise LightFadeBakeError("Nothing to bake: " + ("; ".join(self.skipped) or (
                "select mesh objects, or enable LightFade on their materials "
                "(Material Properties > LightFade)")))
        targets, warnings, problems = validate_targets(objects + list(plans),
                                                       self.settings.unwrap)
        for msg in warnings:
            self._warn(msg)
        self.instance_plans = [plans[o] for o in targets if o in plans]
        targets = [o for o in targets if o not in plans]
        problems += _instances.plan_tiles(self.instance_plans, depsgraph, self.settings,
                                          self._note)
        targets = _instances.bakeable(targets, layer, self._warn)
        emitters = find_emitters(scene, layer)
        self._note(uncounted_note(uncounted_emissive(scene, layer)))
        if any(e.kind == "DAYLIGHT" for e in emitters) and _daylight.problem(scene):
            problems.append(_daylight.problem(scene))
        if not emitters:
            problems.append(
                "No emitters in the scene: add a lamp, count an emissive mesh (Count Emission as "
                "Light), or give the world a "
                "spectrum (Sky Schedule), and keep their LightFade 'Include in Aging' on")
        self.sizes, self.uv_plans = {}, {}
        for obj in targets:
            size, plan = planned_map(obj, depsgraph, self.settings)
            if isinstance(plan, str):
                problems.append(plan)
            else:
                self.uv_plans[obj.name] = plan
                self.sizes[obj.name] = size
        if problems:
            raise LightFadeBakeError("\n".join(problems))
        if not targets and not self.instance_plans:
            raise LightFadeBakeError("Nothing to bake: " + "; ".join(self.skipped))
        self.targets = targets
        self.emitters = emitters
        self.groups = group_emitters(scene, emitters)
        self._plan_glass(scene, depsgraph, layer)
        self.steps = []
        for group in self.groups:
            names = set(group.member_names)
            objs = [o for o in targets if o.name not in names and not self._reusable(o, group)]
            if objs or self.instance_plans:   # instances are baked in every group
                self.steps.append(_Step(group, objs))
        self.work = [sum(n ** 2 for n in sizes) * self.settings.samples
                     for sizes in self._step_sizes()]
        return self

    def _step_sizes(self):
        """Map widths per step: its objects' and each instanced source's atlas."""
        atlases = [plan.size for plan in self.instance_plans]
        return [[self.sizes[o.name] for o in s.objects] + atlases for s in self.steps]

    def _plan_glass(self, scene, depsgraph, layer):
        """Windows (a portal over each while the sky is baked) and the refracting glass
        each group's bake shows as clear panes (:mod:`.portals`, :mod:`.panes`)."""
        self.windows = []
        if self.settings.portals and any(bakes_sky(g) for g in self.groups):
            self.windows = _portals.find_windows(scene, depsgraph, layer)
        windows = _panes.window_panes(self.windows)
        lamps = {g.name: _panes.lamp_panes(scene, depsgraph, g)
                 for g in self.groups if not bakes_sky(g)}
        self.panes = {g.name: windows if bakes_sky(g) else
                      [(m, rgb) for m, rgb, _lamp in lamps[g.name].values()]
                      for g in self.groups}
        for note in (_portals.windows_note(self.windows), _panes.panes_note(windows),
                     _panes.lamps_note(lamps.values())):
            self._note(note)

    def _note(self, note):
        """Keep ``note`` for the result and report it (nothing for '')."""
        if note:
            self.notes.append(note)
            self.report(note)

    def _reusable(self, obj, group):
        """Existing maps of ``obj`` holding exactly ``group``'s emitters (only_changed)."""
        if not self.only_changed:
            return None
        names = set(group.member_names)
        parts = [item for item in obj.lightfade.exposure_maps
                 if item.image is not None and {n for n, _ in members(item)} <= names]
        covered = [n for item in parts for n, _ in members(item)]
        if sorted(covered) != sorted(names):
            return None
        return parts

    def estimate(self):
        """:class:`.sizing.Estimate` of the planned bake."""
        return sizing.estimate(self.scene, self._step_sizes(), self.settings.samples,
                               self.settings.denoise)

    def _warn(self, msg):
        self.skipped.append(msg)
        self.report(msg)

    # ------------------------------------------------------------------ baking
    def __enter__(self):
        if bpy.context.mode != "OBJECT" and bpy.context.object is not None:
            bpy.ops.object.mode_set(mode="OBJECT")
        self.state = BakeState(self.scene, self.view_layer).__enter__()
        try:
            self._prepare()
        except BaseException:
            self.state.__exit__(None, None, None)
            raise
        return self

    def _prepare(self):
        stand_ins = []
        depsgraph = bpy.context.evaluated_depsgraph_get()
        for plan in self.instance_plans:      # baked in the place of each instance
            obj = add_stand_in(self.state, self.scene, plan, depsgraph)
            stand_ins.append(obj)
            self.sizes[obj.name], self.uv_plans[obj.name] = plan.size, plan.uv
        for step in self.steps:
            step.objects = step.objects + stand_ins
        # an object's maps are finished together, after its last group's bake
        self.last_step = {o.name: i for i, s in enumerate(self.steps) for o in s.objects}
        self.baked = self.targets + stand_ins
        depsgraph.update()
        for obj in self.targets:
            plan = self.uv_plans[obj.name]
            if plan.make:
                make_unique_uv(obj, self.view_layer, self.sizes[obj.name])
                self._note(plan.note)
                depsgraph.update()
            layers = obj.data.uv_layers
            if layers.active.name != plan.uv_name:  # Cycles bakes the active UV map
                self.state.set(layers, "active_index", layers.find(plan.uv_name))
        self.state.configure(self.settings.samples, self.settings.margin, self.settings.seed)
        self.nodes = attach_targets(self.state, self.baked)
        self.geometry = {}
        if self.settings.denoise:
            for obj in self.baked:
                self.geometry[obj.name] = texel_geometry(
                    obj, depsgraph, self.uv_plans[obj.name].uv_name, self.sizes[obj.name],
                    self.settings.margin)
        self.done = 0
        self.start = time.perf_counter()

    def __exit__(self, exc_type, exc, tb):
        state, self.state = self.state, None
        return state.__exit__(exc_type, exc, tb)

    def step(self, cancel=None):
        """Bake the next light group; False when all are done.  ``cancel()`` -> True
        raises :class:`BakeCancelled` (between bakes)."""
        if cancel is not None and cancel():
            raise BakeCancelled("Bake cancelled: nothing was changed")
        if self.done == len(self.steps):
            return False
        step = self.steps[self.done]
        with BakeState(self.scene, self.view_layer) as inner:
            isolate(inner, self.scene, step.group)
            if bakes_sky(step.group):
                _portals.add_portals(inner, self.scene, self.windows)
            _panes.clear(inner, self.panes[step.group.name])
            images = {}
            for obj in step.objects:
                image = self.state.new_image(f"{obj.name}_{step.group.name}", self.sizes[obj.name])
                images[obj.name] = image
                for node in self.nodes[obj.name]:
                    node.image = image
            inner.select_only(step.objects)
            check_bake_result(self.state.bake(), step.objects, step.group)
            for image in images.values():
                _daylight.stamp(image, self.scene, step.group)
        for obj in step.objects:
            self.maps.setdefault(obj.name, {})[step.group.name] = (step.group, images[obj.name])
            if self.last_step[obj.name] == self.done:
                self._finish_maps(obj, [image for _, image in self.maps[obj.name].values()])
        self.done += 1
        self._report_progress(step)
        return self.done < len(self.steps)

    def _finish_maps(self, obj, images):
        """Once an object's last group is baked: denoise each of its maps (keeping the raw
        bake's local mean), average them over their 3D neighbours on the surface (across
        islands; one neighbour search for all of them), take the luminance, scale to lux:
        RGB = lux, A = 1."""
        n = images[0].size[0]
        pixels = []
        for image in images:
            px = np.empty(n * n * 4, dtype=np.float32)
            image.pixels.foreach_get(px)
            pixels.append(px.reshape(n, n, 4))
        Y = np.stack([luminance(px[..., :3]) for px in pixels])
        if self.settings.denoise:
            geo = self.geometry[obj.name]
            inside = geo.island >= 0
            colours = _denoise.island_colours(geo.island)
            guide = np.stack([
                _denoise.preserve_mean(luminance(_denoise.guard(
                    _denoise.denoise(px[..., :3], colours), px[..., :3])), Yg, inside)
                for px, Yg in zip(pixels, Y)])
            Y = filter3d.smooth_on_surface(guide, guide, geo.position, geo.normal, geo.covered,
                                           geo.texel)
            Y = [filter3d.extend_over_margin(Yg, geo.covered, inside) for Yg in Y]
        for image, px, Yg in zip(images, pixels, Y):
            px[..., :3] = (np.maximum(Yg, 0.0) * LUX_PER_BAKE_UNIT)[..., None]
            px[..., 3] = 1.0
            image.pixels.foreach_set(px.ravel())

    def _report_progress(self, step):
        done_work = sum(self.work[:self.done])
        fraction = done_work / max(sum(self.work), 1)
        elapsed = time.perf_counter() - self.start
        left = elapsed / fraction * (1 - fraction) if fraction > 0 else 0.0
        names = ", ".join(o.name for o in step.objects[:3]) + ("…" if len(step.objects) > 3 else "")
        message = (f"baked {names} <- {step.group.name} [{self.done}/{len(self.steps)}] "
                   f"{elapsed:.1f} s, ~{sizing.format_seconds(left)} left")
        if self.progress is not None:
            self.progress(fraction, message)
        else:
            print(f"LightFade: {message}", flush=True)

    # ------------------------------------------------------------------ storing
    def commit(self):
        """Store every baked map on its object (only after all groups are done)."""
        result = {}
        for obj in self.targets:
            kept = {g.name for g in self.groups if self._reusable(obj, g)}
            for group in self.groups:
                parts = self._reusable(obj, group)
                if parts and [p.name for p in parts] != [group.name]:
                    self._merge(obj, group, parts)
            baked = self.maps.get(obj.name, {})
            for name, (group, image) in baked.items():
                self.state.keep(image)
                store_map(obj, group, image, self.uv_plans[obj.name].uv_name)
            prune_maps(obj, kept | set(baked))
            result[obj.name] = {item.name: item.image for item in obj.lightfade.exposure_maps}
        for plan in self.instance_plans:      # the stand-in's maps are the atlases
            _instances.store_atlas(self.state, plan, self.maps.get(plan.stand_in.name, {}))
            result[plan.source.name] = {item.name: item.image
                                        for item in plan.source.lightfade.exposure_maps}
        return result

    def _merge(self, obj, group, parts):
        """Sum existing maps into ``group``'s map (a regroup without a bake)."""
        images = [p.image for p in parts]
        w, h = images[0].size
        total = np.zeros(w * h * 4, dtype=np.float32)
        buf = np.empty_like(total)
        for image in images:
            if tuple(image.size) != (w, h):
                raise LightFadeBakeError(f"\"{obj.name}\": maps of different sizes cannot be "
                                         "regrouped: bake exposure again")
            image.pixels.foreach_get(buf)
            total += buf
        total[3::4] = 1.0
        merged = self.state.new_image(f"{obj.name}_{group.name}", w, h)
        merged.pixels.foreach_set(total)
        self.state.keep(merged)
        store_map(obj, group, merged, obj.lightfade.uv_map or self.uv_plans[obj.name].uv_name)


def bake_exposure(context_or_scene, objects=None, settings=None, report=None, progress=None,
                  cancel=None, only_changed=False):
    """Bake one illuminance map (lux) per (mesh, light group) pair.

    Parameters
    ----------
    context_or_scene : bpy.types.Context or bpy.types.Scene
        Where to bake; with a scene, its first view layer (or the current one).
    objects : iterable of bpy.types.Object, optional
        Objects to bake; empty or None: every mesh using a material with LightFade enabled.
    settings : BakeSettings, optional
        Default: :meth:`BakeSettings.from_scene`.
    report : callable(str), optional
        Warnings and notes (skipped objects, UV maps made); default: print.
    progress : callable(fraction, message), optional
        Called after each Cycles bake; default: one printed line per bake.
    cancel : callable() -> bool, optional
        Checked between bakes; True cancels (settings restored, no map stored).
    only_changed : bool
        Keep maps whose light group did not change; sum maps of groups that merged.

    Returns
    -------
    dict
        ``{"maps": {object: {group: Image}}, "skipped": [messages], "notes": [messages],
        "groups": [(group, [emitters])], "emitters": [(name, kind)], "seconds": float}``.
        Image pixels are lux (R = G = B = luminance of the irradiance).

    Raises
    ------
    LightFadeBakeError
        Nothing to bake, no emitters, linked data, overlapping UVs from a modifier... (all
        problems, one per line); :class:`.common.BakeCancelled` when cancelled.
    """
    job = ExposureBake(context_or_scene, objects, settings, report, progress, only_changed)
    job.plan()
    start = time.perf_counter()
    with job:
        while job.step(cancel):
            pass
        if cancel is not None and cancel():
            raise BakeCancelled("Bake cancelled: nothing was changed")
        maps = job.commit()
    return {
        "maps": maps,
        "skipped": job.skipped,
        "notes": job.notes,
        "groups": [(g.name, g.member_names) for g in job.groups],
        "emitters": [(e.name, e.kind) for e in job.emitters],
        "seconds": time.perf_counter() - start,
    }

