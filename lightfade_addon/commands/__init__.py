"""The command line's commands: one module each, found by :func:`discover`.

A command is a module in this package that defines

``NAME``
    the sub-command, e.g. ``"age-image"``;
``HELP``
    one line for ``--help``;
``add_arguments(parser)``
    adds its arguments to an ``argparse`` sub-parser, validating with ``type=`` and
    ``choices=`` (see :func:`number` for bounded numbers);
``run(args) -> int``
    does the work and returns the exit status; it raises :class:`UserError` for a
    problem the user can fix (reported as one line, exit status 2).

Adding a command is adding one such file: :mod:`..cli` lists the package and builds
the parser from what it finds. Commands import nothing from :mod:`..cli`, so the
imports run one way, ``cli -> commands -> core``.
"""

from __future__ import annotations

import argparse
import importlib
import math
import pkgutil

__all__ = ["UserError", "ArgumentParser", "discover", "number"]


class UserError(Exception):
    """A problem with the user's input: reported as one line, exit status 2."""


class ArgumentParser(argparse.ArgumentParser):
    """argparse with one-line errors: ``lightfade: error: ...`` and exit status 2."""

    def error(self, message):
        self.exit(2, f"lightfade: error: {message} (see: {self.prog} --help)\n")


def discover():
    """The command modules of this package, sorted by ``NAME``."""
    modules = [importlib.import_module(f"{__name__}.{info.name}")
               for info in pkgutil.iter_modules(__path__) if not info.name.startswith("_")]
    return sorted((m for m in modules if hasattr(m, "NAME")), key=lambda m: m.NAME)


def number(unit, low=0.0, high=math.inf):
    """An argparse ``type=``: a finite float in ``[low, high]``, in ``unit``.

    Examples
    --------
    >>> number("hours", 0, 24)("8")
    8.0
    """

    def parse(text):
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a number in {unit}, got {text!r}")
        if not math.isfinite(value) or not low <= value <= high:
            bound = f"between {low:g} and {high:g}" if math.isfinite(high) else f">= {low:g}"
            raise argparse.ArgumentTypeError(
                f"must be a finite number {bound} {unit}, got {text!r}")
        return value

    parse.__name__ = unit        # argparse names the type in some messages
    return parse
