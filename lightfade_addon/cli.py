"""The ``lightfade`` command line: ``python -m lightfade_addon <command> ...``.

The parser is built from the command modules of :mod:`.commands` (one module per
command, see there); each gets the parsed arguments and returns an exit status.
Errors a user can fix, in the command line or in the input files, are printed as one
line on stderr with exit status 2, never as a traceback.
"""

from __future__ import annotations

import sys

from . import __version__
from .commands import ArgumentParser, UserError, discover


def make_parser(prog=None):
    """The argument parser of every command; ``prog`` defaults to argparse's choice."""
    parser = ArgumentParser(
        prog=prog,
        description="LightFade: physically based light fading and yellowing (layered "
                    "Kubelka-Munk model).")
    parser.add_argument("--version", action="version", version=f"lightfade {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=ArgumentParser)
    for module in discover():
        p = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        p.set_defaults(run=module.run)
    return parser


def main(argv=None, prog=None):
    """Entry point; returns the exit status (0, 2 for usage or input errors, 130).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name (default: ``sys.argv[1:]``).
    prog : str, optional
        The program name shown in usage lines.
    """
    parser = make_parser(prog)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:           # --help, --version, or a usage error (status 2)
        return exc.code if isinstance(exc.code, int) else 2
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
