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
from ..blender.aging.apply import aged_copies
from ..blender.bake import (
    LightFadeBakeError,
    StaleExposureError,
    find_emitters,
    find_groups,
    maps_lit_by,
)
from ..blender.bake import daylight as _daylight_bake
from ..blender.bake.maps import map_key
from ..blender.bake.instances import baked_placements, stale_placements
from ..blender.daylight import place as _place
from ..blender.daylight.doses import material_doses
from ..blender.aging.parts import describe
from ..blender.targets import targets

# ------------------------------------------------------------------------------ queries


def target_objects(scene):
    """Meshes that aging would touch (those using a material with LightFade enabled)."""
    return list(dict.fromkeys(obj for obj, _material in targets(scene)))


def _emitters_of(scene, obj):
    return [e for e in find_emitters(scene) if e.obj is not obj]


def _has_pixels(item):
    return item.image is not None and tuple(item.image.size) != (0, 0)


def missing_maps(scene, obj):
    """Names of the scene's emitters that no usable exposure map of ``obj`` holds."""
    return [e.name for e in _emitters_of(scene, obj)
            if not any(_has_pixels(m) for m in maps_lit_by(obj, e.name))]


def needs_bake(scene, obj):
    """True when ``obj`` misses a map for an emitter or a baked group has split."""
    return bool(missing_maps(scene, obj)) or any(
        isinstance(_key(scene, obj, m), str) for m in obj.lightfade.exposure_maps)


def _key(scene, obj, item):
    """A map's ``(spectrum, uv filter, h/day, d/yr)``, None (emitters gone or excluded)
    or the message of a group that split."""
    try:
        return map_key(scene, obj, item)
    except StaleExposureError as err:
        return str(err)


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
        material = bpy.data.materials[row["material"]]
        recipe, sensitivity = _recipe(material)
        entries.append({
            "object": row["object"], "material": row["material"],
            "path": row["path"].lower(), "reason": row["reason"],
            "problems": list(row["problems"]), "status": row["status"],
            "recipe": recipe, "sensitivity": sensitivity,
            "parts": [dict(name=n, recipe=r, mask=m) for n, r, m in describe(material)]
            if len(material.lightfade.parts) else [],
        })
    return entries


def light_groups(scene):
    """The emitters that take part in aging, grouped as the bake groups them (one map
    per group: same spectrum, UV filter and schedule)."""
    entries = []
    for g in find_groups(scene):
        spectrum, uv_filter, hours, days = g.key
        entries.append({
            "name": g.name, "emitters": [[e.name, e.kind.lower()] for e in g.emitters],
            "spectrum": spectrum, "uv_filter": uv_filter,
            "hours_per_day": hours, "days_per_year": days,
        })
    return entries


def doses(scene):
    """Per baked map: brightest texel (lux) and its annual dose (Mlx·h per year, None
    when the map's emitters are gone, excluded or no longer share a schedule)."""
    entries = []
    for obj in target_objects(scene):
        for m in obj.lightfade.exposure_maps:
            key = _key(scene, obj, m)
            lux = stats.image_max(m.image)
            entries.append({
                "object": obj.name, "group": m.name,
                "size": list(m.image.size) if m.image is not None else None,
                "max_lux": lux,
                "max_annual_Mlxh": lux * key[2] * key[3] / 1e6 if isinstance(key, tuple) else None,
            })
    return entries


def daylight(scene):
    """The scene's place and weather, and whether daylight is one annual bake (None:
    no place set)."""
    source = _place.place_source(scene)
    if source is None:
        return None
    lat, lon, north, where = source
    props = scene.lightfade_daylight
    return {"latitude": lat, "longitude": lon, "north": north, "from": where,
            "weather": _place.weather_path(scene), "annual": _place.daylight_active(scene),
            "spectrum": props.spectrum.lower().replace("_", "-"), "uv_filter": props.uv_filter,
            "muted_lamps": _daylight_bake.replaced_lamps(scene)}


def material_annual_doses(scene):
    """Per object, material and light group: the annual dose (lux·h per year) over the
    material's texels, max and mean."""
    entries = []
    for obj in target_objects(scene):
        try:
            rows = material_doses(scene, obj)
        except (LightFadeBakeError, StaleExposureError):
            continue
        entries.extend({"object": obj.name, **row} for row in rows)
    return entries


def instances(scene):
    """Per source aged through its instances: how many placements its atlas holds (by
    kind: collection instances, geometry-nodes instances, the source itself), the atlas
    size, the instancers whose instances moved, appeared or went since the bake, and why
    they are aged as they stood at the bake's frame when they change with the frame."""
    entries = []
    layer = bpy.context.view_layer if bpy.context.scene == scene else scene.view_layers[0]
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for obj in target_objects(scene):
        if not obj.lightfade.instance_tiles:
            continue
        kinds = [key.split("|")[1] for key in baked_placements(obj)]
        maps = [m.image for m in obj.lightfade.exposure_maps if m.image is not None]
        stale_keys = stale_placements(depsgraph, layer, obj)
        entries.append({
            "object": obj.name, "instances": len(kinds),
            "collection": kinds.count("COLLECTION"), "geometry_nodes": kinds.count("GEOMETRY"),
            "itself": "OWN" in kinds, "atlas": list(maps[0].size) if maps else None,
            "stale": sorted({k.split("|")[0] or obj.name for k in stale_keys}),
            "changes": obj.lightfade.instance_changes,
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
        for m in maps:
            key = _key(scene, obj, m)
            if not _has_pixels(m):
                lines.append(f"Object '{obj.name}': the map for '{m.name}' has no image data "
                             "(bake again)")
            elif key is None:
                lines.append(f"Object '{obj.name}': the map for '{m.name}' belongs to "
                             "emitters that are gone or excluded from aging (ignored)")
            elif isinstance(key, str):
                lines.append(key)
            elif _daylight_bake.sky_changed(scene, m.image):
                lines.append(f"Object '{obj.name}': the map for '{m.name}' was baked for "
                             "another place, north or weather (bake again)")
    years = scene.lightfade.years
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
    ("light_groups", light_groups),
    ("daylight", daylight),
    ("doses", doses),
    ("material_doses", material_annual_doses),
    ("instances", instances),
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
        out.extend(f"      part {p['name']}: {p['recipe']} - {p['mask']}"
                   for p in e.get("parts", []))
        out.extend(f"      problem: {p}" for p in e["problems"])
    out.append("  light groups:" if report["light_groups"] else "  light groups: none")
    for g in report["light_groups"]:
        uv = ", UV filter" if g["uv_filter"] else ""
        members = ", ".join(f"{name} ({kind})" for name, kind in g["emitters"])
        out.append(f"    {g['name']}: {members}; {g['spectrum']}{uv}, "
                   f"{g['hours_per_day']:g} h/day, {g['days_per_year']:g} days/year")
    out.append("  doses:" if report["doses"] else "  doses: no exposure maps")
    for e in report["doses"]:
        dose = ("not used" if e["max_annual_Mlxh"] is None
                else f"{e['max_annual_Mlxh']:.3g} Mlx·h/year")
        out.append(f"    {e['object']} <- {e['group']}: brightest texel "
                   f"{e['max_lux']:.4g} lux, {dose}")
    day = report.get("daylight")
    if day is None:
        out.append("  daylight: no place (sun lamps with their hours per day)")
    else:
        weather = day["weather"] or "clear sky"
        mode = "one annual bake" if day["annual"] else "annual daylight off"
        muted = f", muted: {', '.join(day['muted_lamps'])}" if day["muted_lamps"] else ""
        out.append(f"  daylight: {day['latitude']:.2f}°, {day['longitude']:.2f}°, north "
                   f"{day['north']:.0f}° (from {day['from']}), {weather}; {mode}{muted}")
    rows = report.get("material_doses") or []
    out.append("  annual dose per material:" if rows else "  annual dose per material: none")
    for e in rows:
        out.append(f"    {e['object']} / {e['material']} <- {e['group']}: max "
                   f"{e['max'] / 1e6:.3g} Mlx·h/year, mean {e['mean'] / 1e6:.3g} Mlx·h/year")
    for e in report.get("instances") or []:
        kinds = f"{e['collection']} collection, {e['geometry_nodes']} geometry-nodes" + (
            ", itself" if e["itself"] else "")
        moved = f"; stale: {', '.join(e['stale'])}" if e["stale"] else ""
        out.append(f"  instances of {e['object']}: {e['instances']} ({kinds}), atlas "
                   f"{'x'.join(map(str, e['atlas'] or []))}{moved}")
        if e.get("changes"):
            out.append(f"    {e['changes']}")
    out.append("  stale:" if report["stale"] else "  stale: nothing")
    out.extend(f"    {line}" for line in report["stale"])
    return "\n".join(out)
