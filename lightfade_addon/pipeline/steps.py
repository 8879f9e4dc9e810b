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
from ..output import maps_made, plural, quiet
from ..blender.bake import LightFadeBakeError
from ..blender.targets import format_problems, material_problems
from .files import Refused, open_blend, output_blend, save_blend, save_render
from .info import as_text, gather, needs_bake, target_objects
from .parser import BAKE_FLAGS

#: Name added to the input's stem when no --output is given.
SUFFIX = {"bake": "_baked", "age": "_aged"}


# ----------------------------------------------------------------------------- settings


def bake_overrides(args):
    """``{property path: value}`` for the bake flags given on the command line."""
    return {path: getattr(args, flag[2:].replace("-", "_"))
            for flag, path, *_rest in BAKE_FLAGS
            if getattr(args, flag[2:].replace("-", "_"), None) is not None}


def _setting(scene, path):
    """``(owner, name, rna)`` of a setting ``"group.name"`` of ``scene``."""
    group, name = path.split(".")
    owner = getattr(scene, group)
    return owner, name, owner.bl_rna.properties[name]


def check_overrides(args, scene):
    """The first bake flag outside its setting's range, as a message; None if all fit."""
    flags = {path: flag for flag, path, *_rest in BAKE_FLAGS}
    for path, value in bake_overrides(args).items():
        _owner, _name, p = _setting(scene, path)
        if p.type == "ENUM":
            allowed = [item.identifier.lower() for item in p.enum_items]
            if str(value).lower() not in allowed:
                return f"{flags[path]} {value}: must be one of {', '.join(allowed)}"
        elif not p.hard_min <= value <= p.hard_max:
            return f"{flags[path]} {value}: must be between {p.hard_min:g} and {p.hard_max:g}"
    return None


def _apply_overrides(scene, args):
    for path, value in bake_overrides(args).items():
        owner, name, p = _setting(scene, path)
        setattr(owner, name, str(value).upper() if p.type == "ENUM" else value)


# ------------------------------------------------------------------------------- helpers


def _bake(scene, objects, args, say):
    # what Age would refuse whatever the bake (an image that cannot be read ...), as the
    # Bake operator does: before any Cycles work, which would only print the image
    # library's complaint ahead of the refusal
    problems = material_problems(scene, objects)
    if problems:
        raise Refused(_one_line(format_problems(problems)))
    _apply_overrides(scene, args)
    settings = ", ".join(f"{flag[2:]} {getattr(*_setting(scene, path)[:2])}"
                         for flag, path, *_rest in BAKE_FLAGS)
    say(f"baking {plural(len(objects), 'object')} ({settings})")
    try:
        result = api.bake(scene, objects=objects)
    except LightFadeBakeError as err:
        raise Refused(_one_line(err)) from None
    say(f"baked {maps_made(result)}")
    return sum(len(m) for m in result["maps"].values())


def _targets_or_refuse(scene):
    objects = target_objects(scene)
    if not objects:
        raise Refused("nothing to age: no material of a mesh has LightFade enabled "
                      "(Material Properties > LightFade > Age this Material)")
    return objects


def _bake_if_needed(scene, args, say):
    """Bake the target objects that miss a map or whose light groups split (all with
    ``--rebake``)."""
    objects = _targets_or_refuse(scene)
    if not args.rebake:
        objects = [o for o in objects if needs_bake(scene, o)]
    return _bake(scene, objects, args, say) if objects else 0


def _one_line(message):
    """A multi-line message ("2 problems, nothing was changed:\n- a\n- b") on one line."""
    lines = [x.strip().removeprefix("- ") for x in str(message).splitlines() if x.strip()]
    return lines[0] + " " + "; ".join(lines[1:]) if len(lines) > 1 else "".join(lines)


def _age(scene, years, say):
    try:
        images = api.age_scene(scene, years=years)
    except api.AgingError as err:
        raise Refused(_one_line(err)) from None
    say(f"aged {plural(len(images), 'material')} to {plural(years, 'year')}")
    return len(images)


def _years_text(years):
    return f"{years:g}".replace("+", "")


# ----------------------------------------------------------------------------- actions


def do_bake(path, args, say):
    out = output_blend(path, args.output, args.in_place, SUFFIX["bake"], len(args.files) > 1)
    scene = open_blend(path)
    n = _bake(scene, _targets_or_refuse(scene), args, say)
    save_blend(out)
    return f"{plural(n, 'map')} -> {out}"


def do_age(path, args, say):
    out = output_blend(path, args.output, args.in_place, SUFFIX["age"], len(args.files) > 1)
    scene = open_blend(path)
    baked = _bake_if_needed(scene, args, say)
    n = _age(scene, args.years, say)
    save_blend(out)
    made = f"baked {plural(baked, 'map')}, " if baked else ""
    return f"{made}{plural(n, 'material')} at {args.years:g} y -> {out}"


def do_render_years(path, args, say):
    scene = open_blend(path)
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
        try:
            api.set_years(scene, years)
        except api.AgingError as err:
            raise Refused(_one_line(err)) from None
        target = os.path.join(os.path.abspath(args.output),
                              f"{stem}_{_years_text(years)}y{scene.render.file_extension}")
        with quiet("render", "gpu"):   # not 4.x's status lines, nor EGL's with no display
            bpy.ops.render.render(write_still=False, scene=scene.name)
        written.append(save_render(scene, target))
        say(f"{plural(years, 'year')} -> {target}")
    return f"{plural(len(written), 'still')} -> {os.path.abspath(args.output)}"


def do_export_aged(path, args, say):
    from ..blender.aging.apply import aged_copies, write_aged_file

    scene = open_blend(path)
    _bake_if_needed(scene, args, say)
    _age(scene, args.years, say)
    stem = os.path.splitext(os.path.basename(path))[0]
    folder = os.path.abspath(args.output)
    os.makedirs(folder, exist_ok=True)
    written = []
    for copy in aged_copies(scene):
        props = copy.lightfade
        name = f"{stem}_{props.source.name}_{props.aged_object.name}_{_years_text(args.years)}y"
        target = os.path.join(folder, _safe(name) + "." + args.format)
        with quiet("save"):
            write_aged_file(scene, copy, args.years, target)
        written.append(target)
        say(f"{props.source.name} on {props.aged_object.name} -> {target}")
    return f"{plural(len(written), 'image')} -> {folder}"


def _safe(name):
    """A file name from material and object names (path separators and the like replaced)."""
    return "".join(c if c.isalnum() or c in "._- " else "_" for c in name)


def do_info(path, args, say):
    scene = open_blend(path)
    report = gather(scene)
    report["file"] = os.path.abspath(path)
    if args.json:
        args.json_reports.append(report)
    else:
        print(as_text(report), flush=True)
    n = len(report["would_age"])
    return f"{plural(n, 'material')} would age" if n else "nothing to age"


ACTIONS = {"bake": do_bake, "age": do_age, "render-years": do_render_years,
           "export-aged": do_export_aged, "info": do_info}


def dump_json(reports):
    """The ``info --json`` document: one report per file that could be read."""
    return json.dumps({"files": reports}, indent=2)
