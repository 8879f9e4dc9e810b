"""A small terminal progress bar for long command-line steps.

An instance is a ``progress(fraction, message)`` callable, the signature the core's
long-running functions accept (:class:`.core.aging.TextureAger`,
:func:`.core.aging.age_image_exact`, :func:`.core.grid.load_or_build`)::

    with ProgressBar("fading") as bar:
        ager = TextureAger(rgb, recipe, lights, progress=bar)

On a terminal it redraws one line with ``\\r``::

    fading [##########..........]  50%  building the fading grid

Anywhere else (a pipe, a log file, a test) it writes a plain line each time the
message changes, so logs stay readable and free of control characters.
"""

from __future__ import annotations

import sys
import time

__all__ = ["ProgressBar"]


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
            fraction = min(max(float(fraction), 0.0), 1.0)
        except (TypeError, ValueError):
            fraction = 0.0
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
