"""Exposure maps on objects: store a bake, read exposure back, fingerprint, remove.

The aging side reads exposure through :func:`lights_and_exposure` and tells stale aged
materials by :func:`exposure_signature`; Reset calls :func:`remove_exposure`.
"""

from __future__ import annotations

import hashlib

import bpy
import numpy as np

from ...core.aging.ager import Light
from ..pixels import resample
from ..vocabulary import resolve_spectrum
from . import daylight as _daylight
from .common import EXPOSURE_PREFIX, LightFadeBakeError, exposure_image_name
from .emitters import memo, schedule_key, schedule_of
from .uvmaps import remove_made_uv


class StaleExposureError(LightFadeBakeError):
    """Emitters baked together into one map no longer share a schedule: bake again."""


# ----------------------------------------------------------------------- writing


def store_map(obj, group, image, uv_name):
    """Name and pack ``image`` (lux) as ``obj``'s map for ``group`` and record it.

    A re-bake replaces the previous image everywhere it is used (``ID.user_remap``) and
    removes it; ``image["lightfade_bake_id"]`` counts the bakes.
    """
    final_name = exposure_image_name(obj.name, group.name)
    bake_id = 1
    old = bpy.data.images.get(final_name)
    if old is not None and old is not image and old.library is None:
        bake_id = int(old.get("lightfade_bake_id", 0)) + 1
        old.user_remap(image)
        bpy.data.images.remove(old)
    image.name = final_name
    image.file_format = "OPEN_EXR"
    image["lightfade_bake_id"] = bake_id
    image.update()
    image.pack()
    maps = obj.lightfade.exposure_maps
    item = maps.get(group.name) or maps.add()
    item.name = group.name
    item.emitter = group.emitters[0].name
    item.emitter_kind = group.emitters[0].kind
    item.members.clear()
    for em in group.emitters:
        ref = item.members.add()
        ref.name, ref.kind = em.name, em.kind
    item.image = image
    obj.lightfade.uv_map = uv_name
    return image


def _drop_item(maps, index):
    image = maps[index].image
    maps.remove(index)
    if image is not None and image.name.startswith(EXPOSURE_PREFIX) and image.library is None:
        bpy.data.images.remove(image)


def prune_maps(obj, keep):
    """Remove ``obj``'s maps (and their images) whose group name is not in ``keep``."""
    maps = obj.lightfade.exposure_maps
    for i in reversed(range(len(maps))):
        if maps[i].name not in keep:
            _drop_item(maps, i)


def remove_exposure(scene, objects=None):
    """Delete exposure maps, their images and any UV map a bake made (a clean reset).

    ``objects`` default: every object of ``scene``.
    """
    for obj in (objects if objects is not None else scene.objects):
        if obj.type != "MESH":
            continue
        maps = obj.lightfade.exposure_maps
        for i in reversed(range(len(maps))):
            _drop_item(maps, i)
        remove_made_uv(obj)
        obj.lightfade.uv_map = ""


# ----------------------------------------------------------------------- reading


def members(item):
    """``[(name, kind)]`` of the emitters baked into a map (old files: the one emitter)."""
    if len(item.members):
        return [(m.name, m.kind) for m in item.members]
    return [(item.emitter, item.emitter_kind)]


def counting_schedule(scene, name, kind):
    """The schedule an emitter's light counts with now, or None: gone, excluded, a sun
    lamp or world that annual daylight replaces, or the daylight group without a place."""
    schedule = schedule_of(scene, name, kind)
    if schedule is None or not schedule.enabled:
        return None
    if kind == "DAYLIGHT":
        return schedule if _daylight.daylight_active(scene) else None
    if _daylight.stands_for_daylight(scene, schedule, kind):
        return None
    return schedule


def map_key(scene, obj, item):
    """The map's current ``(spectrum, uv filter, h/day, d/yr)`` key, or None when its
    emitters are gone or excluded.  Raises :class:`StaleExposureError` when they now differ."""
    names = tuple(members(item))
    known = memo(scene)
    keys = known.get(("map_key", names)) if known is not None else None
    if keys is None:
        keys = set()
        for name, kind in names:
            schedule = counting_schedule(scene, name, kind)
            keys.add(None if schedule is None else schedule_key(schedule, kind))
        if known is not None:
            known["map_key", names] = keys
    keys = set(keys)
    if keys == {None}:
        return None
    if len(keys) > 1:
        raise StaleExposureError(
            f"\"{obj.name}\": the emitters baked together in \"{item.name}\" no longer share "
            "spectrum, UV filter and schedule (or some were removed): bake exposure again")
    return keys.pop()


def read_lux(image):
    """(H, W) float64 lux of an exposure image (its first channel)."""
    w, h = image.size
    buf = np.empty(w * h * image.channels, dtype=np.float32)
    image.pixels.foreach_get(buf)
    return buf.reshape(h, w, image.channels)[..., 0].astype(np.float64)


def lights_and_exposure(scene, obj, shape):
    """Lights and their illuminance maps for aging ``obj``.

    Maps whose groups now share spectrum, UV filter and schedule add up (reciprocity);
    maps of excluded or deleted emitters are left out.

    Parameters
    ----------
    scene : bpy.types.Scene
    obj : bpy.types.Object
    shape : (int, int)
        ``(H, W)`` of the texture being aged; maps are resampled to it.

    Returns
    -------
    lights : list of core.aging.Light
        One per light group, ``lux = 1`` (the maps are absolute).
    maps : (n, H, W) float64 array
        Illuminance in lux while each light is on.

    Raises
    ------
    LightFadeBakeError
        No usable map (bake first); :class:`StaleExposureError` when a group split.
    """
    summed = {}
    for item in obj.lightfade.exposure_maps:
        key = map_key(scene, obj, item) if item.image is not None else None
        if key is None:
            continue
        lux = np.maximum(resample(read_lux(item.image), shape), 0.0)
        summed[key] = summed[key] + lux if key in summed else lux
    if not summed:
        raise LightFadeBakeError(f"Object \"{obj.name}\" has no exposure maps from enabled "
                                 "emitters: run Bake Exposure first")
    lights = [Light(spectrum, uv_filter, 1.0, hours, days)
              for spectrum, uv_filter, hours, days in summed]
    return lights, np.stack(list(summed.values()))


def exposure_signature(scene, obj):
    """A string that changes whenever the exposure ``obj`` gets changes.

    It covers each map's image and bake count, its emitters, their current spectrum, UV
    filter and schedule, and the UV map: a new bake, a schedule or spectrum change and a
    regroup all change it.
    """
    parts = [obj.lightfade.uv_map]
    for item in obj.lightfade.exposure_maps:
        image = item.image
        parts.append(f"{item.name}|{image.name if image else ''}|"
                     f"{int(image.get('lightfade_bake_id', 0)) if image else 0}")
        for name, kind in members(item):
            schedule = schedule_of(scene, name, kind)
            state = ("gone" if schedule is None else
                     f"{schedule.enabled}:{resolve_spectrum(schedule, kind)}:{schedule.uv_filter}:"
                     f"{schedule.hours_per_day:.6g}:{schedule.days_per_year:.6g}")
            if schedule is not None and counting_schedule(scene, name, kind) is None:
                state += ":not counted"
            parts.append(f"{name}:{kind}:{state}")
    return hashlib.sha1("\n".join(parts).encode()).hexdigest()


def maps_lit_by(obj, emitter_name):
    """``obj``'s exposure maps whose group contains ``emitter_name``."""
    return [item for item in obj.lightfade.exposure_maps
            if any(name == emitter_name for name, _ in members(item))]


def store_sum(state, obj, group, parts, uv_name):
    """Sum existing maps ``parts`` into ``group``'s map of ``obj`` (a regroup without a
    bake; ``uv_name``: the UV map when the object has none recorded)."""
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
    merged = state.new_image(f"{obj.name}_{group.name}", w, h)
    merged.pixels.foreach_set(total)
    state.keep(merged)
    store_map(obj, group, merged, obj.lightfade.uv_map or uv_name)
