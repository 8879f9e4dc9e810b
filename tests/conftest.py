"""Test-wide settings: a private grid cache so tests never touch the user's, the
outcome record that ``./run test-oldest`` reads (see ``run``), and early jobs: real
processes that start when collection ends and run beside the tests before them."""

import errno
import os
import shutil
import subprocess
import sys
import tempfile
import threading
from concurrent.futures import Future
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
_EARLY = pytest.StashKey()


def _spawn(args, kwargs, tries=3):
    """``Popen`` with pipes, tried again when the exec fails with EFAULT.

    These processes start from a thread while the main thread runs Blender, which maps
    and unmaps large buffers; a vfork child shares the parent's memory until it execs, so
    an unmapping meanwhile can fail the exec with "[Errno 14] Bad address" (seen once in
    CI). Plain fork avoids it but runs OpenBLAS's fork handler, which stops its threads
    under a solve in progress on another thread (a hang, seen on the oldest stack)."""
    for attempt in range(tries):
        try:
            return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    text=True, **kwargs)
        except OSError as exc:
            if exc.errno != errno.EFAULT or attempt == tries - 1:
                raise


class EarlyJobs:
    """Jobs that only run real processes, started when collection ends.

    A test module declares ``EARLY = {name: job}``; ``job(jobs, folder)`` runs its
    processes with :meth:`run` in an empty temporary ``folder`` and returns what its
    tests check.  A test gets that with the ``early`` fixture: ``early(name)`` waits for
    the job (starting it then if it was not).  The jobs run one after the other in one
    background thread, beside the tests before theirs (the second core); the thread
    ends when no job is left (no idle thread lingers while tests fork).  The jobs are
    not started when no selected test asks for them, and a process still running at
    the end of the session is killed.
    """

    def __init__(self):
        self._futures, self._queue, self._procs, self._folders = {}, [], [], []
        self._lock = threading.Lock()
        self._thread = None
        self._stopping = False

    def start(self, name, job, soon=False):
        """Queue ``job`` (once per ``name``); ``soon``: ahead of the queued jobs (a fixture's
        job, which a test of the running module waits for, before jobs of later modules)."""
        with self._lock:
            if name not in self._futures:
                folder = Path(tempfile.mkdtemp(prefix="lightfade-early-"))
                self._folders.append(folder)
                self._futures[name] = future = Future()
                self._queue.insert(0 if soon else len(self._queue), (future, job, folder))
                if self._thread is None:
                    self._thread = threading.Thread(target=self._work, name="early-jobs")
                    self._thread.start()
            return self._futures[name]

    def _work(self):
        while True:
            with self._lock:
                if not self._queue:
                    self._thread = None
                    return
                future, job, folder = self._queue.pop(0)
            if future.set_running_or_notify_cancel():
                try:
                    future.set_result(job(self, folder))
                except BaseException as exc:  # noqa: BLE001 (the test reports it)
                    future.set_exception(exc)

    def result(self, name, job):
        return self.start(name, job).result()

    def run(self, args, timeout=900, **kwargs):
        """``subprocess.run(args, capture_output=True, text=True, **kwargs)``."""
        with self._lock:
            if self._stopping:
                raise RuntimeError("the session is over")
            proc = _spawn(args, kwargs)
            self._procs.append(proc)
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            raise AssertionError(f"{args[:3]}... took over {timeout} s:\n{out[-2000:]}"
                                 f"\n{err[-2000:]}") from None
        return subprocess.CompletedProcess(args, proc.returncode, out, err)

    def stop(self):
        with self._lock:
            self._stopping = True
            thread = self._thread
            for future, _job, _folder in self._queue:
                future.cancel()
            self._queue.clear()
            for proc in self._procs:
                if proc.poll() is None:
                    proc.kill()
        if thread is not None:
            thread.join()
        for folder in self._folders:
            shutil.rmtree(folder, ignore_errors=True)


def _early_jobs(item):
    if "early" not in getattr(item, "fixturenames", ()):
        return {}
    return getattr(getattr(item, "module", None), "EARLY", {})


def pytest_collection_finish(session):
    jobs = session.config.stash.setdefault(_EARLY, EarlyJobs())
    if session.config.option.collectonly:
        return
    for item in session.items:
        for name, job in _early_jobs(item).items():
            jobs.start(name, job)


@pytest.fixture
def early(request):
    """``early(name)``: the result of the module's early job ``name`` (see EarlyJobs)."""
    jobs = request.config.stash.setdefault(_EARLY, EarlyJobs())
    return lambda name: jobs.result(name, request.module.EARLY[name])


@pytest.fixture(scope="session")
def early_jobs(request):
    """The :class:`EarlyJobs`, for fixtures that start a job once its inputs exist."""
    return request.config.stash.setdefault(_EARLY, EarlyJobs())


def pytest_sessionfinish(session):
    jobs = session.config.stash.get(_EARLY, None)
    if jobs is not None:
        jobs.stop()


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
