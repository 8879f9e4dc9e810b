"""The farm job: ``farm-job`` writes an OpenJD bundle; its steps run ``farm-bake``,
``farm-merge`` and ``farm-age`` (``docs/farm.md``).

``farm-job`` opens the scene read-only, plans the bake as the Bake operator would
(:class:`..blender.bake.ExposureBake`: targets, light groups, map sizes, UV maps), times
tiny bakes for the rate (:func:`..blender.bake.calibrate`), sizes chunks of objects
from the estimate (:mod:`.chunks`) and writes ``template.yaml`` (:mod:`.openjd`).  The
task plan (scene hash, bake settings and their hash, groups, chunks) is embedded in it.

``farm-bake`` bakes one light group for one chunk on the public bake
(``ExposureBake(..., groups=[name])``: the same planning, seeds, denoising and lux as a
one-machine bake) and writes the finished maps atomically (:mod:`.taskmaps`); it never
saves the scene.  ``farm-merge`` checks every task's maps before it changes anything,
then stores them as the bake's own commit does and saves the file safely.  Each
refuses with one line (:class:`.files.Refused`) and exit status 1.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict

import bpy
import numpy as np

from .. import api
from ..blender.bake import BakeSettings, ExposureBake, LightFadeBakeError, calibrate
from ..blender.bake import daylight as _daylight
from ..blender.bake import sizing
from ..blender.bake.maps import prune_maps, store_map
from ..blender.bake.uvmaps import make_unique_uv
from ..output import plural
from . import openjd, taskmaps
from .chunks import chunk_objects
from .files import Refused, open_blend, save_blend, write_text
from .parser import BAKE_FLAGS
from .steps import _age, _apply_overrides, _one_line, _targets_or_refuse, bake_overrides
from ..blender.targets import format_problems, material_problems

#: Plan layout version: a task refuses a plan of another.
PLAN_FORMAT = 1
#: Seconds a task spends besides baking: Blender's start, opening the file, planning,
#: Cycles' scene build, the maps' write (~8 s a task for the generated hall of
#: benchmarks/farm.py on this 2-core machine; a farm's large files take longer to
#: open): docs/farm.md.
TASK_OVERHEAD = 10.0


# ----------------------------------------------------------------------------- the plan


def settings_record(scene, settings, groups):
    """What makes two bakes of one scene alike: the bake settings, the light groups
    with their emitters, Blender's version (its Cycles) — hashed into the job."""
    return {"settings": asdict(settings),
            "groups": [[g.name, list(g.member_names)] for g in groups],
            "blender": ".".join(map(str, bpy.app.version[:2]))}


def _quiet(_msg):
    pass


def plan_bake(scene, objects, groups=None, report=_quiet):
    """The planned :class:`ExposureBake` of ``objects`` (one-line refusal on a problem)."""
    settings = BakeSettings.from_scene(scene)
    try:
        return ExposureBake(scene, objects, settings, report=report, progress=_progress,
                            groups=groups).plan()
    except LightFadeBakeError as err:
        raise Refused(_one_line(err)) from None


def _progress(_fraction, message):
    print(f"lightfade: {message}", flush=True)


def object_seconds(scene, job):
    """Estimated seconds of each target's bake for one light group."""
    s = job.settings
    return [sizing.estimate(scene, [[job.sizes[o.name]]], s.samples, s.denoise).seconds
            for o in job.targets]


def read_plan(path):
    try:
        with open(path, encoding="utf-8") as f:
            plan = json.load(f)
    except (OSError, ValueError) as err:
        raise Refused(f"cannot read the job's plan {path} ({err})") from None
    if plan.get("format") != PLAN_FORMAT:
        raise Refused(f"the plan {path} is of another LightFade (format "
                      f"{plan.get('format')}, not {PLAN_FORMAT}): make the job again")
    return plan


def _check_scene_file(path, plan):
    sha = taskmaps.file_sha256(path)
    if sha != plan["scene"]:
        raise Refused(f"the scene file changed since the job was made (SHA-256 {sha[:12]}..., "
                      f"the job's {plan['scene'][:12]}...): make the job again (farm-job)")


def open_planned(path, plan, names, groups=None):
    """Open the job's scene with the job's bake settings; the planned bake of the objects
    ``names`` (``groups``: only these light groups), checked against the plan's settings
    hash."""
    _check_scene_file(path, plan)
    scene = open_blend(path)
    _apply_overrides(scene, _Flags(plan["overrides"]))
    objects = []
    for name in names:
        obj = scene.objects.get(name)
        if obj is None:
            raise Refused(f"object '{name}' of the job is not in the scene: make the job again")
        objects.append(obj)
    job = plan_bake(scene, objects, groups)
    got = taskmaps.settings_hash(settings_record(scene, job.settings, job.groups))
    if got != plan["settings_hash"]:
        raise Refused(f"the bake settings or light groups differ from the job's (settings "
                      f"hash {got}, the job's {plan['settings_hash']}): make the job again "
                      "with this Blender and LightFade")
    return scene, job


class _Flags:
    """The bake flags of the plan, as ``args`` for :func:`.steps._apply_overrides`."""

    def __init__(self, overrides):
        for flag, _path, *_rest in BAKE_FLAGS:
            setattr(self, flag[2:].replace("-", "_"), overrides.get(flag))


# ----------------------------------------------------------------------------- farm-job


def _job_checks(scene, args, objects):
    problems = material_problems(scene, objects)
    if problems:
        raise Refused(_one_line(format_problems(problems)))
    if args.years is not None:
        if scene.camera is None:
            raise Refused(f"scene '{scene.name}' has no camera: set one (Scene Properties > "
                          "Camera) for the Render step, or leave out --years")
        if scene.render.is_movie_format:
            raise Refused(f"scene '{scene.name}' renders to a movie format "
                          f"({scene.render.image_settings.file_format}): choose an image "
                          "format (Output Properties > Output) for the Render step")


def _chunks(scene, job, args, say):
    say("timing tiny bakes for the estimate")
    calibrate(scene, job.targets[0])
    seconds = object_seconds(scene, job)
    chunks = chunk_objects([o.name for o in job.targets], seconds, args.task_minutes * 60.0,
                           TASK_OVERHEAD)
    by_name = dict(zip([o.name for o in job.targets], seconds))
    return chunks, [sum(by_name[n] for n in c) for c in chunks], sum(seconds)


def _relative(path, folder):
    """``path`` relative to ``folder`` where it lies inside it (OpenJD joins a PATH
    default to the template's folder and refuses one outside it), else None."""
    try:
        rel = os.path.relpath(path, folder)
    except ValueError:   # another drive
        return None
    return None if rel.split(os.sep)[0] == os.pardir else rel


def flamenco_settings(spec, scene, out):
    """The settings of the Flamenco job type ``tools/flamenco/lightfade_farm.js``."""
    return {"scene": scene, "plan": os.path.join(out, "plan.json"),
            "groups": "\n".join(spec.groups), "chunks": spec.chunks,
            "work_dir": os.path.join(out, spec.work), "output_dir": os.path.join(out, spec.output),
            "stem": spec.stem, "years": spec.years or 0.0,
            "frame_start": spec.frames[0], "frame_end": spec.frames[1]}


def do_farm_job(path, args, say):
    path = os.path.abspath(path)
    sha = taskmaps.file_sha256(path)
    scene = open_blend(path)
    objects = _targets_or_refuse(scene)
    _job_checks(scene, args, objects)
    _apply_overrides(scene, args)
    job = plan_bake(scene, objects, report=say)
    chunks, seconds, one_group = _chunks(scene, job, args, say)
    groups = [g.name for g in job.groups]
    overrides = {flag: v for flag, _p, *_r in BAKE_FLAGS
                 if (v := getattr(args, flag[2:].replace("-", "_"), None)) is not None}
    plan = {"format": PLAN_FORMAT, "scene": sha, "file": os.path.basename(path),
            "overrides": overrides,
            "settings_hash": taskmaps.settings_hash(settings_record(scene, job.settings,
                                                                    job.groups)),
            "groups": [[g.name, list(g.member_names)] for g in job.groups],
            "chunks": chunks, "seconds": [round(s, 1) for s in seconds]}
    out = os.path.abspath(args.out)
    first = scene.frame_start
    frames = (first, first + max(int(args.frames or math.ceil(args.years or 0) + 1), 2) - 1)
    spec = openjd.JobSpec(
        name=os.path.basename(path), scene=_relative(path, out), work="work", output="output",
        stem=os.path.splitext(os.path.basename(path))[0],
        plan=json.dumps(plan, indent=1) + "\n", groups=groups, chunks=len(chunks),
        bake_timeout=int(max(3600, 10 * max(seconds) + 600)), years=args.years,
        frames=frames)
    template = openjd.job_template(spec)
    openjd.validate(template)
    target = write_text(os.path.join(out, "template.yaml"), openjd.to_yaml(template))
    write_text(os.path.join(out, "parameter_values.yaml"),
               openjd.to_yaml(openjd.parameter_values({"SceneFile": path})))
    write_text(os.path.join(out, "plan.json"), spec.plan)
    write_text(os.path.join(out, "flamenco_settings.json"),
               json.dumps(flamenco_settings(spec, path, out), indent=1) + "\n")
    n = len(groups) * len(chunks)
    return (f"{plural(n, 'Bake task')} ({plural(len(groups), 'light group')} x "
            f"{plural(len(chunks), 'chunk')} of {plural(len(job.targets), 'object')}, "
            f"~{sizing.format_seconds(max(seconds))} each at most; one machine "
            f"~{sizing.format_seconds(one_group * len(groups))}) -> {target}")


# ----------------------------------------------------------------------------- farm-bake


def _uv(obj, uv_name):
    data = obj.data.uv_layers[uv_name].data
    uv = np.empty(len(data) * 2, dtype=np.float32)
    data.foreach_get("uv", uv)
    return uv


def _lux(image):
    w, h = image.size
    px = np.empty(w * h * image.channels, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(h, w, image.channels)[..., 0].copy()


def _task(plan, group, chunk):
    names = [g for g, _members in plan["groups"]]
    if group not in names:
        raise Refused(f"light group '{group}' is not in the job (its groups: "
                      f"{', '.join(names)})")
    if not 0 <= chunk < len(plan["chunks"]):
        raise Refused(f"chunk {chunk} is not in the job (0 to {len(plan['chunks']) - 1})")
    return names.index(group)


def bake_group(scene, job, group):
    """Run the planned bake ``job`` of one light group: ``(maps, about)`` — each object's
    lux map, its UV map and UV hash (the bake's own seed, denoising and units)."""
    maps, about = {}, {}
    try:
        with job:
            while job.step():
                pass
            for name, by_group in job.maps.items():
                maps[name] = _lux(by_group[group][1])
                uv_name = job.uv_plans[name].uv_name
                about[name] = {"uv_map": uv_name,
                               "uv_hash": taskmaps.uv_hash(_uv(scene.objects[name], uv_name))}
    except LightFadeBakeError as err:
        raise Refused(_one_line(err)) from None
    return maps, about


def do_farm_bake(path, args, say):
    plan = read_plan(args.plan)
    gi = _task(plan, args.group, args.chunk)
    label = taskmaps.task_label(args.group, args.chunk)
    scene, job = open_planned(path, plan, plan["chunks"][args.chunk], groups=[args.group])
    say(f"{label}: baking {plural(len(job.targets), 'object')}")
    maps, about = bake_group(scene, job, args.group)
    header = {"scene": plan["scene"], "settings": plan["settings_hash"], "group": args.group,
              "chunk": args.chunk}
    target = os.path.join(os.path.abspath(args.maps), taskmaps.file_name(gi, args.chunk))
    try:
        taskmaps.write(target, header, maps, about)
    except OSError as err:
        raise Refused(f"could not write {target} ({err})") from None
    return f"{label}: {plural(len(maps), 'map')} -> {target}"


# ----------------------------------------------------------------------------- farm-merge


def expected_maps(plan, job):
    """``[(file, label, group, {object: {"shape", "uv_map"}})]`` of every Bake task."""
    tasks = []
    for gi, (group, members) in enumerate(plan["groups"]):
        for c, names in enumerate(plan["chunks"]):
            want = {n: {"shape": [job.sizes[n], job.sizes[n]],
                        "uv_map": job.uv_plans[n].uv_name}
                    for n in names if n not in set(members)}
            tasks.append((taskmaps.file_name(gi, c), taskmaps.task_label(group, c), group,
                          want))
    return tasks


def checked_maps(plan, job, folder):
    """Every task's header and maps, after checking them all (one line naming the first
    task to rerun)."""
    found = []
    for name, label, group, want in expected_maps(plan, job):
        path = os.path.join(folder, name)
        try:
            header = taskmaps.check(path, label, plan["scene"], plan["settings_hash"], group,
                                    want)
        except taskmaps.MapProblem as err:
            raise Refused(str(err)) from None
        found.append((label, group, header, taskmaps.read(path)[1]))
    return found


def _same_uvs(scene, job, found):
    """Make the UV maps the bake makes (as its tasks did) and check them against theirs."""
    made = set()
    for label, _group, header, _maps in found:
        for o in header["objects"]:
            obj, plan = scene.objects[o["name"]], job.uv_plans[o["name"]]
            if plan.make and o["name"] not in made:
                make_unique_uv(obj, job.view_layer, job.sizes[o["name"]])
                made.add(o["name"])
            if (o["uv_map"] not in obj.data.uv_layers
                    or taskmaps.uv_hash(_uv(obj, o["uv_map"])) != o["uv_hash"]):
                raise Refused(f"the UV map '{o['uv_map']}' of '{o['name']}' is not the one "
                              f"{label} baked on: rerun {label}")


def _image(name, lux):
    h, w = lux.shape
    image = bpy.data.images.new(name, w, h, alpha=False, float_buffer=True)
    image.colorspace_settings.is_data = True
    px = np.empty((h, w, 4), dtype=np.float32)
    px[..., :3] = lux[..., None]
    px[..., 3] = 1.0
    image.pixels.foreach_set(px.ravel())
    return image


def store_maps(scene, job, found):
    """Store the maps on their objects as the bake's commit does; returns how many."""
    groups = {g.name: g for g in job.groups}
    n = 0
    for _label, group, _header, maps in found:
        for name, lux in maps.items():
            obj = scene.objects[name]
            image = _image(f"{name}_{group}", lux)
            _daylight.stamp(image, scene, groups[group])
            store_map(obj, groups[group], image, job.uv_plans[name].uv_name)
            n += 1
    for obj in job.targets:
        prune_maps(obj, set(groups))
    return n


def do_farm_merge(path, args, say):
    plan = read_plan(args.plan)
    scene, job = open_planned(path, plan, [n for chunk in plan["chunks"] for n in chunk])
    found = checked_maps(plan, job, os.path.abspath(args.maps))
    _same_uvs(scene, job, found)
    n = store_maps(scene, job, found)
    out = os.path.abspath(args.output)
    if os.path.realpath(out) == os.path.realpath(path):
        raise Refused(f"the output {out} is the job's scene, which stays read-only")
    save_blend(out)
    return f"{plural(n, 'map')} from {plural(len(found), 'Bake task')} -> {out}"


# ----------------------------------------------------------------------------- farm-age


def do_farm_age(path, args, say):
    first, last = args.frames
    scene = open_blend(path)
    n = _age(scene, args.years, say)
    try:
        api.keyframe_years(scene, [(first, 0.0), (last, args.years)])
    except api.AgingError as err:
        raise Refused(_one_line(err)) from None
    scene.frame_start, scene.frame_end = first, last
    out = save_blend(os.path.abspath(args.output))
    return (f"{plural(n, 'material')}, years 0 at frame {first} to {args.years:g} at "
            f"frame {last} -> {out}")


ACTIONS = {"farm-job": do_farm_job, "farm-bake": do_farm_bake, "farm-merge": do_farm_merge,
           "farm-age": do_farm_age}
