"""Where grids are kept between runs: a store given by the caller, then a folder on disk.

The folder is, in order: the one given to :func:`set_directory` (the Blender shell
passes ``bpy.utils.extension_path_user(__package__, path="grids", create=True)``),
``$LIGHTFADE_CACHE``, ``$XDG_CACHE_HOME/lightfade``, ``~/.cache/lightfade``.
"""

from __future__ import annotations

import os
import pathlib
import tempfile

from . import gridbuild
from .grid import GridSettings
from .gridfile import grid_from_bytes, grid_to_bytes
from .spectra import WAVELENGTHS

__all__ = ["directory", "set_directory", "load_or_build"]

_directory = None


def set_directory(path):
    """Keep grids in ``path`` from now on (created on first write); None: the default.

    Parameters
    ----------
    path : str or os.PathLike or None
    """
    global _directory
    _directory = None if path is None else pathlib.Path(path)


def directory():
    """The folder grids are kept in (see the module docstring for the order)."""
    if _directory is not None:
        return _directory
    root = os.environ.get("LIGHTFADE_CACHE")
    if root:
        return pathlib.Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return pathlib.Path(xdg or pathlib.Path.home() / ".cache") / "lightfade"


def load_or_build(recipe, spectra, max_dose, settings=GridSettings(), wavelengths=WAVELENGTHS,
                  cache=True, progress=None, store=None):
    """The grid from ``store``, the disk cache, or built (and put in both).

    The file name is the grid's key, so a change to anything it depends on makes a
    new file. Writes go to a temporary file in the same folder and are renamed into
    place (atomic on POSIX and Windows), so two processes building the same grid
    never leave a partial file; a corrupt or partial file is detected by its
    checksum and rebuilt.

    Parameters
    ----------
    recipe, spectra, max_dose, settings, wavelengths, progress
        As for :func:`.gridbuild.build_grid`.
    cache : bool
        Use the folder on disk.
    store : MutableMapping[str, bytes], optional
        Looked in first and given every grid used (the Blender layer keeps the
        grids a .blend needs inside the file, so render nodes never simulate).
    """
    key = gridbuild.grid_key(recipe, spectra, max_dose, settings, wavelengths)
    if store is not None and key in store:
        grid = _read(store[key], key)
        if grid is not None:
            return grid
    path = directory() / f"grid-{key}.npz"
    grid = _read_file(path, key) if cache else None
    if grid is None:
        grid = gridbuild.build_grid(recipe, spectra, max_dose, settings, wavelengths, progress)
        if cache:
            _write_file(path, grid_to_bytes(grid))
    if store is not None:
        store[key] = grid_to_bytes(grid)
    return grid


def _read(data, key):
    try:
        grid = grid_from_bytes(data)
    except ValueError:
        return None
    return grid if grid.key == key else None


def _read_file(path, key):
    try:
        return _read(path.read_bytes(), key)
    except OSError:
        return None


def _write_file(path, data):
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".grid-", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only cache only costs a rebuild next time
