"""tests/conftest.py records pytest's exit status for ``./run test-oldest`` (see ``run``).

Three real pytest runs, as an early job (tests/conftest.py): they run beside the tests
before these.
"""

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: What each run selects, and the status it must record.
SELECTIONS = {
    "passed": (["tests/test_package.py", "-k", "test_core_never_imports_blender_modules"], "0"),
    "nothing collected": (["tests/test_package.py", "-k", "no_test_has_this_name"], "5"),
}
FAILING_TEST = "def test_fails():\n    assert False\n"


def _record(jobs, folder, name, *args):
    out = folder / f"outcome-{name.replace(' ', '-')}"
    proc = jobs.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args],
                    cwd=ROOT, env=dict(os.environ, LIGHTFADE_PYTEST_OUTCOME=str(out)), timeout=300)
    return proc.returncode, out.read_text().strip() if out.exists() else None


def record_outcomes(jobs, folder):
    """``{run: (exit code, recorded status)}`` of the three runs."""
    results = {name: _record(jobs, folder, name, *args) for name, (args, _) in SELECTIONS.items()}
    failing = folder / "test_fails.py"
    failing.write_text(FAILING_TEST)
    results["failed"] = _record(jobs, folder, "failed", "--rootdir", str(ROOT),
                                "-c", str(ROOT / "pyproject.toml"), "--confcutdir", str(ROOT),
                                "-p", "tests.conftest", str(failing))
    return results


EARLY = {"outcomes": record_outcomes}


@pytest.mark.parametrize("name", sorted(SELECTIONS))
def test_exit_status_is_recorded(early, name):
    code, recorded = early("outcomes")[name]
    status = SELECTIONS[name][1]
    assert recorded == status and code == int(status)


def test_failure_is_recorded(early):
    assert early("outcomes")["failed"] == (1, "1")
