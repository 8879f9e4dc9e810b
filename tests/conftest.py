"""Test-wide settings: a private grid cache so tests never touch the user's."""

import os
import tempfile

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
