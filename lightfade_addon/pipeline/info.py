"""``info``: what a file would age and how, its emitters and doses, and what is stale.

A thin gathering layer over :mod:`..blender.aging`, :mod:`..blender.bake` and
:mod:`..blender.stats`: one function per section, each ``fn(scene) -> list`` of plain
dicts or strings, so that a section can be rebuilt on a richer query by changing one
call.  Nothing here changes the file.
"""

from __future__ import annotations

import bpy

from .. import api
from ..blender import stats
from ..blender.apply import aged_copies
from ..blender.bake import find_emitters
from ..blender.properties import resolve_spectrum
from ..blender.targets import targets

# ------------------------------------------------------------------------------ queries


def target_objects(scene):
    """Meshes that aging would touch (those using a material with LightFade enabled)."""
    return list(dict.fromkeys(obj for obj, _material in targets(scene)))


def _emitters_of(scene, obj):
    return [e for e in find_emitters(scene) if e.obj is not obj]


def missing_maps(scene, obj):
    """Names of the scene's emitters that ``obj`` has no usable exposure map for."""
    have = {m.name for m in obj.lightfade.exposure_maps
            if m.image is not None and tuple(m.image.size) != (0, 0)}
    return [e.name for e in _emitters_of(scene, obj) if e.name not in have]


def _recipe(material):
    props = material.lightfade
    sensitivity = (f"beta {props.beta:g}e-6" if props.sensitivity_mode == "BETA"
                   else f"Blue Wool {props.blue_wool}")
    return props.recipe.lower().replace("_", "-"), sensitivity


# ----------------------------------------------------------------------------- sections


def would_age(scene):
    """One entry per (object, material) pair Age would take: its albedo path
    (``direct``, ``baked`` or ``flat``), why, what stops it, and its aged status
    (:func:`..api.material_plan`)."""
    entries = []
    for row in api.material_plan(scene):
        recipe, sensitivity = _recipe(bpy.data.materials[row["material"]])
        entries.append({
            "object": row["object"], "material": row["material"],
            "path": row["path"].lower(), "reason": row["reason"],
            "problems": list(row["problems"]), "status": row["status"],
            "recipe": recipe, "sensitivity": sensitivity,
        })
    return entries


def emitters(scene):
    """The emitters that take part in aging, with spectrum and schedule."""
    entries = []
    for e in find_emitters(scene):
        schedule = stats.emitter_schedule(scene, e.name, e.kind)
        entries.append({
            "name": e.name, "kind": e.kind.lower(),
            "spectrum": resolve_spectrum(schedule, e.kind),
            "uv_filter": schedule.uv_filter,
            "hours_per_day": schedule.hours_per_day, "days_per_year": schedule.days_per_year,
        })
    return entries


def doses(scene):
    """Per baked map: brightest texel (lux) and its annual dose (Mlx·h per year)."""
    entries = []
    for obj in target_objects(scene):
        for m in obj.lightfade.exposure_maps:
            schedule = stats.emitter_schedule(scene, m.emitter, m.emitter_kind)
            lux = stats.image_max(m.image)
            entries.append({
                "object": obj.name, "emitter": m.name, "kind": m.emitter_kind.lower(),
                "size": list(m.image.size) if m.image is not None else None,
                "max_lux": lux,
                "max_annual_Mlxh": (stats.annual_dose(lux, schedule) / 1e6
                                    if schedule is not None else None),
            })
    return entries


def stale(scene):
    """What no longer matches the scene: missing maps, maps of gone emitters, aged
    materials whose exposure, schedule or recipe changed since Age."""
    lines = []
    for obj in target_objects(scene):
        maps = obj.lightfade.exposure_maps
        missing = missing_maps(scene, obj)
        if not len(maps):
            lines.append(f"Object '{obj.name}' has no exposure maps (bake; age bakes them)")
        elif missing:
            lines.append(f"Object '{obj.name}' has no exposure map for "
                         f"{', '.join(repr(n) for n in missing)} (added after the bake?)")
        current = {e.name for e in _emitters_of(scene, obj)}
        for m in maps:
            if m.image is None or tuple(m.image.size) == (0, 0):
                lines.append(f"Object '{obj.name}': the map for '{m.name}' has no image data "
                             "(re-bake)")
            elif m.name not in current:
                lines.append(f"Object '{obj.name}': the map for '{m.name}' belongs to an "
                             "emitter that is gone or excluded from aging (ignored)")
    for copy in aged_copies(scene):
        props = copy.lightfade
        if not props.source.lightfade.enabled:
            lines.append(f"Material '{props.source.name}' on '{props.aged_object.name}' is "
                         "aged but no longer has LightFade enabled (Reset it)")
    for e in would_age(scene):
        if e["status"].startswith("stale"):
            lines.append(f"Material '{e['material']}' on '{e['object']}' is {e['status']}")
    return lines


#: Report sections in order: (key, function of the scene).
SECTIONS = (
    ("would_age", would_age),
    ("emitters", emitters),
    ("doses", doses),
    ("stale", stale),
)


def gather(scene):
    """All sections for ``scene`` as one JSON-ready dict."""
    report = {"scene": scene.name, "years": scene.lightfade.years,
              "camera": scene.camera.name if scene.camera is not None else None}
    for key, fn in SECTIONS:
        report[key] = fn(scene)
    return report


# ----------------------------------------------------------------------------- as text


def as_text(report):
    """A human-readable rendering of :func:`gather`'s dict."""
    out = [f"{report.get('file', '')}  scene '{report['scene']}', years {report['years']:g}, "
           f"camera {report['camera'] or '(none)'}"]
    out.append("  would age:" if report["would_age"] else "  would age: nothing")
    for e in report["would_age"]:
        out.append(f"    {e['object']} / {e['material']}: {e['path']} ({e['recipe']}, "
                   f"{e['sensitivity']}; {e['status']}) - {e['reason']}")
        out.extend(f"      problem: {p}" for p in e["problems"])
    out.append("  emitters:" if report["emitters"] else "  emitters: none")
    for e in report["emitters"]:
        uv = ", UV filter" if e["uv_filter"] else ""
        out.append(f"    {e['name']} ({e['kind']}): {e['spectrum']}{uv}, "
                   f"{e['hours_per_day']:g} h/day, {e['days_per_year']:g} days/year")
    out.append("  doses:" if report["doses"] else "  doses: no exposure maps")
    for e in report["doses"]:
        dose = ("emitter gone" if e["max_annual_Mlxh"] is None
                else f"{e['max_annual_Mlxh']:.3g} Mlx·h/year")
        out.append(f"    {e['object']} <- {e['emitter']} ({e['kind']}): brightest texel "
                   f"{e['max_lux']:.4g} lux, {dose}")
    out.append("  stale:" if report["stale"] else "  stale: nothing")
    out.extend(f"    {line}" for line in report["stale"])
    return "\n".join(out)
