"""What LightFade prints: counts in words, and the libraries' chatter kept off the terminal.

Blender and the image libraries print from C, straight to the process's file
descriptors 1 and 2, where Python's ``sys.stdout`` cannot catch it:
:func:`captured` points the descriptors at temporary files for a while and hands back
the lines written meanwhile; :func:`quiet` does the same and then writes back every
line that is not known noise (a pattern of :data:`NOISE`), so a real error still
reaches the terminal.  Python's own ``print`` is caught too.

>>> plural(1, "material"), plural(3, "material"), plural(2, "still")
('1 material', '3 materials', '2 stills')

This module imports neither ``core`` nor Blender.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import os
import re
import sys
import tempfile

__all__ = ["plural", "captured", "quiet", "NOISE", "Captured"]


def plural(n, noun, nouns=None):
    """``n`` and ``noun`` in the number that ``n`` asks for: ``"1 map"``, ``"0 maps"``.

    Parameters
    ----------
    n : int or float
        The count (a float is written with ``:g``: ``2.5 years``).
    noun : str
        The singular (``"material"``, ``"light group"``).
    nouns : str, optional
        The plural, when it is not ``noun + "s"`` (``"matrices"``).
    """
    text = f"{n:g}" if isinstance(n, float) else str(n)
    return f"{text} {noun if n == 1 else (nouns or noun + 's')}"


def maps_made(result, noun="map"):
    """What an exposure bake made, as it makes it: one map per object and light group.

    ``result`` is the dict of ``blender.bake.bake_exposure`` (``"maps"``: object →
    {light group: image}, ``"groups"``, ``"emitters"``).

    >>> maps_made({"maps": {"A": {"Sun": 0, "Lamps": 0}, "B": {"Sun": 0, "Lamps": 0}},
    ...            "groups": ["Sun", "Lamps"], "emitters": ["Sun", "L1", "L2"]})
    '4 maps (2 objects x 2 light groups of 3 emitters)'
    """
    maps = sum(len(m) for m in result["maps"].values())
    objects, groups = len(result["maps"]), len(result["groups"])
    emitters = len(result["emitters"])
    split = " x " if maps == objects * groups else ", "
    detail = plural(objects, "object") + split + plural(groups, "light group")
    if emitters != groups:
        detail += " of " + plural(emitters, "emitter")
    return f"{plural(maps, noun)} ({detail})"


#: Known noise, by where it comes from: full-line regular expressions.
NOISE = {
    # Blender 4.x prints a status line per step of a render in background mode ("Fra:1
    # Mem:10.54M (Peak 10.54M) | Time:00:00.00 | Compositing | Operation 2-6"): some 20
    # a still, 8 for each map the bake denoises through the compositor.
    "render": (r"Fra:\d+ Mem:\S+ \(Peak \S+\) \| .*",),
    # 5.x: a compositor on the GPU (a new scene's default) in a process without a
    # display: its context fails three times, then the compositor runs on the CPU.
    "gpu": (r"EGL Error \(0x3009\): EGL_BAD_MATCH: .*",),
    # A save's report: 5.x "Saved copy as", 4.x "Saved" plus the remap's counts (when
    # a path failed to remap, that line is news).
    "save": (r'Info: Saved (copy as )?".*"',
             r"Info: Total files \d+ \| Changed \d+ \| Failed 0"),
    # Opening a file: "Read blend:", with the log's time and category from 5.0 on.
    "open": (r'(\d+:\d+\.\d+\s+blend\s+\|\s+)?Read blend: ".*"',),
}


@functools.cache
def _libc():
    try:
        return ctypes.CDLL("ucrtbase" if sys.platform == "win32" else None)
    except OSError:
        return None


def _c_flush():
    """Flush C's stdio buffers (what Blender's ``printf`` holds back) where we can."""
    libc = _libc()
    if libc is not None:
        with contextlib.suppress(AttributeError):
            libc.fflush(None)


def _flush():
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, ValueError, OSError):
            stream.flush()
    _c_flush()


class Captured:
    """What :func:`captured` caught: ``lines[fd]``, a list of lines (no line ends)."""

    def __init__(self, fds):
        self.lines = {fd: [] for fd in fds}

    def all_lines(self):
        """Every line caught, descriptor by descriptor, without blank ones."""
        return [x for fd in self.lines for x in self.lines[fd] if x.strip()]

    def replay(self, noise=(), drop=()):
        """Write the lines back to their descriptors, less the ones matching a pattern
        of ``noise`` (regular expressions matching the whole line) or equal to one of
        ``drop``."""
        patterns = [re.compile(p) for p in noise]
        _flush()
        for fd, lines in self.lines.items():
            kept = [x for x in lines
                    if x not in drop and not any(p.fullmatch(x) for p in patterns)]
            data = ("\n".join(kept) + "\n").encode("utf-8", "replace") if kept else b""
            while data:
                data = data[os.write(fd, data):]


@contextlib.contextmanager
def captured(fds=(1, 2)):
    """Catch what is written to file descriptors ``fds`` meanwhile (C code too).

    Yields a :class:`Captured`, filled when the block ends (also on an error); nothing
    is written back unless the caller replays it (:meth:`Captured.replay`).  A
    descriptor that is not open (Blender's UI on Windows has no console) is left alone.
    """
    result = Captured(fds)
    _flush()
    saved, files = {}, {}
    try:
        for fd in fds:
            try:
                copy = os.dup(fd)
            except OSError:         # not open (Blender's UI on Windows has no console)
                continue
            saved[fd] = copy
            files[fd] = tempfile.TemporaryFile()
            os.dup2(files[fd].fileno(), fd)
        yield result
    finally:
        _flush()
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
        for fd, f in files.items():
            f.seek(0)
            result.lines[fd] = f.read().decode("utf-8", "replace").splitlines()
            f.close()


@contextlib.contextmanager
def quiet(*kinds, fds=(1, 2)):
    """Run the block with the noise of ``kinds`` (keys of :data:`NOISE`) left out of
    descriptors ``fds``; every other line is written back when the block ends."""
    noise = [p for kind in kinds for p in NOISE[kind]]
    out = None
    try:
        with captured(fds) as out:
            yield out
    finally:
        if out is not None:
            out.replay(noise)
