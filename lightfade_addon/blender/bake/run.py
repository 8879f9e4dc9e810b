"""A whole exposure bake in one call: :class:`.exposure.ExposureBake` planned, stepped
to the end and committed (scripts, the API, the pipeline; the operator steps the job
itself to stay responsive)."""

from __future__ import annotations

import time

from .common import BakeCancelled
from .exposure import ExposureBake


def bake_exposure(context_or_scene, objects=None, settings=None, report=None, progress=None,
                  cancel=None, only_changed=False, batch=True):
    """Bake one illuminance map (lux) per (mesh, light group) pair.

    Parameters
    ----------
    context_or_scene : bpy.types.Context or bpy.types.Scene
        Where to bake; with a scene, its first view layer (or the current one).
    objects : iterable of bpy.types.Object, optional
        Objects to bake; empty or None: every mesh using a material with LightFade enabled.
    settings : BakeSettings, optional
        Default: :meth:`BakeSettings.from_scene`.
    report : callable(str), optional
        Warnings and notes (skipped objects, UV maps made); default: print.
    progress : callable(fraction, message), optional
        Called after each Cycles bake; default: one printed line per bake.
    cancel : callable() -> bool, optional
        Checked between bakes; True cancels (settings restored, no map stored).
    only_changed : bool
        Keep maps whose light group did not change; sum maps of groups that merged.
    batch : bool or int
        Bake the objects whose maps are at most :data:`.batch.BATCH_MAX_SIZE` (or this
        number) wide together, in atlases (:mod:`.batch`); False: each on its own.

    Returns
    -------
    dict
        ``{"maps": {object: {group: Image}}, "skipped": [messages], "notes": [messages],
        "groups": [(group, [emitters])], "emitters": [(name, kind)], "seconds": float,
        "noise": {(object, group): adaptive.Noise}}`` (adaptive bakes: the error each map
        reached, its samples, whether it hit the cap).
        Image pixels are lux (R = G = B = luminance of the irradiance).

    Raises
    ------
    LightFadeBakeError
        Nothing to bake, no emitters, linked data, overlapping UVs from a modifier... (all
        problems, one per line); :class:`.common.BakeCancelled` when cancelled.
    """
    job = ExposureBake(context_or_scene, objects, settings, report, progress, only_changed,
                       batch=batch)
    job.plan()
    start = time.perf_counter()
    with job:
        while job.step(cancel):
            pass
        if cancel is not None and cancel():
            raise BakeCancelled("Bake cancelled: nothing was changed")
        maps = job.commit()
    return {
        "maps": maps,
        "skipped": job.skipped,
        "notes": job.notes,
        "groups": [(g.name, g.member_names) for g in job.groups],
        "emitters": [(e.name, e.kind) for e in job.emitters],
        "seconds": time.perf_counter() - start,
        "noise": dict(job.noise),
    }

