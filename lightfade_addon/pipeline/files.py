"""Opening and writing files safely for the scene commands.

Writes never leave a half-written file under the final name: a .blend (or a still) is
first written to a hidden temporary file in the target folder and then renamed over the
target (``os.replace``, atomic on one file system).  Blender writes its ``.blend1``
backup only when it saves over an existing file; it never does here, so none is left.
"""

from __future__ import annotations

import contextlib
import os

import bpy

from ..output import NOISE, captured


class Refused(Exception):
    """This file cannot be processed; the message is one line naming what to do."""


def _first_line(err):
    text = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
    return text.removeprefix("Error: ")


def open_blend(path):
    """Open ``path`` as the current file (without its UI), or raise :class:`Refused`."""
    if not os.path.exists(path):
        raise Refused("no such file")
    if not os.path.isfile(path):
        raise Refused("not a file (a folder?)")
    try:
        with _said_once("open"):
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    except RuntimeError as err:
        if _looks_like_blend(path):
            raise Refused(f"Blender {bpy.app.version_string} cannot read this .blend file "
                          f"({_first_line(err)}): saved by a newer Blender?") from None
        raise Refused(f"not a .blend file ({_first_line(err)})") from None
    return bpy.context.scene


@contextlib.contextmanager
def _said_once(kind):
    """Run a Blender operator with its known noise (:data:`..output.NOISE` ``[kind]``)
    kept off the terminal; the report of a RuntimeError it raises, which Blender prints
    too ("Error: File format is not supported ..."), is left to the caller's one line.
    Anything else it prints is written out when it returns."""
    said, drop = None, ()
    try:
        with captured() as said:
            yield
    except RuntimeError as err:
        drop = (_first_line(err), f"Error: {_first_line(err)}")
        raise
    finally:
        if said is not None:
            said.replay(NOISE[kind], drop)


#: How a .blend file starts: plain, gzip- or zstd-compressed.
_BLEND_MAGIC = (b"BLENDER", b"\x1f\x8b", b"\x28\xb5\x2f\xfd")


def _looks_like_blend(path):
    with open(path, "rb") as f:
        head = f.read(8)
    return head.startswith(_BLEND_MAGIC)


def output_blend(src, output, in_place, suffix, several):
    """The .blend path to write for input ``src``.

    Parameters
    ----------
    src : str
        The input file.
    output : str or None
        ``--output``: a ``.blend`` path (one input) or a folder (each file keeps its name).
    in_place : bool
        ``--in-place``: overwrite ``src``.
    suffix : str
        Added to the input's stem when no ``--output`` is given (``scene_aged.blend``).
    several : bool
        Several inputs: ``output`` is a folder even if it ends in ``.blend``.

    Raises
    ------
    Refused
        The result would overwrite ``src`` without ``--in-place``.
    """
    src = os.path.abspath(src)
    if in_place:
        return src
    stem, _ext = os.path.splitext(os.path.basename(src))
    if output is None:
        out = os.path.join(os.path.dirname(src), stem + suffix + ".blend")
    elif output.lower().endswith(".blend") and not several:
        out = os.path.abspath(output)
    else:
        out = os.path.join(os.path.abspath(output), os.path.basename(src))
    if os.path.normcase(os.path.realpath(out)) == os.path.normcase(os.path.realpath(src)):
        raise Refused(f"the output {out} is the input file: give another --output, or "
                      "--in-place to overwrite it")
    return out


def _temporary(path):
    folder, name = os.path.split(path)
    stem, ext = os.path.splitext(name)
    return os.path.join(folder, f".{stem}.lightfade-{os.getpid()}.tmp{ext}")


def _remove(*paths):
    for p in paths:
        try:
            os.remove(p)
        except FileNotFoundError:
            pass


def save_blend(path):
    """Save the current file as ``path`` through a temporary file and a rename.

    Relative paths in the file are remapped to the new folder; the open file keeps
    its own path (``copy=True``).  On any error the temporary file is removed and the
    target is left as it was.
    """
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = _temporary(path)
    _remove(tmp)  # an existing file would make Blender write a .blend1 backup of it
    try:
        with _said_once("save"):   # not 'Info: Saved copy as ".x.lightfade-1.tmp.blend"'
            bpy.ops.wm.save_as_mainfile(filepath=tmp, copy=True, relative_remap=True,
                                        check_existing=False)
        os.replace(tmp, path)
    except (RuntimeError, OSError) as err:
        raise Refused(f"could not write {path} ({_first_line(err)})") from None
    finally:
        _remove(tmp, tmp + "@", tmp + "1")
    return path


def save_render(scene, path):
    """Write the ``Render Result`` with ``scene``'s output settings as ``path`` (temp + rename)."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = _temporary(path)
    try:
        bpy.data.images["Render Result"].save_render(filepath=tmp, scene=scene)
        os.replace(tmp, path)
    except (RuntimeError, OSError, KeyError) as err:
        raise Refused(f"could not write {path} ({_first_line(err)})") from None
    finally:
        _remove(tmp)
    return path


def write_text(path, text):
    """Write ``text`` as ``path`` (UTF-8) through a temporary file and a rename."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = _temporary(path)
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except OSError as err:
        raise Refused(f"could not write {path} ({_first_line(err)})") from None
    finally:
        _remove(tmp)
    return path
