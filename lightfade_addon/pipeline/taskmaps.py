"""The maps a Bake task hands to Merge: one ``.npz`` file per task, written atomically.

A file holds, for one light group and one chunk of objects, each object's exposure map
(lux, float32, rows bottom-up as in the image) and a header saying where it comes from:
the scene file's SHA-256, the settings hash (bake settings and light groups), the task
(group and chunk), and per object the map size, UV map and a hash of its UV
coordinates.  Merge takes a file only when all of these are the job's
(:func:`check`): a map of another scene, of other settings or of a half-finished task is
refused with one line naming the task to rerun.

Written under a hidden temporary name in the same folder and renamed over the final
name once complete (``os.replace``, atomic on one file system): a task killed midway
leaves at most the temporary file, which Merge never reads.  Pure Python and numpy.
"""

from __future__ import annotations

import hashlib
import json
import os

import numpy as np

#: Version of the file layout; Merge refuses another.
FORMAT = 1


class MapProblem(Exception):
    """A task's maps cannot be merged; the message is one line naming the task to rerun."""


def task_label(group, chunk):
    """How a Bake task is named to people and to ``openjd run --task-param``."""
    return f"Bake task Group={group} Chunk={chunk}"


def file_name(group_index, chunk):
    return f"g{int(group_index):03d}_c{int(chunk):04d}.npz"


def settings_hash(settings):
    """SHA-256 (16 hex digits) of a JSON-able dict: bake settings and light groups."""
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def file_sha256(path, block=1 << 20):
    """SHA-256 of a file's bytes (hex): which scene a map was baked from."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(block):
            h.update(chunk)
    return h.hexdigest()


def uv_hash(uv):
    """SHA-256 (16 hex digits) of UV coordinates (any shape, float), rounded to 1e-6."""
    a = np.round(np.asarray(uv, dtype=np.float64), 6).astype(np.float32)
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()[:16]


def write(path, header, maps, about):
    """Write ``maps`` (``{object name: (H, W) lux}``) and ``header`` (a JSON-able dict)
    as ``path``, atomically.  ``about``: ``{object name: dict}`` (its UV map and UV hash),
    kept in the header's ``objects`` with each map's name and shape, in order.

    The data is flushed to disk before the rename, so that the final name never points
    at a file a crash could leave short.
    """
    folder, name = os.path.split(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    names = list(maps)
    header = dict(header, format=FORMAT, objects=[
        dict(about.get(n, {}), name=n, shape=list(np.shape(maps[n]))) for n in names])
    arrays = {f"map{i}": np.asarray(maps[n], dtype=np.float32) for i, n in enumerate(names)}
    tmp = os.path.join(folder, f".{name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            np.savez(f, header=np.array(json.dumps(header)), **arrays)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return path


def read(path):
    """``(header, {object name: (H, W) float32 lux})`` of a task's file."""
    with np.load(path, allow_pickle=False) as data:
        header = json.loads(str(data["header"]))
        maps = {o["name"]: data[f"map{i}"] for i, o in enumerate(header["objects"])}
    return header, maps


def check(path, label, scene, settings, group, objects):
    """The header of ``path`` if it is the task's maps for this job, else
    :class:`MapProblem` (one line: what is wrong and ``label``, the task to rerun).

    ``objects``: ``{name: {"shape": [H, W], "uv_map": name}}`` that the task bakes.
    """
    rerun = f": rerun {label}"
    if not os.path.isfile(path):
        raise MapProblem(f"no maps from {label} ({path} is missing){rerun}")
    try:
        header, maps = read(path)
    except Exception as err:  # noqa: BLE001 (a damaged file: whatever numpy says)
        raise MapProblem(f"the maps of {label} cannot be read ({path}: "
                         f"{type(err).__name__}: {err}){rerun}") from None
    if header.get("format") != FORMAT:
        raise MapProblem(f"{path} has maps of another layout (format "
                         f"{header.get('format')}, not {FORMAT}){rerun}")
    if header.get("scene") != scene:
        raise MapProblem(f"{path} was baked from another scene (SHA-256 "
                         f"{str(header.get('scene'))[:12]}..., the job's is {scene[:12]}...)"
                         f"{rerun}")
    if header.get("settings") != settings:
        raise MapProblem(f"{path} was baked with other settings (settings hash "
                         f"{header.get('settings')}, the job's is {settings}){rerun}")
    if header.get("group") != group:
        raise MapProblem(f"{path} holds light group '{header.get('group')}', not "
                         f"'{group}'{rerun}")
    got = {o["name"]: o for o in header["objects"]}
    if sorted(got) != sorted(objects):
        raise MapProblem(f"{path} holds maps of {sorted(got)}, not {sorted(objects)}{rerun}")
    for name, want in objects.items():
        have = got[name]
        if list(maps[name].shape) != list(want["shape"]) or have.get("uv_map") != want["uv_map"]:
            raise MapProblem(f"{path}: the map of '{name}' is {have.get('shape')} on UV map "
                             f"'{have.get('uv_map')}', the job needs {want['shape']} on "
                             f"'{want['uv_map']}'{rerun}")
        if not np.all(np.isfinite(maps[name])):
            raise MapProblem(f"{path}: the map of '{name}' holds NaN or infinite texels{rerun}")
    return header
