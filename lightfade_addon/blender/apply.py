"""Years -> pixels: write each aged copy's texture for a number of years.

The one path every consumer takes — the slider's update callback, the frame-change
handler (keyframed years), :func:`lightfade_addon.api.set_years` and a fresh process
rendering the saved file — so they always agree:

1. a copy whose :func:`.runtime.signature` no longer matches (a new bake, a changed
   recipe or schedule) is prepared again from the file's data before it is shown;
2. the dose lookup of the prepared ager (or, past its range, of a temporary one) is
   written into the aged image, clipped to [0, 1] and finite.
"""

from __future__ import annotations

import time

import numpy as np

from . import runtime
from .copies import copies_of
from .errors import AgingError, check_years
from .exposure import exposure_shape, exposure_uv
from .pixels import write_rgba


def aged_copies(scene):
    """Aged copies whose object is in ``scene``."""
    objects = set(scene.objects)
    return [c for c in copies_of() if c.lightfade.aged_object in objects]


def stale_reason(scene, copy):
    """Why ``copy`` no longer matches its inputs ('' when up to date)."""
    props = copy.lightfade
    if props.signature != runtime.signature(scene, copy):
        return "exposure, schedule or recipe changed since Age"
    return ""


def needs_age(scene, copy):
    """Why a stale copy needs the Age button (a new Cycles albedo bake), or ''."""
    props = copy.lightfade
    obj = props.aged_object
    if props.path == "BAKED" and props.albedo is not None and obj is not None:
        shape = exposure_shape(obj)
        if shape != tuple(props.albedo.size)[::-1] or exposure_uv(obj) != props.uv_map:
            return "the exposure was baked at another size or UV map: press Age"
    return ""


def _state(scene, copy):
    """The prepared state, (re)built from the file when missing or stale."""
    state = runtime.get(copy)
    stale = copy.lightfade.signature != runtime.signature(scene, copy)
    if state is not None and not stale:
        return state
    blocked = needs_age(scene, copy) if stale else ""
    if blocked:
        raise AgingError(f"Material '{copy.lightfade.source.name}' on "
                         f"'{copy.lightfade.aged_object.name}' is stale: {blocked}")
    obj = copy.lightfade.aged_object
    state = runtime.prepare(scene, copy, exposure_shape(obj) or (64, 64))
    copy.lightfade.signature = runtime.signature(scene, copy)
    return state


def write_years(state, image, years):
    """Age ``state`` to ``years`` into ``image`` (finite, in [0, 1])."""
    ager = state.ager if years <= state.ager.max_years else runtime.far_ager(state, years)
    ager.age(years, out=state.buffer)
    rgb = state.buffer[:, :3]
    np.nan_to_num(rgb, copy=False, nan=0.0, posinf=1.0, neginf=0.0)
    np.clip(rgb, 0.0, 1.0, out=rgb)
    write_rgba(image, state.buffer)
    state.years = years


def show(scene, copy, years, force=False):
    """Show ``years`` on one aged copy; True if its pixels were written."""
    state = _state(scene, copy)
    if not force and state.years == years:
        return False
    write_years(state, copy.lightfade.aged_image, years)
    return True


def update_scene(scene, years=None, report=print):
    """Show ``years`` (default: the scene's slider) on every aged copy; seconds taken.

    Stale copies are brought up to date first; one that needs Age is left as it was
    and reported in one line.
    """
    t0 = time.perf_counter()
    years = check_years(scene.lightfade.years if years is None else years)
    for copy in aged_copies(scene):
        try:
            show(scene, copy, years)
        except AgingError as err:
            report(f"LightFade: {err}")
    return time.perf_counter() - t0
