"""The on-disk grid cache inside Blender: the extension's own user directory.

Installed as an extension, grids simulated once are cached in
``bpy.utils.extension_path_user(<package>, create=True)/grids`` (Blender's place for an
extension's data) instead of ``~/.cache``.  Run as a legacy add-on or with the ``bpy``
module, the core's default applies.  :func:`unregister` undoes what :func:`register` did.
"""

import os

import bpy

from ..core.fading import cache


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
    if path is not None:
        cache.set_directory(path)


def unregister():
    if extension_cache_dir() is not None:
        cache.set_directory(None)
