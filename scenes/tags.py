"""The scenes' ``lightfade_*`` tags as LightFade settings, and the doses they add up to.

The builders tag materials, lights, the world and emitting meshes with custom properties
(:mod:`scenes.common`); :func:`apply_tags` turns them into the add-on's settings, and
:func:`annual_doses` reads what the baked exposure maps and those schedules give a year.
"""

from __future__ import annotations

import numpy as np


def _schedule_from_tags(schedule, idb, spectrum_enum):
    """Copy ``lightfade_*`` tags of ``idb`` to a LightFade schedule; untagged: excluded."""
    if "lightfade_spectrum" not in idb:
        schedule.enabled = False
        return None
    schedule.enabled = True
    schedule.spectrum = spectrum_enum[idb["lightfade_spectrum"]]
    schedule.hours_per_day = float(idb.get("lightfade_hours_per_day", schedule.hours_per_day))
    schedule.days_per_year = float(idb.get("lightfade_days_per_year", schedule.days_per_year))
    schedule.uv_filter = bool(idb.get("lightfade_uv_filter", False))
    return dict(spectrum=idb["lightfade_spectrum"], hours_per_day=schedule.hours_per_day,
                days_per_year=schedule.days_per_year, uv_filter=schedule.uv_filter)


def apply_tags(scene):
    """Map the scene's custom tags to LightFade settings.

    - A material with ``mat["lightfade_recipe"]`` gets ``Material.lightfade.enabled``, the
      recipe and, if tagged, ``mat["lightfade_blue_wool"]`` (set after the recipe, whose
      update callback resets the class to the recipe's own); untagged materials are left off.
    - Lights, the world and meshes with ``lightfade_spectrum`` get their schedule from
      ``lightfade_spectrum`` / ``_hours_per_day`` / ``_uv_filter`` (and ``_days_per_year``,
      default 365). Untagged emitters are excluded from aging: in these scenes every
      light that belongs to the room's history is tagged (the room's sky through the
      window is tagged daylight-glass, 10 h a day, so it counts).

    - A scene with ``scene["lightfade_place"]`` (latitude, longitude, north, optional
      weather) gets it through ``api.set_daylight``: daylight becomes one annual bake, and
      the sun lamp and sky standing for daylight are muted in the exposure bake.

    Returns
    -------
    dict
        ``materials`` {name: {recipe, blue_wool}}, ``emitters`` {name: schedule or None}
        and ``daylight`` (the place, or None).
    """
    from lightfade_addon.blender.vocabulary import RECIPE_IDS, SPECTRUM_IDS

    recipe_enum = {v: k for k, v in RECIPE_IDS.items()}
    spectrum_enum = {v: k for k, v in SPECTRUM_IDS.items()}
    out = dict(materials={}, emitters={})
    materials = []
    for obj in scene.objects:
        for slot in getattr(obj, "material_slots", ()):
            if slot.material is not None and slot.material not in materials:
                materials.append(slot.material)
    for mat in materials:
        props = mat.lightfade
        if "lightfade_recipe" not in mat:
            props.enabled = False
            continue
        props.enabled = True
        props.recipe = recipe_enum[mat["lightfade_recipe"]]
        props.sensitivity_mode = "BLUE_WOOL"
        if "lightfade_blue_wool" in mat:
            props.blue_wool = int(mat["lightfade_blue_wool"])
        out["materials"][mat.name] = dict(recipe=mat["lightfade_recipe"], blue_wool=props.blue_wool)
    for obj in scene.objects:
        if obj.type == "LIGHT":
            out["emitters"][obj.name] = _schedule_from_tags(obj.data.lightfade, obj.data, spectrum_enum)
        elif obj.type == "MESH" and "lightfade_spectrum" in obj:
            out["emitters"][obj.name] = _schedule_from_tags(obj.lightfade_emitter, obj, spectrum_enum)
        elif obj.type == "MESH":
            obj.lightfade_emitter.enabled = False
    if scene.world is not None:
        out["emitters"]["World"] = _schedule_from_tags(scene.world.lightfade, scene.world, spectrum_enum)
    out["daylight"] = None
    if "lightfade_place" in scene:
        from lightfade_addon import api

        place = {k: (float(v) if k != "weather" else v)
                 for k, v in scene["lightfade_place"].to_dict().items()}
        api.set_daylight(scene, **place)
        out["daylight"] = place
    return out


# ----------------------------------------------------------------------- doses and labels


def annual_doses(scene):
    """{object name: (H, W) lux·h per year} from the baked maps and the emitters' schedules."""
    from lightfade_addon.blender.exposure import lights_and_exposure

    doses = {}
    for obj in scene.objects:
        if obj.type != "MESH" or not len(obj.lightfade.exposure_maps):
            continue
        first = next((m.image for m in obj.lightfade.exposure_maps if m.image is not None), None)
        if first is None:
            continue
        shape = tuple(first.size)[::-1]
        lights, maps = lights_and_exposure(scene, obj, shape)
        doses[obj.name] = sum(light.annual_dose * m for light, m in zip(lights, maps))
    return doses


def peak_annual_dose(doses):
    """The dose rate (lux·h a year) at the brightest point: 99.9th percentile of all texels."""
    if not doses:
        return 0.0
    return float(np.percentile(np.concatenate([d.ravel() for d in doses.values()]), 99.9))
