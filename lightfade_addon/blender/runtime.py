"""Prepared agers, kept in memory and keyed robustly by the aged copy's ``session_uid``.

Everything slow happens once per aged copy in :func:`prepare`: albedo and exposure
read, the grid loaded from the file (or simulated once), colours unmixed — a
:class:`~lightfade_addon.core.aging.TextureAger`.  The years slider then only looks
doses up.  The state is rebuilt from what the file holds (albedo image or flat colour,
exposure maps, the stored grid) whenever it is missing: after a file load, an undo, or
in a fresh render process; renaming a material or image does not lose it.

Years past the prepared range (``max_years``) are computed by a second, temporary ager
with a longer dose axis that lives only in memory: the stored grid, and so every
value inside the range, stays exactly as it was.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

from ..core.aging import Light, TextureAger
from ..core.grid import GridSettings
from ..core.recipes import get_recipe
from ..core.restore import Prior
from .errors import AgingError
from .exposure import exposure_signature, lights_and_exposure
from .grids import SceneGridStore
from .pixels import read_linear, read_rgba
from .vocabulary import RECIPE_IDS, SPECTRUM_IDS

#: Smallest prepared range: the slider's soft maximum.
MIN_PREPARED_YEARS = 100.0
#: The grid every preparation uses (the tests of bookkeeping patch in a coarser one).
GRID_SETTINGS = GridSettings()


def prepared_range(years):
    """Years a preparation covers: 100 × the smallest power of two holding ``years``.

    The same rule sizes the temporary far-years ager (:func:`far_ager`), so the slider
    past the range and an Age at that many years use the same dose axis and agree.
    """
    k = max(0, math.ceil(math.log2(max(years, 1e-12) / MIN_PREPARED_YEARS) - 1e-12))
    return MIN_PREPARED_YEARS * 2.0 ** k


@dataclass
class Prepared:
    """A prepared copy: the ager, the pixel buffer and what it was built from."""

    ager: TextureAger
    image_ptr: int
    buffer: np.ndarray                    # (n, 4) float32, Blender's RGBA layout
    inputs: tuple                         # (rgb, recipe, lights, exposure) for a far ager
    years: float | None = None
    far: list = field(default_factory=list)   # at most one temporary ager


_STATES = {}


def clear():
    """Forget every prepared ager (file load, reset, unregister)."""
    _STATES.clear()


def forget(copy):
    _STATES.pop(copy.session_uid, None)


def get(copy):
    """The prepared state of ``copy`` if it is still valid for its image, else None."""
    state = _STATES.get(copy.session_uid)
    image = copy.lightfade.aged_image
    if state is None or image is None or state.image_ptr != image.as_pointer():
        return None
    return state


def material_recipe(material):
    """The core recipe for a material's LightFade settings."""
    props = material.lightfade
    recipe = get_recipe(RECIPE_IDS[props.recipe])
    if props.sensitivity_mode == "BETA":
        return recipe.with_beta(props.beta * 1e-6)
    return recipe.with_blue_wool(props.blue_wool)


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


def prepare(scene, copy, shape, progress=None):
    """Build (or load) the ager of ``copy`` and remember it; returns :class:`Prepared`.

    ``shape`` is the exposure maps' (H, W) (the flat path's texture size).  The grid comes
    from the file's store, else the disk cache, else it is simulated, and is stored
    in the file under the key recorded in ``copy.lightfade.grid_key``.
    """
    props = copy.lightfade
    obj = props.aged_object
    if obj is None or props.source is None:
        raise AgingError(f"Aged material '{copy.name}' lost its object or source: press Reset")
    rgba = albedo_rgba(copy, shape)
    lights, exposure = lights_and_exposure(scene, obj, rgba.shape[:2])
    recipe = material_recipe(props.source)
    prior = material_prior(props.source)
    rgb = rgba[..., :3]
    try:
        ager = TextureAger(rgb, recipe, lights, exposure, max_years=props.max_years,
                           encoding="linear", settings=GRID_SETTINGS, progress=progress,
                           store=SceneGridStore(scene), prior=prior)
    except ValueError as err:
        raise AgingError(f"Material '{props.source.name}' on '{obj.name}': {err}") from None
    props.grid_key = ager.grid.key
    props.lost_texels = 0 if ager.lost is None else int(np.count_nonzero(ager.lost))
    buffer = np.empty((rgb.shape[0] * rgb.shape[1], 4), dtype=np.float32)
    buffer[:, 3] = rgba[..., 3].reshape(-1)
    state = Prepared(ager, props.aged_image.as_pointer(), buffer,
                     (rgb, recipe, lights, exposure, prior))
    _STATES[copy.session_uid] = state
    return state


def far_ager(state, years):
    """An ager covering ``years`` beyond the prepared range, in memory only.

    Its range is :func:`prepared_range` of ``years``, so every process (and an Age at
    that many years) computes the same values for the same years.
    """
    max_years = prepared_range(years)
    if state.far and state.far[0].max_years == max_years:
        return state.far[0]
    rgb, recipe, lights, exposure, prior = state.inputs
    far = TextureAger(rgb, recipe, lights, exposure, max_years=max_years, encoding="linear",
                      settings=GRID_SETTINGS, store=None, prior=prior)
    state.far[:] = [far]
    return far
