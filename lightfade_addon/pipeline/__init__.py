"""Scene commands for pipelines: bake, age, render and describe .blend files.

Two entry points run the very same code (:func:`main`):

* ``blender -c lightfade <sub-command> ...`` — the command the extension registers with
  ``bpy.utils.register_cli_command`` (:mod:`..blender.cli_command`, Blender 4.2+);
* ``python -m lightfade_addon scene <sub-command> ...`` — with the ``bpy`` module and no
  Blender binary (:mod:`..commands.scene`).

Sub-commands: ``bake``, ``age``, ``render-years`` and ``info`` (:mod:`.parser`), each on
one or more files (:mod:`.batch`), written safely (:mod:`.files`).  See
``docs/pipeline.md``.  Importing this package does not import ``bpy``.
"""

from __future__ import annotations

import sys

from .parser import add_subcommands, check, make_parser

__all__ = ["add_subcommands", "main", "run"]


def run(args):
    """Run parsed arguments; returns the exit status (0 done, 1 refused, 2 usage)."""
    problem = check(args)
    if problem is not None:
        print(f"lightfade: error: {problem}", file=sys.stderr)
        return 2
    try:
        from . import batch
    except ImportError as err:
        print(f"lightfade: the scene commands need Blender's bpy module ({err}): run them "
              "with 'blender -c lightfade ...' or install bpy", file=sys.stderr)
        return 1
    return batch.run(args)


def main(argv, prog="blender -c lightfade"):
    """Parse ``argv`` (the arguments after the command name) and run; returns the exit
    status (0 done, 1 refused, 2 usage)."""
    parser = make_parser(prog)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0) or a usage error (2)
        return exc.code if isinstance(exc.code, int) else 2
    return run(args)
