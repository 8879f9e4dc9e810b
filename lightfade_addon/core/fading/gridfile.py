"""A :class:`.grid.FadeGrid` as bytes: an .npz with a JSON header and a checksum.

The Blender shell keeps the grids a .blend needs inside the file (so render nodes
never simulate) and :mod:`.cache` keeps them on disk; both go through these two
functions, which detect corrupt or partial data.
"""

from __future__ import annotations

import hashlib
import io
import json

import numpy as np

from .grid import FadeGrid

__all__ = ["grid_to_bytes", "grid_from_bytes", "FILE_FORMAT"]

#: Bumped whenever the layout of the bytes changes.
FILE_FORMAT = 2


def grid_to_bytes(grid):
    """The grid as bytes (an .npz with a checksum), e.g. to store in a .blend."""
    buf = io.BytesIO()
    meta = dict(format=FILE_FORMAT, key=grid.key, recipe=grid.recipe, q=grid.q,
                naxes=len(grid.axes))
    arrays = {f"axis{k}": a for k, a in enumerate(grid.axes)}
    arrays.update(mixes=grid.mixes, doses=grid.doses, change=grid.change)
    if grid.initial is not None:
        arrays["initial"] = grid.initial
    meta["sha256"] = _digest(arrays)
    np.savez(buf, meta=np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8), **arrays)
    return buf.getvalue()


def grid_from_bytes(data):
    """Inverse of :func:`grid_to_bytes`; ValueError if the data is corrupt or partial."""
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            meta = json.loads(bytes(z["meta"]).decode())
            arrays = {k: z[k] for k in z.files if k != "meta"}
    except Exception as exc:  # zipfile, json and numpy errors alike
        raise ValueError(f"not a readable LightFade grid ({exc})") from None
    if meta.get("format") != FILE_FORMAT:
        raise ValueError(f"grid format {meta.get('format')} is not {FILE_FORMAT}")
    if _digest(arrays) != meta.get("sha256"):
        raise ValueError("grid checksum mismatch (corrupt or partial data)")
    axes = [arrays[f"axis{k}"] for k in range(meta["naxes"])]
    return FadeGrid(meta["key"], meta["recipe"], axes, arrays["mixes"], arrays["doses"],
                    arrays["change"], meta["q"], arrays.get("initial"))


def _digest(arrays):
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()
