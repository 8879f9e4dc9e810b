"""The ``lightfade`` command line: ``python -m lightfade_addon <command> ...``.

Commands are small functions registered in :data:`COMMANDS`; each gets the parsed
arguments and returns an exit status. Errors a user can fix are printed as one
line on stderr with exit status 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import sys

from . import __version__

COMMANDS = {}


def command(name, help):
    """Register ``fn(parser)`` as the argument builder of command ``name``."""

    def wrap(build):
        COMMANDS[name] = (help, build)
        return build

    return wrap


class UserError(Exception):
    """A problem with the user's input: reported as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``lightfade: error: ...`` and exit status 2."""

    def error(self, message):
        self.exit(2, f"lightfade: error: {message} (see: {self.prog} --help)\n")


def make_parser():
    parser = _Parser(
        prog="python -m lightfade_addon",
        description="LightFade: physically based light fading and yellowing (layered "
                    "Kubelka-Munk model).")
    parser.add_argument("--version", action="version", version=f"lightfade {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, (help_text, build) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        build(p)
    return parser


def main(argv=None):
    """Entry point; returns the exit status."""
    from . import commands  # noqa: F401  (registers the commands)

    parser = make_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    try:
        return args.run(args) or 0
    except UserError as exc:
        print(f"lightfade: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("lightfade: interrupted", file=sys.stderr)
        return 130
