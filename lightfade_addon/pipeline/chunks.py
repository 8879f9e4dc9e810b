"""Bake tasks sized from the bake's own time estimate: objects into chunks.

A farm job splits the exposure bake into tasks of one light group and one chunk of
objects (:mod:`.farm`).  Each object's bake time for one group comes from the bake's
estimate (:func:`..blender.bake.sizing.estimate`: texel·samples over the calibrated
rate, plus denoising); a chunk should take about ``target`` seconds, so that a task
runs for minutes, not seconds (a task also pays Blender's start and the file's opening,
``overhead``), and the chunks of a group are alike in time.  Pure Python: no bpy.
"""

from __future__ import annotations


def chunk_count(seconds, target, overhead=0.0):
    """How many chunks share work of ``seconds`` (a list, per object) at ``target``
    seconds per task, each task paying ``overhead`` seconds once: the chunks first-fit
    decreasing packing needs (an object longer than a task is a chunk of its own): at
    least 1, at most one per object."""
    if not seconds:
        return 0
    usable = max(float(target) - float(overhead), 1e-9)
    bins = []
    for s in sorted((float(x) for x in seconds), reverse=True):
        k = next((i for i, load in enumerate(bins) if load + s <= usable), None)
        if k is None:
            bins.append(s)
        else:
            bins[k] += s
    return max(1, len(bins))


def split(names, seconds, count):
    """``names`` into ``count`` chunks of alike total ``seconds`` (longest first, each to
    the chunk with the least so far: the LPT rule, within 4/3 of the best split).

    Ties go to the lower chunk and to the earlier name, so that the split is the same on
    every machine; each chunk keeps the names in their given order.  Returns a list of
    ``count`` lists of names (none empty when ``count <= len(names)``).
    """
    loads = [0.0] * count
    member = [[] for _ in range(count)]
    order = sorted(range(len(names)), key=lambda i: (-float(seconds[i]), i))
    for i in order:
        k = min(range(count), key=lambda c: (loads[c], c))
        loads[k] += float(seconds[i])
        member[k].append(i)
    return [[names[i] for i in sorted(m)] for m in member]


def chunk_objects(names, seconds, target, overhead=0.0):
    """Chunks of ``names`` (per-object bake ``seconds`` for one light group) for tasks
    of about ``target`` seconds: :func:`chunk_count` chunks by :func:`split`."""
    return split(list(names), list(seconds), chunk_count(seconds, target, overhead))
