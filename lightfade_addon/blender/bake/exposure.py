"""The exposure bake: one illuminance map (lux) per object and light group, with Cycles.

For each light group (:mod:`.emitters`) every other emitter is switched off and Cycles
bakes the DIFFUSE pass (direct + indirect light, no colour) of all target objects at
once, each into its own float image through a node added to its real materials
(:mod:`.targets`), whose baked texels read as a Lambertian (:mod:`.surface`): the light
arriving, whatever the material.  A group is baked in passes (:mod:`.adaptive`: one
for a fixed bake; more where a map is above its noise target), each finished as a map
(:mod:`.passes`: denoised, 3D-filtered), the map their mean in lux; once every group is
done the maps are stored on the objects (:mod:`.maps`).  Everything the bake changes is
put back by :class:`.state.BakeState`, also on error or cancel; a cancelled bake stores
nothing.  Before any Cycles work, every object is checked (:mod:`.uvmaps`) and all
problems are reported at once.  :func:`.run.bake_exposure` runs a whole bake in one call."""

from __future__ import annotations

import time
from dataclasses import dataclass

import bpy

from . import adaptive
from . import batch as _batch
from . import daylight as _daylight
from . import geometry as _geometry
from . import instance_frames, instances as _instances
from . import panes as _panes
from . import portals as _portals
from . import sizing
from .common import BakeCancelled, LightFadeBakeError
from .emitters import (
    bakes_sky,
    group_emitters,
    find_emitters,
    isolate,
    uncounted_emissive,
    uncounted_note,
)
from .maps import members, prune_maps, store_map, store_sum
from .passes import Passes
from .settings import BakeSettings
from .stand_in import add_stand_in
from .state import BakeState
from .targets import attach_targets, check_bake_result, find_targets, validate_targets
from .uvmaps import make_unique_uv, texel_geometry


@dataclass
class _Step:
    group: object
    objects: list
    #: Pass of the group's maps this bake adds (:mod:`.adaptive`; 0 for a fixed bake).
    index: int = 0
    #: Its samples per texel (None: the settings' per pass).
    samples: int | None = None


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
                 progress=None, only_changed=False, groups=None, batch=True):
        self.scene, self.view_layer = scene_and_layer(context_or_scene)
        #: names of the light groups to bake (None: all); a farm task bakes one
        self.only_groups = None if groups is None else set(groups)
        self.settings = settings or BakeSettings.from_scene(self.scene)
        self.report = report or print
        self.progress = progress
        self.only_changed = only_changed
        self.batch = batch
        self.objects = list(objects or [])
        self.skipped, self.notes = [], []
        self.state = None
        self.maps = {}  # object name -> {group name: temp image}
        self.baked = {}  # baked object name (an object, an atlas) -> {group: (group, image, names)}
        self.noise = {}  # (object name, group name) -> adaptive.Noise (adaptive bakes)
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
                                                       self.settings.unwrap, plans)
        for msg in warnings:
            self._warn(msg)
        self.instance_plans = [plans[o] for o in targets if o in plans]
        targets = [o for o in targets if o not in plans]
        problems += _instances.plan_tiles(self.instance_plans, depsgraph, self.settings,
                                          self._note)
        for line in instance_frames.frame_changes(scene, layer, self.instance_plans):
            self._note(line)
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
            size, plan = _geometry.checked_plan(obj, depsgraph, self.settings)
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
            if self.only_groups is not None and group.name not in self.only_groups:
                continue
            names = set(group.member_names)
            objs = [o for o in targets if o.name not in names and not self._reusable(o, group)]
            for index in range(self.settings.first_passes if objs or self.instance_plans else 0):
                self.steps.append(_Step(group, objs, index))   # instances: in every group
        self.work = []
        self._planned(self.steps)
        # small objects baked together, one temporary mesh and atlas per batch
        self.batches = _batch.Batches(targets, self.sizes, self.groups, self.settings.margin,
                                      self.batch)
        return self

    def _planned(self, steps):
        """Add ``steps`` to the work; an object's passes are finished together, after its
        last step so far."""
        self.last_step = {o.name: i for i, s in enumerate(self.steps) for o in s.objects}
        self.work += [sum(n ** 2 for n in sizes) * self._samples(s)
                      for s, sizes in zip(steps, self._step_sizes(steps))]

    def _step_sizes(self, steps):
        """Map widths per step: its objects' and each instanced source's atlas (whose
        stand-in joins the steps when the bake starts)."""
        return [[self.sizes[o.name] for o in s.objects] + [
            p.size for p in self.instance_plans if p.stand_in not in s.objects] for s in steps]

    def _samples(self, step):
        return step.samples or self.settings.samples_per_pass()

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
        """:class:`.sizing.Estimate` of the planned bake (a range for an adaptive one)."""
        sizes = self._step_sizes([s for s in self.steps if s.index == 0])
        return sizing.estimate_for(self.scene, sizes, self.settings)

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
        self.last_step = {o.name: i for i, s in enumerate(self.steps) for o in s.objects}
        self.bakeables = self.targets + stand_ins
        depsgraph.update()
        for obj in self.targets:
            plan = self.uv_plans[obj.name]
            if plan.make:
                make_unique_uv(obj, self.view_layer, self.sizes[obj.name])
                self._note(plan.note)
                depsgraph.update()
                _geometry.check_made_map(obj, depsgraph)
            layers = obj.data.uv_layers
            if layers.active.name != plan.uv_name:  # Cycles bakes the active UV map
                self.state.set(layers, "active_index", layers.find(plan.uv_name))
        self.state.configure(self.settings.samples_per_pass(), self.settings.margin,
                             self.settings.seed)
        depsgraph = self.batches.stand_in(self.state, self.targets, self.uv_plans, depsgraph,
                                          self.scene, self.view_layer)
        alone, atlases = self.batches.split(self.bakeables)
        self.nodes = attach_targets(self.state, alone + [obj for _, obj in atlases])
        self.geometry = {}
        if self.settings.denoise or self.settings.adaptive:
            for obj in alone:
                self.geometry[obj.name] = texel_geometry(
                    obj, depsgraph, self.uv_plans[obj.name].uv_name, self.sizes[obj.name],
                    self.settings.margin)
            self.geometry.update(self.batches.geometry(depsgraph, self.settings.margin))
        regions = self.batches.regions()
        regions.update({p.stand_in.name: p.regions() for p in self.instance_plans})
        self.passes = Passes(self.settings, self.geometry, regions)
        self.done = 0
        self.start = time.perf_counter()

    def __exit__(self, exc_type, exc, tb):
        state, self.state = self.state, None
        return state.__exit__(exc_type, exc, tb)

    def step(self, cancel=None):
        """Bake the next light group (or pass of one); False when all are done.
        ``cancel()`` -> True raises :class:`BakeCancelled` (between bakes)."""
        if cancel is not None and cancel():
            raise BakeCancelled("Bake cancelled: nothing was changed")
        if self.done == len(self.steps):
            return False
        step = self.steps[self.done]
        limit = self.settings.max_seconds       # extra passes start before the time cap
        if not (step.index >= self.settings.first_passes and 0 < limit
                < time.perf_counter() - self.start):
            self._bake(step)
        for key, _, _, names in self.batches.units(step.objects, self.sizes):
            if max(self.last_step[n] for n in names) == self.done:
                self.passes.finish(key)
        self.done += 1
        self._report_progress(step)
        if self.done == len(self.steps) and not self._next_round():
            self._write_maps()
        return self.done < len(self.steps)

    def _bake(self, step):
        """One Cycles call: pass ``step.index`` of ``step.group`` for ``step.objects`` (the
        small ones in their atlases, :mod:`.batch`); each map denoised (the raw bake's
        local mean kept) into :attr:`pending`."""
        units = self.batches.units(step.objects, self.sizes)
        group = step.group.name
        with BakeState(self.scene, self.view_layer) as inner:
            isolate(inner, self.scene, step.group)
            if bakes_sky(step.group):
                _portals.add_portals(inner, self.scene, self.windows)
            _panes.clear(inner, self.panes[step.group.name])
            inner.set(self.scene.cycles, "seed",
                      adaptive.pass_seed(self.settings.seed, group, step.index))
            inner.set(self.scene.cycles, "samples", self._samples(step))
            images = {}
            for key, obj, size, _ in units:
                known = self.baked.get(key, {}).get(group)
                images[key] = image = known[1] if known else self.state.new_image(
                    f"{key}_{group}", size)
                for node in self.nodes[key]:
                    node.image = image
            baked = [obj for _, obj, _, _ in units]
            inner.select_only(baked)
            check_bake_result(self.state.bake(), baked, step.group)
            for image in images.values():
                _daylight.stamp(image, self.scene, step.group)
        for key, _, _, names in units:
            known = self.baked.get(key, {}).get(group)
            names = list(dict.fromkeys((known[2] if known else []) + names))
            self.baked.setdefault(key, {})[group] = (step.group, images[key], names)
            self.passes.add(key, group, self._samples(step), images[key], step.index)

    def _next_round(self):
        """Adaptive bakes: measure every map's error from its passes (:mod:`.adaptive`)
        and plan one more pass, of the samples it lacks, for each map above the target;
        True if any were planned."""
        if not self.settings.adaptive:
            return False
        baked = [obj for _, obj, _, _ in self.batches.units(self.bakeables, self.sizes)]
        more = self.passes.wanted(baked)    # measures every map, also when late
        late = 0 < self.settings.max_seconds < time.perf_counter() - self.start
        by_name = {o.name: o for o in self.bakeables}
        steps = [] if late else [
            _Step(g, [by_name[n] for obj in objs for n in self.baked[obj.name][name][2]],
                  index, extra)
            for g in self.groups for (name, index, extra), objs in
            sorted(more.items(), key=lambda kv: kv[0][1:]) if name == g.name]
        self.steps += steps
        self._planned(steps)
        return bool(steps)

    def _write_maps(self):
        """Every map from its passes, each atlas's cut into its objects' maps; the report
        names the noise each map reached and those that hit the cap."""
        for key, groups in self.passes.passes.items():
            for group in groups:
                self.passes.write(self.baked[key][group][1], key, group)
        for key, entries in self.baked.items():
            atlas = self.batches.atlas_of(key)
            if atlas is None:
                self.maps[key] = {g: (group, image) for g, (group, image, _) in entries.items()}
            else:
                for name, maps in _batch.cut(self.state, self.scene, atlas, entries).items():
                    self.maps.setdefault(name, {}).update(maps)
        if self.settings.adaptive:
            self.noise = self.batches.per_object(self.passes.noise, self.baked,
                                                 self.passes.region_noise)
            self._note(adaptive.noise_note(self.noise, self.settings))

    def _report_progress(self, step):
        fraction = sum(self.work[:self.done]) / max(sum(self.work), 1)
        elapsed = time.perf_counter() - self.start
        left = elapsed / fraction * (1 - fraction) if fraction > 0 else 0.0
        names = ", ".join(o.name for o in step.objects[:3]) + ("…" if len(step.objects) > 3 else "")
        names += f" (pass {step.index + 1})" if self.settings.adaptive else ""
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
                    store_sum(self.state, obj, group, parts,
                              self.uv_plans[obj.name].uv_name)
            baked = self.maps.get(obj.name, {})
            for name, (group, image) in baked.items():
                self.state.keep(image)
                store_map(obj, group, image, self.uv_plans[obj.name].uv_name)
                self.passes.record(obj.lightfade.exposure_maps[group.name],
                                   self.batches.key(obj.name), group.name)
            prune_maps(obj, kept | set(baked))
            result[obj.name] = {item.name: item.image for item in obj.lightfade.exposure_maps}
        for plan in self.instance_plans:      # the stand-in's maps are the atlases
            _instances.store_atlas(self.state, plan, self.maps.get(plan.stand_in.name, {}))
            result[plan.source.name] = {item.name: item.image
                                        for item in plan.source.lightfade.exposure_maps}
        return result
