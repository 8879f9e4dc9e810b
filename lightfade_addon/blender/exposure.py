"""The one place the aging shell reads exposure from (an adapter over the bake).

Everything the aging side needs of the exposure bake goes through these functions, so
that a different bake module is a change of the imports below and nothing else:

* :func:`lights_and_exposure` — the lights and their lux maps for an object;
* :func:`exposure_signature` — a digest that changes with a new bake, a changed schedule
  or regrouped emitters (what aged materials compare against to know they are stale);
* :func:`remove_exposure` — exposure maps (and the UV maps the bake made) removed;
* :func:`exposure_shape` / :func:`exposure_uv` — size and UV map of an object's maps.
"""

from __future__ import annotations

import hashlib

import bpy
import numpy as np

from ..core.aging import Light
from .errors import AgingError
from .pixels import read_rgba, resample
from .properties import resolve_spectrum

#: UV map the bake makes for meshes that need a unique exposure layout.
BAKE_UV_MAP = "LightFadeUV"


def _schedule(scene, item):
    """The schedule of the emitter an exposure map was baked for, or None if gone."""
    if item.emitter_kind == "WORLD":
        return scene.world.lightfade if scene.world else None
    obj = bpy.data.objects.get(item.emitter)
    if obj is None:
        return None
    if item.emitter_kind == "EMISSIVE":
        return obj.lightfade_emitter
    return obj.data.lightfade if obj.type == "LIGHT" else None


def _read_lux(image):
    return read_rgba(image)[..., 0].astype(np.float64)


def _maps(obj):
    return [m for m in obj.lightfade.exposure_maps if m.image is not None and m.image.size[0] > 0]


def exposure_shape(obj):
    """(H, W) of the object's exposure maps, or None without maps."""
    maps = _maps(obj)
    return tuple(maps[0].image.size)[::-1] if maps else None


def exposure_uv(obj):
    """Name of the UV map the object's exposure was baked in ('' if none)."""
    return obj.lightfade.uv_map


def lights_and_exposure(scene, obj, shape):
    """Lights (one per exposure map) and their lux maps resampled to ``shape``.

    Returns
    -------
    lights : list of core.aging.Light
        Spectrum and schedule (``lux = 1``: the maps are absolute lux).
    maps : ndarray, shape (len(lights), H, W)
        Illuminance in lux while each light is on.
    """
    lights, maps = [], []
    for item in obj.lightfade.exposure_maps:
        schedule = _schedule(scene, item)
        if schedule is None or not schedule.enabled or item.image is None:
            continue
        lights.append(Light(resolve_spectrum(schedule, item.emitter_kind), schedule.uv_filter,
                            1.0, schedule.hours_per_day, schedule.days_per_year))
        maps.append(np.maximum(resample(_read_lux(item.image), shape), 0.0))
    if not lights:
        raise AgingError(f"Object '{obj.name}' has no exposure maps from enabled emitters: "
                         "run Bake Exposure first")
    return lights, np.stack(maps)


def exposure_problem(scene, obj):
    """One line saying why ``obj`` cannot be aged for lack of exposure, or None."""
    for item in obj.lightfade.exposure_maps:
        schedule = _schedule(scene, item)
        if schedule is not None and schedule.enabled and item.image is not None:
            return None
    return (f"Object '{obj.name}' has no exposure maps from enabled emitters: run Bake "
            "Exposure first")


def exposure_signature(scene, obj):
    """A digest of everything the object's exposure means for aging.

    Changes with a new bake (each bake bumps the map's ``lightfade_bake_id``), a changed
    schedule (spectrum, UV filter, hours, days, enabled) or a different set of emitters.
    """
    h = hashlib.sha1()
    for item in obj.lightfade.exposure_maps:
        image = item.image
        schedule = _schedule(scene, item)
        parts = [item.emitter, item.emitter_kind,
                 image.name if image else "", str(image.get("lightfade_bake_id", 0)) if image else "",
                 str(tuple(image.size)) if image else ""]
        if schedule is not None:
            parts += [str(schedule.enabled), resolve_spectrum(schedule, item.emitter_kind),
                      str(schedule.uv_filter), repr(schedule.hours_per_day),
                      repr(schedule.days_per_year)]
        h.update("|".join(parts).encode())
    h.update(obj.lightfade.uv_map.encode())
    return h.hexdigest()


def remove_exposure(scene, objects):
    """Remove the exposure maps of ``objects`` (images nothing else uses, and the UV map
    the bake made); returns the number of images removed."""
    removed = 0
    for obj in objects:
        if obj.type != "MESH":
            continue
        for item in obj.lightfade.exposure_maps:
            if item.image is not None and item.image.users <= 1:
                bpy.data.images.remove(item.image)
                removed += 1
        obj.lightfade.exposure_maps.clear()
        obj.lightfade.uv_map = ""
        uv = obj.data.uv_layers.get(BAKE_UV_MAP)
        if uv is not None and obj.data.library is None:
            obj.data.uv_layers.remove(uv)
    return removed
