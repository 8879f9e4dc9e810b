"""The on-disk grid cache inside Blender: the extension's own user directory.

Installed as an extension, grids simulated once are cached in
``bpy.utils.extension_path_user(<package>, create=True)/grids`` (Blender's place for an
extension's data) instead of ``~/.cache``.  Run as a legacy add-on or with the ``bpy``
module, the core's default applies.  :func:`unregister` undoes what :func:`register` did.
"""

import os

import bpy

from ..core import grid

_ENV = "LIGHTFADE_CACHE"
_set_by_us = []


def extension_cache_dir():
    """The extension's grid cache folder, or None when not running as an extension."""
    package = __package__.rpartition(".")[0]
    if not package.startswith("bl_ext."):
        return None
    try:
        return os.path.join(bpy.utils.extension_path_user(package, create=True), "grids")
    except (ValueError, RuntimeError, AttributeError):
        return None


def register():
    path = extension_cache_dir()
    if path is None:
        return
    setter = getattr(grid, "set_cache_dir", None)
    if setter is not None:
        setter(path)
        _set_by_us.append("setter")
    elif _ENV not in os.environ:
        os.environ[_ENV] = path
        _set_by_us.append("env")


def unregister():
    while _set_by_us:
        how = _set_by_us.pop()
        if how == "setter":
            grid.set_cache_dir(None)
        else:
            os.environ.pop(_ENV, None)
