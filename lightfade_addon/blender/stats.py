"""Exposure-map statistics for the UI: brightest texel and annual dose, cached.

Reading a 1024² float map costs ~16 MB and a few ms, too much for every panel redraw,
so the maximum is cached per image and recomputed only when the image's
``lightfade_bake_id`` (bumped by every bake) or size changes.
"""

import numpy as np

_MAX_CACHE = {}


def image_max(image):
    """Largest value of the R channel of ``image`` (lux for an exposure map); 0 if empty."""
    if image is None:
        return 0.0
    key = (image.as_pointer(), image.name_full, int(image.get("lightfade_bake_id", 0)), tuple(image.size))
    value = _MAX_CACHE.get(key)
    if value is None:
        n = len(image.pixels)
        if n == 0:
            value = 0.0
        else:
            pixels = np.empty(n, dtype=np.float32)
            image.pixels.foreach_get(pixels)
            value = float(pixels[0::image.channels].max())
        if len(_MAX_CACHE) > 256:
            _MAX_CACHE.clear()
        _MAX_CACHE[key] = value
    return value


def annual_dose(max_lux, schedule):
    """Annual dose in lux·h of a texel at ``max_lux`` lux under ``schedule``.

    ``lux × hours_per_day × days_per_year``; divide by 1e6 for Mlx·h.
    """
    return max_lux * schedule.hours_per_day * schedule.days_per_year


def emitter_schedule(scene, name, kind):
    """The :class:`LIGHTFADE_PG_schedule` of the emitter a map was baked for, or None
    (annual daylight: ``Scene.lightfade_daylight``, 24 h × 365 d of its mean lux)."""
    if kind == "DAYLIGHT":
        return scene.lightfade_daylight
    if kind == "WORLD":
        return scene.world.lightfade if scene.world is not None else None
    obj = scene.objects.get(name)
    if obj is None:
        return None
    if obj.type == "LIGHT":
        return obj.data.lightfade
    return obj.lightfade_emitter


def clear_cache():
    _MAX_CACHE.clear()
