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

import atexit
import os
import shutil
import sys

from .parser import add_subcommands, check, make_parser

__all__ = ["add_subcommands", "main", "run", "run_program"]

#: The add-on package (``lightfade_addon`` or ``bl_ext.<repo>.lightfade``).
_PACKAGE = __package__.rpartition(".")[0]


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


def _old_bpy_module():
    bpy = sys.modules.get("bpy")
    return bpy is not None and not bpy.app.binary_path and bpy.app.version < (5, 0, 0)


def _exit_now(status):
    import bpy

    sys.stdout.flush()
    sys.stderr.flush()
    if os.path.basename(os.path.normpath(bpy.app.tempdir)).startswith("blender_"):
        shutil.rmtree(bpy.app.tempdir, ignore_errors=True)   # what Blender's exit removes
    os._exit(status)


def run_program(args):
    """:func:`run` for ``python -m lightfade_addon scene``: the process's exit status.

    The bpy module of Blender 4.x (seen with 4.2.23, not with 5.2) segfaults at
    interpreter exit once the add-on is registered, which would turn every status into
    139; when this process is ``python -m`` of the add-on and runs on such a module, it
    ends right after the interpreter's exit handlers with the command's status.
    """
    status = run(args)
    main_spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    if _old_bpy_module() and main_spec is not None and main_spec.name == f"{_PACKAGE}.__main__":
        atexit.register(_exit_now, status)
    return status
