"""Command-line commands; importing this package registers them with :mod:`..cli`."""

from . import info  # noqa: F401
