"""Instances that change with the frame: said once, since an atlas holds one frame's.

The bake packs the placements of one frame (the current one) into each source's atlas
(:mod:`.instances`).  A scatter whose count is animated, or an animated instancer, has
other placements in other frames: they are stale there.  :func:`frame_changes` compares
the scene's first, middle and last frames with the bake's and says so once per source,
with the counts; the line is stored with the source (``instance_changes``) for ``info``.
"""

from __future__ import annotations

from contextlib import contextmanager

import bpy
import numpy as np

from .instances import find_placements


@contextmanager
def _frame(scene):
    """Restores ``scene``'s current frame (and subframe) on exit."""
    frame, sub = scene.frame_current, scene.frame_subframe
    try:
        yield
    finally:
        scene.frame_set(frame, subframe=sub)


def _layout(plan):
    """``{key: rounded world matrix}`` of a plan's placements."""
    return {p.key: [round(v, 4) for row in p.matrix for v in row] for p in plan.placements}


def frame_changes(scene, view_layer, plans):
    """One line per source in ``plans`` whose placements differ at the scene's first,
    middle or last frame from the bake's frame (instances that appear, go or move with time: the
    count of a scatter animated, an animated instancer): an atlas holds the instances of
    one frame, each lit where it stands then.  Stored in ``plan.changes``; the lines
    returned.  The frame is put back."""
    if not plans or scene.frame_start == scene.frame_end:
        return []
    now = {plan.source: _layout(plan) for plan in plans}
    counts = {plan.source: [] for plan in plans}
    with _frame(scene):
        for frame in sorted({scene.frame_start, (scene.frame_start + scene.frame_end) // 2,
                             scene.frame_end}):
            if frame == scene.frame_current:
                continue
            scene.frame_set(frame)
            found = find_placements(bpy.context.evaluated_depsgraph_get(), view_layer)
            for source in now:
                there = found.get(source)
                layout = _layout(there) if there is not None else {}
                if layout.keys() != now[source].keys() or any(
                        not np.allclose(layout[k], now[source][k], atol=1e-3) for k in layout):
                    counts[source].append((frame, len(layout)))
    lines = []
    for plan in plans:
        if counts[plan.source]:
            others = ", ".join(f"{n} at frame {f}" for f, n in counts[plan.source])
            plan.changes = (
                f"\"{plan.source.name}\": its instances change with the frame ({others}, "
                f"{len(now[plan.source])} at frame {scene.frame_current}, baked): an atlas "
                f"holds one frame's instances, each aged where it stands at frame "
                f"{scene.frame_current}; one that appears or moves later reads the tile of "
                "the nearest baked one (geometry nodes) or keeps its own (collection "
                "instances)")
            lines.append(plan.changes)
    return lines
