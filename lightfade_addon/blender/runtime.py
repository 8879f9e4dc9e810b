"""Preparing an aged copy: its aging table and per-texel data, as images in the file.

Everything slow happens once per aged copy in :func:`prepare`: albedo and exposure
read, the grid loaded from the file (or simulated once), colours unmixed — a
:class:`~lightfade_addon.core.aging.TextureAger` — and what it keeps written into
three images the copy's node group reads (:mod:`.agingdata`): the keys, the dose
rates and the aging table. The years then cost nothing here: the material evaluates
them. :func:`evaluator` rebuilds the numpy twin from the same images (after a file
load too, with no unmixing), for real aged images (:mod:`.apply`).
"""

from __future__ import annotations

import hashlib
import math

import numpy as np

from ..core.aging import Light, TextureAger
from ..core.grid import GridSettings
from ..core.recipes import get_recipe
from ..core.restore import Prior
from . import agingdata
from .errors import AgingError
from .exposure import exposure_signature, lights_and_exposure
from .grids import SceneGridStore
from .part_properties import parts_digest
from .pixels import read_linear, read_rgba, resample
from .vocabulary import RECIPE_IDS, SPECTRUM_IDS

#: Smallest prepared range: the slider's soft maximum.
MIN_PREPARED_YEARS = 100.0
#: The grid every preparation uses (the tests of bookkeeping patch in a coarser one).
GRID_SETTINGS = GridSettings()
#: A copy's aging table holds at most one entry per texel of its texture, within these
#: bounds: its data images (keys, rates, table) then weigh about what the float aged
#: image each copy carried before did (benchmarks/footprint.py).
TABLE_ENTRIES = (1 << 18, 1 << 22)


def prepared_range(years):
    """Years a preparation covers: 100 × the smallest power of two holding ``years``."""
    k = max(0, math.ceil(math.log2(max(years, 1e-12) / MIN_PREPARED_YEARS) - 1e-12))
    return MIN_PREPARED_YEARS * 2.0 ** k


#: Numpy evaluators rebuilt from a copy's images, keyed by the copy's ``session_uid``
#: and lane name ('' for the copy's own images) and checked against the images they
#: were read from.
_EVALUATORS = {}


def clear():
    """Forget every cached evaluator (file load, reset, unregister)."""
    _EVALUATORS.clear()


def forget(copy):
    for key in [k for k in _EVALUATORS if k[0] == copy.session_uid]:
        del _EVALUATORS[key]


def settings_recipe(props):
    """The core recipe for recipe settings (a material's, a part's or a lane's)."""
    recipe = get_recipe(RECIPE_IDS[props.recipe])
    if props.sensitivity_mode == "BETA":
        return recipe.with_beta(props.beta * 1e-6)
    return recipe.with_blue_wool(props.blue_wool)


def material_recipe(material):
    """The core recipe for a material's LightFade settings."""
    return settings_recipe(material.lightfade)


def material_prior(material):
    """The texture's own history (:class:`..core.restore.Prior`), or None when it is new.

    ``already_years`` under one light: its spectrum, UV filter, lux and hours per day,
    every day of the year (the texture's lux is taken as uniform).
    """
    s = material.lightfade
    if not s.already_years > 0:
        return None
    light = Light(SPECTRUM_IDS[s.already_spectrum], s.already_uv_filter, s.already_lux,
                  s.already_hours_per_day, 365.0)
    return Prior(float(s.already_years), (light,))


def signature(scene, copy):
    """Digest of everything a copy's aged pixels depend on besides the years.

    Exposure (a new bake, schedules, emitters), the source material's recipe and
    sensitivity, the albedo path and its image.  A stored digest that differs from the
    current one means the copy is stale.
    """
    props = copy.lightfade
    source = props.source
    obj = props.aged_object
    if source is None or obj is None:
        return ""
    s = source.lightfade
    albedo = props.albedo
    parts = [exposure_signature(scene, obj), s.recipe, s.sensitivity_mode, str(s.blue_wool),
             repr(s.beta), repr(material_prior(source)), props.path, props.uv_map,
             albedo.name if albedo is not None else repr(tuple(props.flat_colour)),
             str(tuple(albedo.size)) if albedo is not None else ""]
    if len(s.parts):                                  # several recipes by mask (.parts)
        parts.append(parts_digest(s))
    return hashlib.sha1("|".join(parts).encode()).hexdigest()


def albedo_rgba(copy, shape):
    """(H, W, 4) linear albedo of a copy; ``shape`` is used by the flat path only."""
    props = copy.lightfade
    if props.path == "FLAT":
        rgba = np.ones((*shape, 4), dtype=np.float32)
        rgba[..., :3] = props.flat_colour
    elif props.albedo is None:
        raise AgingError(f"Material '{copy.name}' lost its albedo image: press Age again")
    elif props.path == "DIRECT":
        rgba = read_linear(props.albedo)
    else:
        rgba = read_rgba(props.albedo)
    rgb = np.nan_to_num(rgba[..., :3], nan=0.0, posinf=1.0, neginf=0.0)
    rgba[..., :3] = np.clip(rgb, 0.0, 1.0)          # a Base Color is a reflectance
    return rgba


def prepare(scene, copy, shape, progress=None, lane=None):
    """Build (or load) the aging of ``copy`` and write its images and node group data.

    ``shape`` is the exposure maps' (H, W) (the flat path's texture size).  The grid
    comes from the file's store, else the disk cache, else it is simulated, and is
    stored in the file under the key recorded in ``copy.lightfade.grid_key``.  With
    ``lane`` (one recipe of a material with parts, :mod:`.parts`) that lane's recipe
    is prepared and its images and grid key are kept in the lane.
    Returns the :class:`~lightfade_addon.core.aging.TextureAger`.
    """
    props = copy.lightfade
    obj = props.aged_object
    if obj is None or props.source is None:
        raise AgingError(f"Aged material '{copy.name}' lost its object or source: press Reset")
    rgba = albedo_rgba(copy, shape)
    lights, at_bake = lights_and_exposure(scene, obj, shape)     # read once, at the bake's size
    exposure = np.stack([resample(m, rgba.shape[:2]) for m in at_bake])
    recipe = material_recipe(props.source) if lane is None else settings_recipe(lane)
    prior = material_prior(props.source)
    # the node group reads the rates at the bake's resolution: the grid must reach their max
    max_rate = float(sum(e.max() * light.annual_dose for e, light in zip(at_bake, lights)))
    try:
        ager = TextureAger(rgba[..., :3], recipe, lights, exposure, max_years=props.max_years,
                           encoding="linear", settings=GRID_SETTINGS, progress=progress,
                           store=SceneGridStore(scene), prior=prior, max_rate=max_rate,
                           table_entries=min(max(rgba.shape[0] * rgba.shape[1],
                                                 TABLE_ENTRIES[0]), TABLE_ENTRIES[1]))
    except ValueError as err:
        raise AgingError(f"Material '{props.source.name}' on '{obj.name}': {err}") from None
    data = props if lane is None else lane
    data.grid_key = ager.grid.key
    data.lost_texels = 0 if ager.lost is None else int(np.count_nonzero(ager.lost))
    agingdata.write(copy, ager, lights, at_bake, restored=prior is not None, lane=lane)
    forget(copy)
    return ager


def evaluator(copy, lane=None):
    """(table, texels, positions, original RGBA) of ``copy`` (or of its ``lane``) for
    :func:`..core.table.evaluate`, read from the images (cached while they are unchanged)."""
    key = agingdata.fingerprint(copy, lane)
    slot = (copy.session_uid, "" if lane is None else lane.name)
    cached = _EVALUATORS.get(slot)
    if cached is not None and cached[0] == key:
        return cached[1]
    original = albedo_rgba(copy, agingdata.key_shape(copy, lane))
    restored = (copy.lightfade if lane is None else lane).restored_image
    if restored is not None:
        original = read_rgba(restored)
    data = agingdata.read(copy, original, lane)
    _EVALUATORS[slot] = (key, data)
    return data
