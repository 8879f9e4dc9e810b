"""Test-wide settings: a private grid cache so tests never touch the user's, and the
outcome record that ``./run test-oldest`` reads (see ``run``)."""

import os
import sys
import tempfile
from pathlib import Path

import pytest


@pytest.fixture(scope="session", autouse=True)
def private_grid_cache():
    with tempfile.TemporaryDirectory(prefix="lightfade-test-cache-") as d:
        old = os.environ.get("LIGHTFADE_CACHE")
        os.environ["LIGHTFADE_CACHE"] = d
        yield d
        if old is None:
            os.environ.pop("LIGHTFADE_CACHE", None)
        else:
            os.environ["LIGHTFADE_CACHE"] = old


#: The running session, kept for :func:`pytest_unconfigure` (which gets only the config).
_SESSION = pytest.StashKey()


def pytest_sessionstart(session):
    session.config.stash[_SESSION] = session


def pytest_unconfigure(config):
    """Write pytest's exit status to ``$LIGHTFADE_PYTEST_OUTCOME`` once everything is printed.

    The bpy 4.2 module segfaults at interpreter exit (after this hook) once a PropertyGroup
    with an ``update=`` callback was registered, so ``./run test-oldest`` decides pass/fail
    from this record rather than from the process's exit code.
    """
    path = os.environ.get("LIGHTFADE_PYTEST_OUTCOME")
    session = config.stash.get(_SESSION, None)
    sys.stdout.flush()
    sys.stderr.flush()
    if path and session is not None:
        Path(path).write_text(f"{int(session.exitstatus)}\n")
