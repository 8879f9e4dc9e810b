"""One file, one sub-command: open, bake if needed, age, render or describe, save.

Each ``do_*`` function takes the path of one input file and the parsed arguments,
returns a short result line for the summary table, and raises
:class:`.files.Refused` with a one-line reason when the file cannot be processed.
They call the add-on's Python API (:mod:`..api`), so a file aged here is the same as
one aged from the UI.
"""

from __future__ import annotations

import json
import os

import bpy

from .. import api
from ..blender.bake import LightFadeBakeError
from . import files, info
from .files import Refused
from .parser import BAKE_FLAGS

#: Name added to the input's stem when no --output is given.
SUFFIX = {"bake": "_baked", "age": "_aged"}


# ----------------------------------------------------------------------------- settings


def bake_overrides(args):
    """``{Scene.lightfade property: value}`` for the bake flags given on the command line."""
    return {prop: getattr(args, flag[2:].replace("-", "_"))
            for flag, prop, *_rest in BAKE_FLAGS
            if getattr(args, flag[2:].replace("-", "_"), None) is not None}


def check_overrides(args, scene):
    """The first bake flag outside its setting's range, as a message; None if all fit."""
    rna = scene.lightfade.bl_rna.properties
    flags = {prop: flag for flag, prop, *_rest in BAKE_FLAGS}
    for prop, value in bake_overrides(args).items():
        p = rna[prop]
        if p.type == "ENUM":
            allowed = [item.identifier.lower() for item in p.enum_items]
            if str(value).lower() not in allowed:
                return f"{flags[prop]} {value}: must be one of {', '.join(allowed)}"
        elif not p.hard_min <= value <= p.hard_max:
            return f"{flags[prop]} {value}: must be between {p.hard_min} and {p.hard_max}"
    return None


def _apply_overrides(scene, args):
    props = scene.lightfade
    for prop, value in bake_overrides(args).items():
        if props.bl_rna.properties[prop].type == "ENUM":
            value = str(value).upper()
        setattr(props, prop, value)


# ------------------------------------------------------------------------------- helpers


def _bake(scene, objects, args, say):
    _apply_overrides(scene, args)
    props = scene.lightfade
    say(f"baking {len(objects)} object(s) at {props.bake_resolution} px, "
        f"{props.bake_samples} samples")
    try:
        result = api.bake(scene, objects=objects)
    except LightFadeBakeError as err:
        raise Refused(str(err)) from None
    return sum(len(m) for m in result["maps"].values())


def _targets_or_refuse(scene):
    objects = info.target_objects(scene)
    if not objects:
        raise Refused("nothing to age: no material of a mesh has LightFade enabled "
                      "(Material Properties > LightFade > Age this Material)")
    return objects


def _bake_if_needed(scene, args, say):
    """Bake the target objects that miss an exposure map (all with ``--rebake``)."""
    objects = _targets_or_refuse(scene)
    if not args.rebake:
        objects = [o for o in objects if info.missing_maps(scene, o)]
    return _bake(scene, objects, args, say) if objects else 0


def _age(scene, years, say):
    wanted = len(info.would_age(scene))
    try:
        images = api.age_scene(scene, years=years)
    except api.AgingError as err:
        raise Refused(str(err)) from None
    note = "" if len(images) == wanted else f" (of {wanted}; see the messages above)"
    say(f"aged {len(images)} material(s){note} to {years:g} years")
    return len(images), note


def _years_text(years):
    return f"{years:g}".replace("+", "")


# ----------------------------------------------------------------------------- actions


def do_bake(path, args, say):
    out = files.output_blend(path, args.output, args.in_place, SUFFIX["bake"],
                             len(args.files) > 1)
    scene = files.open_blend(path)
    n = _bake(scene, _targets_or_refuse(scene), args, say)
    files.save_blend(out)
    return f"{n} map(s) -> {out}"


def do_age(path, args, say):
    out = files.output_blend(path, args.output, args.in_place, SUFFIX["age"],
                             len(args.files) > 1)
    scene = files.open_blend(path)
    baked = _bake_if_needed(scene, args, say)
    n, note = _age(scene, args.years, say)
    files.save_blend(out)
    made = f"baked {baked} map(s), " if baked else ""
    return f"{made}{n} material(s){note} at {args.years:g} y -> {out}"


def do_render_years(path, args, say):
    scene = files.open_blend(path)
    if scene.camera is None:
        raise Refused(f"scene '{scene.name}' has no camera: set one (Scene Properties > "
                      "Camera) to render from")
    if scene.render.is_movie_format:
        raise Refused(f"scene '{scene.name}' renders to a movie format "
                      f"({scene.render.image_settings.file_format}): choose an image format "
                      "(Output Properties > Output)")
    _bake_if_needed(scene, args, say)
    _age(scene, max(args.years), say)
    stem = os.path.splitext(os.path.basename(path))[0]
    written = []
    for years in args.years:
        api.set_years(scene, years)
        target = os.path.join(os.path.abspath(args.output),
                              f"{stem}_{_years_text(years)}y{scene.render.file_extension}")
        bpy.ops.render.render(write_still=False, scene=scene.name)
        written.append(files.save_render(scene, target))
        say(f"{years:g} years -> {target}")
    return f"{len(written)} still(s) -> {os.path.abspath(args.output)}"


def do_info(path, args, say):
    scene = files.open_blend(path)
    report = info.gather(scene)
    report["file"] = os.path.abspath(path)
    if args.json:
        args.json_reports.append(report)
    else:
        print(info.as_text(report), flush=True)
    n = len(report["would_age"])
    return f"{n} material(s) would age" if n else "nothing to age"


ACTIONS = {"bake": do_bake, "age": do_age, "render-years": do_render_years, "info": do_info}


def dump_json(reports):
    """The ``info --json`` document: one report per file that could be read."""
    return json.dumps({"files": reports}, indent=2)
