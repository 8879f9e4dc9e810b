"""The one place the aging shell reads exposure from (an adapter over :mod:`.bake`).

Everything the aging side needs of the exposure bake goes through these functions:

* :func:`lights_and_exposure` — the light groups and their lux maps for an object;
* :func:`exposure_images` — the map images themselves with their light (read by the
  aging node group);
* :func:`exposure_signature` — a digest that changes with a new bake, a changed schedule
  or regrouped emitters (what aged materials compare against to know they are stale);
* :func:`remove_exposure` — exposure maps (and the UV map the bake made) removed;
* :func:`exposure_shape` / :func:`exposure_uv` — size and UV map of an object's maps;
* :func:`exposure_problem` — why an object cannot age for lack of exposure;
* :func:`scene_objects` — the scene's objects and the sources aged through their
  instances (which may stand in no scene themselves).

The bake's own errors become :class:`AgingError` here, so that the aging operators catch
one exception type.
"""

from __future__ import annotations

from ..core.fading.lights import Light
from . import bake
from .errors import AgingError


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
    """Lights (one per light group) and their lux maps resampled to ``shape``.

    Returns
    -------
    lights : list of core.aging.Light
        Spectrum and schedule (``lux = 1``: the maps are absolute lux).
    maps : ndarray, shape (len(lights), H, W)
        Illuminance (photometric, from the luminance of the bake) in lux while each
        light group is on.
    """
    try:
        return bake.lights_and_exposure(scene, obj, shape)
    except bake.LightFadeBakeError as err:
        raise AgingError(str(err)) from None


def exposure_images(scene, obj):
    """``[(image, Light)]``: each counted exposure map of ``obj`` (lux while its light
    group is on) with its light's spectrum and schedule (``lux = 1``).

    Raises :class:`AgingError` when none counts or a group no longer shares one schedule.
    """
    out = []
    try:
        for item in obj.lightfade.exposure_maps:
            key = bake.maps.map_key(scene, obj, item) if item.image is not None else None
            if key is not None:
                spectrum, uv_filter, hours, days = key
                out.append((item.image, Light(spectrum, uv_filter, 1.0, hours, days)))
    except bake.LightFadeBakeError as err:
        raise AgingError(str(err)) from None
    if not out:
        raise AgingError(f"Object \"{obj.name}\" has no exposure maps from enabled emitters: "
                         "run Bake Exposure first")
    return out


def exposure_problem(scene, obj):
    """One line saying why ``obj`` cannot be aged for lack of exposure, or None."""
    if not _maps(obj):
        return f"Object '{obj.name}' has no exposure maps: run Bake Exposure first"
    try:
        bake.lights_and_exposure(scene, obj, (1, 1))
    except bake.LightFadeBakeError as err:
        return str(err)
    return None


exposure_signature = bake.exposure_signature
remove_exposure = bake.remove_exposure
#: Sources aged per instance (:mod:`.bake.instances`), and Reset's removal of their tiles.
instance_sources = bake.instances.instance_sources
remove_instance_data = bake.instances.remove_instance_data
stale_placements = bake.instances.stale_placements


def scene_objects(scene):
    """``scene``'s objects, then the sources aged through their instances that stand in
    no scene themselves (a list, in the file's order)."""
    objects = list(scene.objects)
    return objects + [o for o in instance_sources(scene) if not o.users_scene]
