"""Running one sub-command over several files: progress, summary table, exit status.

Each file is opened, processed and written on its own; a file that is refused (missing,
unreadable, nothing to age, no camera ...) or fails is named in the summary and the
next file still runs.  Exit status: 0 when every file is done, 1 when any was refused
or failed, 2 for a usage error (before any file is touched).
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
import traceback

import bpy

from ..output import plural
from .steps import ACTIONS, check_overrides, dump_json
from .files import Refused, write_text
from .farm import ACTIONS as FARM_ACTIONS

#: The add-on package these modules belong to (``lightfade_addon`` or ``bl_ext.<repo>.lightfade``).
ADDON_PACKAGE = __package__.rpartition(".")[0]


def ensure_registered():
    """Enable the add-on if its properties are not registered (``python -m`` with bpy)."""
    if hasattr(bpy.types.Scene, "lightfade"):
        return
    import addon_utils

    addon_utils.enable(ADDON_PACKAGE, default_set=False)
    if not hasattr(bpy.types.Scene, "lightfade"):
        raise Refused(f"could not enable the add-on '{ADDON_PACKAGE}' (see the messages above)")


@contextlib.contextmanager
def stdout_to_stderr():
    """Send what is written to stdout meanwhile (Blender's C code too) to stderr."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def _row(path, status, seconds, result):
    return {"file": path, "status": status, "seconds": seconds, "result": result}


def _one(action, path, args, k, n):
    def say(msg):
        print(f"lightfade [{k}/{n}] {os.path.basename(path)}: {msg}", flush=True)

    say("start")
    t0 = time.perf_counter()
    try:
        result = action(path, args, say)
        status = "done"
    except Refused as err:
        status, result = "refused", str(err)
    except Exception as err:  # noqa: BLE001 (one broken file must not stop the batch)
        traceback.print_exc()
        status, result = "failed", f"{type(err).__name__}: {str(err).strip().splitlines()[0]}"
    seconds = time.perf_counter() - t0
    if status == "done":
        say(f"done in {seconds:.1f} s: {result}")
    else:
        print(f"lightfade: {path}: {result}", file=sys.stderr, flush=True)
    return _row(path, status, seconds, result)


def summary(action, rows):
    """The table printed at the end of a run."""
    counts = {s: sum(r["status"] == s for r in rows) for s in ("done", "refused", "failed")}
    head = ", ".join(f"{v} {k}" for k, v in counts.items() if v)
    width = max(len(r["file"]) for r in rows)
    lines = [f"lightfade {action}: {plural(len(rows), 'file')}: {head}",
             f"  {'status':8} {'seconds':>8}  {'file':{width}}  result"]
    for r in rows:
        lines.append(f"  {r['status']:8} {r['seconds']:8.1f}  {r['file']:{width}}  {r['result']}")
    return "\n".join(lines)


def _run_files(args):
    action = {**ACTIONS, **FARM_ACTIONS}[args.action]
    rows = [_one(action, path, args, k, len(args.files)) for k, path in enumerate(args.files, 1)]
    print(summary(args.action, rows), flush=True)
    return rows


def _run_checked(args):
    try:
        ensure_registered()
    except Refused as err:
        print(f"lightfade: {err}", file=sys.stderr)
        return 1, []
    problem = check_overrides(args, bpy.context.scene)
    if problem is not None:
        print(f"lightfade: error: {problem}", file=sys.stderr)
        return 2, []
    rows = _run_files(args)
    return (0 if all(r["status"] == "done" for r in rows) else 1), rows


def _json_document(args, rows):
    reports = iter(args.json_reports)
    return dump_json([next(reports) if r["status"] == "done"
                      else {"file": os.path.abspath(r["file"]), "error": r["result"]}
                      for r in rows]) + "\n"


def run(args):
    """Run ``args.action`` on every file of ``args.files``; returns the exit status.

    With ``info --json`` stdout carries the JSON document only: everything else
    (Blender's messages too) goes to stderr.  With ``info --json FILE`` the document is
    written to FILE (safely) and the run prints as usual.
    """
    if not (args.action == "info" and args.json):
        return _run_checked(args)[0]
    args.json_reports = []
    if args.json != "-":
        status, rows = _run_checked(args)
        if status != 2:
            try:
                write_text(os.path.abspath(args.json), _json_document(args, rows))
            except Refused as err:
                print(f"lightfade: {err}", file=sys.stderr)
                return 1
        return status
    with stdout_to_stderr():
        status, rows = _run_checked(args)
    if status != 2:
        sys.stdout.write(_json_document(args, rows))
        sys.stdout.flush()
    return status
