"""tests/conftest.py records pytest's exit status for ``./run test-oldest`` (see ``run``)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _record(tmp_path, *args):
    out = tmp_path / "outcome"
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args],
        cwd=ROOT, env=dict(os.environ, LIGHTFADE_PYTEST_OUTCOME=str(out)), capture_output=True, text=True,
    )
    return proc.returncode, out.read_text().strip() if out.exists() else None


@pytest.mark.parametrize("select, status", [
    ("test_core_never_imports_blender_modules", "0"),          # passed
    ("no_test_has_this_name", "5"),                            # nothing collected
])
def test_exit_status_is_recorded(tmp_path, select, status):
    code, recorded = _record(tmp_path, "tests/test_package.py", "-k", select)
    assert recorded == status and code == int(status)


def test_failure_is_recorded(tmp_path):
    failing = tmp_path / "test_fails.py"
    failing.write_text("def test_fails():\n    assert False\n")
    code, recorded = _record(tmp_path, "--rootdir", str(ROOT), "-c", str(ROOT / "pyproject.toml"),
                             "--confcutdir", str(ROOT), "-p", "tests.conftest", str(failing))
    assert (code, recorded) == (1, "1")
