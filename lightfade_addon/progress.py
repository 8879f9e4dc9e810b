"""One progress protocol for the core, the command line, Blender and the Python API.

Every long-running function takes an optional ``progress`` argument: a callable
``progress(fraction, message)`` with ``fraction`` in [0, 1] of the whole job done and
``message`` a short text saying what is being done. It returns nothing and must be
cheap. Who shows it is an adapter:

* :class:`ProgressBar` — the command line: a redrawn bar on a terminal, one plain line
  per new message anywhere else (a pipe, a log, ``blender -b``);
* ``lightfade_addon.blender.progress.WindowProgress`` (and ``window_progress``, its
  context manager) — Blender's window progress indicator and status bar, or a
  :class:`ProgressBar` line per step in background mode;
* the Python API passes the caller's own callable straight through (or :func:`silent`).

Helpers compose them: :func:`scaled` maps a sub-job onto part of the range, so that a
function with two stages can hand ``scaled(progress, 0.0, 0.6)`` to the first::

    with ProgressBar("grid") as bar:
        ager = TextureAger(rgb, recipe, lights, progress=bar)

On a terminal the bar redraws one line with ``\\r``::

    grid [###############...............]  50%  simulating printed-paper: light mix 1/2
"""

from __future__ import annotations

import sys
import time

__all__ = ["ProgressBar", "silent", "scaled", "report", "console_after"]


def silent(fraction, message=""):
    """The do-nothing progress callable (the default of every ``progress=None``)."""


def report(progress):
    """``progress`` itself, or :func:`silent` when it is None."""
    return progress if progress is not None else silent


def scaled(progress, start, stop):
    """A progress callable reporting ``[0, 1]`` as ``[start, stop]`` of ``progress``.

    Parameters
    ----------
    progress : callable(fraction, message) or None
    start, stop : float
        The part of the outer job the inner one covers, fractions in [0, 1].

    Examples
    --------
    >>> seen = []
    >>> scaled(lambda f, m: seen.append((f, m)), 0.5, 1.0)(0.5, "half of the second half")
    >>> seen
    [(0.75, 'half of the second half')]
    """
    outer = report(progress)

    def inner(fraction, message=""):
        outer(start + (stop - start) * fraction, message)

    return inner


def console_after(progress, seconds=2.0, label="LightFade", stream=None, clock=time.perf_counter):
    """``progress`` that also prints one line per new message on the console (``stream``,
    default ``sys.stderr``) once ``seconds`` have passed since it was made — a job that
    turns out long says what it does, a quick one stays quiet — unless ``progress``
    prints lines itself (its ``prints`` attribute, as :class:`ProgressBar`'s).

    Examples
    --------
    >>> import io
    >>> out, now = io.StringIO(), [0.0]
    >>> say = console_after(None, 2.0, "Age", out, clock=lambda: now[0])
    >>> say(0.1, "table"); now[0] = 2.5; say(0.5, "group"); say(0.6, "group")
    >>> out.getvalue()
    'Age:  50%  group (2.5 s)\\n'
    """
    inner = report(progress)
    if getattr(progress, "prints", False):
        return inner
    start = clock()
    last = [None]

    def say(fraction, message=""):
        inner(fraction, message)
        elapsed = clock() - start
        if elapsed >= seconds and message != last[0]:
            out = stream if stream is not None else sys.stderr
            out.write(f"{label}: {min(max(float(fraction), 0.0), 1.0) * 100:3.0f}%  "
                      f"{message} ({elapsed:.1f} s)\n")
            out.flush()
            last[0] = message

    return say


class ProgressBar:
    """A ``progress(fraction, message)`` callable drawing on ``stream``.

    Parameters
    ----------
    label : str
        Printed before the bar.
    stream : file, optional
        Where to draw; default ``sys.stderr`` (looked up when drawing).
    width : int
        Characters of the bar itself.
    tty : bool, optional
        Force the redrawn bar (True) or plain lines (False); default: whether
        ``stream`` is a terminal.
    """

    #: It prints (:func:`console_after` adds no lines of its own).
    prints = True

    def __init__(self, label="", stream=None, width=30, tty=None):
        self.label = label
        self._stream = stream
        self.width = int(width)
        self._tty = tty
        self._last_message = None
        self._last_len = 0
        self._drawn = False
        self._start = time.perf_counter()

    @property
    def stream(self):
        return self._stream if self._stream is not None else sys.stderr

    @property
    def tty(self):
        if self._tty is not None:
            return self._tty
        try:
            return self.stream.isatty()
        except (AttributeError, ValueError):
            return False

    def __call__(self, fraction, message=""):
        """Report ``fraction`` in [0, 1] done, with what is being done."""
        try:
            fraction = float(fraction)
        except (TypeError, ValueError):
            fraction = 0.0
        fraction = min(max(fraction, 0.0), 1.0) if fraction == fraction else 0.0   # NaN: 0
        prefix = f"{self.label} " if self.label else ""
        if self.tty:
            filled = int(round(fraction * self.width))
            bar = "#" * filled + "." * (self.width - filled)
            line = f"{prefix}[{bar}] {fraction * 100:3.0f}%  {message}"
            pad = " " * max(0, self._last_len - len(line))
            self.stream.write("\r" + line + pad)
            self._last_len = len(line)
            self._drawn = True
            self.stream.flush()
        elif message != self._last_message:
            self.stream.write(f"{prefix}{fraction * 100:3.0f}%  {message}\n")
            self.stream.flush()
        self._last_message = message

    def close(self, message=None):
        """End the bar: a final newline on a terminal, and ``message`` if given."""
        if self.tty and self._drawn:
            self.stream.write("\n")
            self._drawn = False
        if message:
            self.stream.write(message + "\n")
        self.stream.flush()

    @property
    def elapsed(self):
        """Seconds since the bar was made."""
        return time.perf_counter() - self._start

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
