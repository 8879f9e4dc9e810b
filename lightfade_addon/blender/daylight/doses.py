"""Annual doses per texel and the years until a just-noticeable fade, as arrays.

``annual_dose(scene, obj)`` reads the stored exposure maps: each holds the illuminance
(lux) while its group is on, so its annual dose is ``lux × hours/day × days/year``; the
daylight group's map holds the year-round mean illuminance and counts 24 h × 365 d
(:mod:`..bake.daylight`).  ``years_until_noticeable`` ages the material's own colours
under all the object's light groups (:class:`..core.aging.TextureAger`, the same inputs
Age uses) and finds, per texel, the years at which CIEDE2000 from new reaches 1
(:func:`..core.noticeable.years_to_noticeable`).
"""

from __future__ import annotations

import bpy
import numpy as np

from ...core.aging.ager import TextureAger
from ...core.fading.grid import GridSettings
from ...core.aging.noticeable import JND_DELTA_E00, years_to_noticeable
from ..bake.common import LightFadeBakeError
from ..bake.instances import tiled
from ..bake.maps import exposure_signature, lights_and_exposure, map_key, read_lux
from ..bake.raster import rasterise
from ..bake.uvmaps import evaluated_mesh, triangle_uvs
from ..pixels import read_linear, read_rgba, resample
from ..aging.runtime import material_recipe
from ..source import material_plan

#: Years the noticeable-fade view looks ahead: slower texels read "> this".
HORIZON_YEARS = 1000.0


def annual_dose(scene, obj):
    """``{light group name: (H, W) float32 lux·h per year}`` of ``obj``'s exposure maps.

    Maps of emitters that are gone, excluded or replaced by annual daylight are left out;
    rows run bottom-up as in the image (row 0 is UV v = 0).

    Raises
    ------
    LightFadeBakeError
        ``obj`` is not a mesh or has no counted exposure map (bake first);
        :class:`..bake.maps.StaleExposureError` when a baked group has split.
    """
    if obj is None or obj.type != "MESH":
        raise LightFadeBakeError(f"'{getattr(obj, 'name', obj)}' is not a mesh: annual doses "
                                 "are per texel of a mesh's exposure maps")
    doses = {}
    for item in obj.lightfade.exposure_maps:
        if item.image is None or tuple(item.image.size) == (0, 0):
            continue
        key = map_key(scene, obj, item)
        if key is None:
            continue
        _spectrum, _uv, hours, days = key
        doses[item.name] = (read_lux(item.image) * (hours * days)).astype(np.float32)
    if not doses:
        raise LightFadeBakeError(f"Object \"{obj.name}\" has no exposure maps from counted "
                                 "emitters: run Bake Exposure first")
    return doses


def total_dose(scene, obj):
    """(H, W) float32: the sum of :func:`annual_dose` over the light groups."""
    return sum(annual_dose(scene, obj).values())


def texel_albedo(scene, obj, material, shape):
    """(H, W, 3) linear Base Color of ``material`` on ``obj`` at the exposure texels.

    Direct path: the image resampled to the exposure map; flat: the colour; baked: the
    albedo Age baked (an aged copy of this material on this object), else an error
    saying to Age first.
    """
    plan = material_plan(scene, obj, material)
    if plan.problems:
        raise LightFadeBakeError("\n".join(plan.problems))
    if plan.path == "FLAT":
        return np.broadcast_to(np.float32(plan.flat), (*shape, 3)).copy()
    if plan.path == "DIRECT":
        rgb = read_linear(plan.image)[..., :3]
    else:
        baked = [s.material for s in obj.material_slots if s.material is not None
                 and s.material.lightfade.source == material
                 and s.material.lightfade.albedo is not None]
        if not baked:
            raise LightFadeBakeError(
                f"Material '{material.name}' on '{obj.name}' takes its colour from a node graph "
                "Cycles must bake: press Age once, then show the noticeable-fade view")
        rgb = read_rgba(baked[0].lightfade.albedo)[..., :3]
    rgb = np.clip(np.nan_to_num(rgb, nan=0.0, posinf=1.0), 0.0, 1.0)

    def at(width):                              # an atlas repeats it in each tile
        if rgb.shape[:2] == (width, width):
            return rgb
        return np.stack([resample(rgb[..., c], (width, width)) for c in range(3)], axis=-1)

    if shape[0] != shape[1]:
        return np.stack([resample(rgb[..., c], shape) for c in range(3)],
                        axis=-1).astype(np.float32)
    return tiled(obj, at, shape[0], 0.0).astype(np.float32)


def years_until_noticeable(scene, obj, material, horizon=HORIZON_YEARS,
                           threshold=JND_DELTA_E00, settings=None):
    """(H, W) float32 years until each texel of ``material`` on ``obj`` fades by
    ``threshold`` ΔE00 (inf: not within ``horizon`` years), at the exposure map's texels.

    ``settings`` is the fading grid's (:class:`..core.grid.GridSettings`, default the
    shipped one).
    """
    doses = annual_dose(scene, obj)
    shape = next(iter(doses.values())).shape
    lights, exposure = lights_and_exposure(scene, obj, shape)
    rgb = texel_albedo(scene, obj, material, shape)
    ager = TextureAger(rgb, material_recipe(material), lights, exposure, max_years=horizon,
                       encoding="linear", settings=settings or GridSettings())
    return years_to_noticeable(ager, threshold)


def material_labels(obj, size, depsgraph=None):
    """(size, size) int32: the material slot index of the face covering each texel of the
    exposure UV map (-1 where none); rows bottom-up as in the maps."""
    depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
    with evaluated_mesh(obj, depsgraph) as mesh:
        uv_name = obj.lightfade.uv_map if obj.lightfade.uv_map in mesh.uv_layers else (
            mesh.uv_layers.active.name if mesh.uv_layers else None)
        if uv_name is None:
            return np.full((size, size), -1, dtype=np.int32)
        tri, poly = triangle_uvs(mesh, uv_name)
        index = np.empty(len(mesh.polygons), dtype=np.int64)
        mesh.polygons.foreach_get("material_index", index)
    return tiled(obj, lambda width: rasterise(tri, width, index[poly], strict=False)[1],
                 size, -1)


_SUMMARY = {}


def material_doses(scene, obj):
    """Annual dose per material of ``obj`` and light group, over the texels the material
    covers: a list of dicts ``{"material", "group", "max", "mean"}`` in lux·h per year
    (cached on the maps' bake counts and the groups' schedules)."""
    from ..bake.maps import exposure_signature

    key = (obj.session_uid, exposure_signature(scene, obj),
           tuple(s.material.name if s.material else "" for s in obj.material_slots))
    if key in _SUMMARY:
        return _SUMMARY[key]
    doses = annual_dose(scene, obj)
    size = next(iter(doses.values())).shape[0]
    labels = material_labels(obj, size)
    rows = []
    for index, slot in enumerate(obj.material_slots):
        mask = labels == index
        if slot.material is None or not mask.any():
            continue
        material = slot.material.lightfade.source or slot.material
        for group, dose in doses.items():
            d = dose[mask] if dose.shape == labels.shape else dose.ravel()
            rows.append({"material": material.name, "group": group,
                         "max": float(d.max()), "mean": float(d.mean())})
    if len(_SUMMARY) > 64:
        _SUMMARY.clear()
    _SUMMARY[key] = rows
    return rows
