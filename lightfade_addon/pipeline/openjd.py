"""The farm job as an Open Job Description template (``jobtemplate-2023-09``).

:func:`job_template` builds the template as data (dicts and lists) from a
:class:`JobSpec`; :func:`to_yaml` writes it; :func:`validate` checks it with
``openjd-model`` where that is installed (the development stack: Blender's own Python
does not have it, and the template is plain data either way).  Pure Python: no bpy.

Steps (each one command, so any OpenJD runner takes them: ``openjd run``, AWS Deadline
Cloud, and the Flamenco job type of ``docs/farm.md``):

``Bake``    one task per light group × chunk of objects: ``farm-bake`` writes that
            task's maps into ``WorkDir/maps``
``Merge``   after every Bake task: ``farm-merge`` checks all maps and saves the scene
            with them as ``OutputDir/NAME_baked.blend``
``Age``     (with a time-lapse) ``farm-age`` ages that file and keys the years over the
            frames: ``OutputDir/NAME_aged.blend``
``Render``  one task per frame: plain ``blender -b ... -f FRAME``, no LightFade needed

Every path is a job parameter of type PATH, so a farm maps it to its workers' file
systems (OpenJD path mapping; Deadline Cloud's job attachments read ``dataFlow``).
The task plan (the groups and the objects of each chunk, the scene's hash and the
bake settings) travels inside the template, as a file embedded in the steps that
read it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

SPECIFICATION = "jobtemplate-2023-09"


@dataclass
class JobSpec:
    """What the template is made of.

    Attributes
    ----------
    name : str
        Job name (the scene's file name).
    scene, work, output : str or None
        Defaults of the PATH parameters, relative to the bundle's folder (OpenJD joins
        them to the template's): the scene file, the folder of the Bake tasks' maps, the
        folder of the merged (and aged) file and the frames.  None: no default.
    stem : str
        The scene file's name without ``.blend``.
    plan : str
        The task plan, JSON text (:mod:`.farm`), embedded in Bake and Merge.
    groups : list of str
        Light group names (Bake's ``Group`` parameter).
    chunks : int
        Chunks of objects per group (Bake's ``Chunk`` parameter, 0 to ``chunks - 1``).
    bake_timeout : int
        Seconds a Bake task may run before the farm stops it.
    years : float or None
        Years at the time-lapse's last frame; None: no Age and Render steps.
    frames : tuple of int
        First and last frame of the time-lapse.
    """

    name: str
    scene: str
    work: str
    output: str
    stem: str
    plan: str
    groups: list
    chunks: int
    bake_timeout: int = 3600
    years: float | None = None
    frames: tuple = (1, 1)
    blender: str = "blender"
    extra: dict = field(default_factory=dict)


def _path(name, kind, flow, default, description):
    p = {"name": name, "type": "PATH", "objectType": kind, "dataFlow": flow,
         "description": description}
    if default is not None:
        p["default"] = default
    return p


def parameters(spec):
    """The job parameters: three PATH parameters and the Blender executable."""
    return [
        _path("SceneFile", "FILE", "IN", spec.scene,
              "The .blend file to bake (read only; every task checks its SHA-256)"),
        _path("WorkDir", "DIRECTORY", "INOUT", spec.work,
              "Where the Bake tasks write their maps (maps/) for Merge"),
        _path("OutputDir", "DIRECTORY", "OUT", spec.output,
              "Where Merge writes NAME_baked.blend, Age NAME_aged.blend and Render the "
              "frames (renders/)"),
        {"name": "Blender", "type": "STRING", "default": spec.blender, "minLength": 1,
         "description": "The Blender executable on the workers (4.2 or newer; LightFade "
                        "installed for Bake, Merge and Age)"},
    ]


def _lightfade(*args):
    """A step's run action: ``blender -c lightfade ARGS``."""
    return {"command": "{{Param.Blender}}", "args": ["-c", "lightfade", *args]}


def _plan_file(spec):
    return {"name": "Plan", "type": "TEXT", "filename": "plan.json", "data": spec.plan}


def _outputs(spec):
    base = "{{Param.OutputDir}}/" + spec.stem
    return base + "_baked.blend", base + "_aged.blend"


def bake_step(spec):
    run = _lightfade("farm-bake", "{{Param.SceneFile}}", "--plan", "{{Task.File.Plan}}",
                     "--group", "{{Task.Param.Group}}", "--chunk", "{{Task.Param.Chunk}}",
                     "--maps", "{{Param.WorkDir}}/maps")
    run["timeout"] = int(spec.bake_timeout)
    return {
        "name": "Bake",
        "description": "Exposure maps of one light group for one chunk of objects",
        "parameterSpace": {
            "taskParameterDefinitions": [
                {"name": "Group", "type": "STRING", "range": list(spec.groups)},
                {"name": "Chunk", "type": "INT", "range": f"0-{spec.chunks - 1}"},
            ],
            "combination": "Group * Chunk",
        },
        "script": {"embeddedFiles": [_plan_file(spec)], "actions": {"onRun": run}},
    }


def merge_step(spec):
    merged, _aged = _outputs(spec)
    run = _lightfade("farm-merge", "{{Param.SceneFile}}", "--plan", "{{Task.File.Plan}}",
                     "--maps", "{{Param.WorkDir}}/maps", "--output", merged)
    return {
        "name": "Merge",
        "description": "Check every Bake task's maps and save the scene with them",
        "dependencies": [{"dependsOn": "Bake"}],
        "script": {"embeddedFiles": [_plan_file(spec)], "actions": {"onRun": run}},
    }


def age_step(spec):
    merged, aged = _outputs(spec)
    first, last = spec.frames
    run = _lightfade("farm-age", merged, "--years", f"{spec.years:g}", "--frames",
                     str(first), str(last), "--output", aged)
    return {
        "name": "Age",
        "description": f"Age the materials; years keyed from 0 at frame {first} to "
                       f"{spec.years:g} at frame {last}",
        "dependencies": [{"dependsOn": "Merge"}],
        "script": {"actions": {"onRun": run}},
    }


def render_step(spec):
    _merged, aged = _outputs(spec)
    first, last = spec.frames
    out = "{{Param.OutputDir}}/renders/" + spec.stem + "_####"
    return {
        "name": "Render",
        "description": "The years time-lapse, one frame per task, in plain Blender",
        "dependencies": [{"dependsOn": "Age"}],
        "parameterSpace": {"taskParameterDefinitions": [
            {"name": "Frame", "type": "INT", "range": f"{first}-{last}"}]},
        "script": {"actions": {"onRun": {
            "command": "{{Param.Blender}}",
            "args": ["-b", aged, "-o", out, "-f", "{{Task.Param.Frame}}"]}}},
    }


def job_template(spec):
    """The OpenJD job template of ``spec``, as a dict."""
    steps = [bake_step(spec), merge_step(spec)]
    if spec.years is not None:
        steps += [age_step(spec), render_step(spec)]
    return {
        "specificationVersion": SPECIFICATION,
        "name": f"LightFade {spec.name}"[:128],
        "description": "Exposure bake, merge, aging and years time-lapse of a scene "
                       "(LightFade farm-job)",
        "parameterDefinitions": parameters(spec),
        "steps": steps,
    }


def parameter_values(values):
    """A Deadline Cloud bundle's ``parameter_values.yaml`` (``{name: value}``): the
    values ``deadline bundle submit`` uses where the template has no default (the
    scene, which lies outside the bundle)."""
    return {"parameterValues": [{"name": k, "value": v} for k, v in values.items()]}


# ----------------------------------------------------------------------------- writing


def _scalar(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if value == [] or value == {}:
        return "[]" if value == [] else "{}"
    return json.dumps(str(value))   # a JSON string is a YAML double-quoted scalar


def _is_scalar(value):
    return not isinstance(value, (dict, list)) or not value


def _lines(value, depth):
    pad = "  " * depth
    out = []
    if isinstance(value, dict):
        for key, item in value.items():
            if isinstance(item, str) and "\n" in item:
                out.append(f"{pad}{key}: |")
                out += [f"{pad}  {line}" if line else "" for line in item.rstrip("\n").split("\n")]
            elif _is_scalar(item):
                out.append(f"{pad}{key}: {_scalar(item)}")
            else:
                out.append(f"{pad}{key}:")
                out += _lines(item, depth + 1)
    else:
        for item in value:
            if _is_scalar(item):
                out.append(f"{pad}- {_scalar(item)}")
            else:
                inner = _lines(item, depth + 1)
                out.append(f"{pad}- {inner[0].lstrip()}")
                out += inner[1:]
    return out


def to_yaml(template):
    """``template`` (dicts, lists, strings, numbers) as YAML text: block style, strings
    double-quoted as JSON writes them, multi-line strings as literal blocks (``|``)."""
    return "\n".join(_lines(template, 0)) + "\n"


def validate(template):
    """Check ``template`` against the OpenJD specification with ``openjd-model``.

    Returns True when checked, False when ``openjd-model`` is not installed (Blender's
    Python); raises ``ValueError`` (the model's message) when the template is wrong.
    """
    try:
        from openjd.model import DecodeValidationError, decode_job_template
    except ImportError:
        return False
    try:
        decode_job_template(template=template)
    except DecodeValidationError as err:
        raise ValueError(f"the OpenJD template is not valid: {err}") from None
    return True
