"""The fading grids a .blend uses, kept inside it (``Scene["lightfade_grids"]``).

Render nodes then never simulate: a fresh process rebuilds each aged material's
:class:`~lightfade_addon.core.aging.ager.TextureAger` from the file's grid.  Only the grids
that aged copies name are kept (:func:`purge`), so repeated Age and Bake do not grow
the file.
"""

from __future__ import annotations

import base64
import collections.abc

GRID_STORE = "lightfade_grids"


class SceneGridStore(collections.abc.MutableMapping):
    """``Scene["lightfade_grids"]`` as a mapping of grid keys to bytes (base64 inside)."""

    def __init__(self, scene):
        self.scene = scene

    def _group(self, create=False):
        if GRID_STORE not in self.scene and create:
            self.scene[GRID_STORE] = {}
        return self.scene.get(GRID_STORE)

    def __getitem__(self, key):
        group = self._group()
        if group is None or key not in group:
            raise KeyError(key)
        return base64.b64decode(group[key])

    def __setitem__(self, key, value):
        self._group(create=True)[key] = base64.b64encode(value).decode("ascii")

    def __delitem__(self, key):
        del self._group()[key]

    def __iter__(self):
        group = self._group()
        return iter(list(group.keys()) if group is not None else [])

    def __len__(self):
        group = self._group()
        return len(group) if group is not None else 0


def purge(scene, keep):
    """Remove every stored grid whose key is not in ``keep``; the store too when empty."""
    store = SceneGridStore(scene)
    for key in list(store):
        if key not in keep:
            del store[key]
    if GRID_STORE in scene and len(store) == 0:
        del scene[GRID_STORE]
