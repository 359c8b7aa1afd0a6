"""A pytest plugin: CPU seconds of each test (setup + call + teardown) in its own process and the
children it waited for, with its wall start and end (Unix time), one line a test to
``$TAOS_TEST_CPU_DIR/cpu-<pid>.tsv``.

Where `make test`'s CPU goes, test by test, in the run as it is (two xdist workers beside the
docs build); wall durations there are inflated by whatever the other core does, CPU is not:

    TAOS_TEST_CPU_DIR=/tmp/cpu make test PYTEST="PYTHONDONTWRITEBYTECODE= .venv/bin/python -m pytest \
        -q -p no:cacheprovider -p benchmarks.pytest_cpu"
    cat /tmp/cpu/cpu-*.tsv | sort -t$'\\t' -k2 -rn | head -40

A child that is never waited for (a killed process's orphan, a Dask worker of a cluster left to
another test) is not counted."""

from __future__ import annotations

import os
import resource
import time
from pathlib import Path

import pytest


def _cpu_s() -> float:
    """This process's CPU, its waited-for children's, and the commands the test suite's fork
    server (``tests/_forkserver.py``) ran for it (waited for by the fork server)."""
    import sys

    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    fs = sys.modules.get("tests._forkserver")
    forked = fs.STATS.get("child_cpu_s", 0.0) if fs is not None else 0.0
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime + forked


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    out = os.environ.get("TAOS_TEST_CPU_DIR")
    t0, w0 = _cpu_s(), time.time()
    yield
    if out:
        Path(out).mkdir(parents=True, exist_ok=True)
        with open(Path(out) / f"cpu-{os.getpid()}.tsv", "a") as f:
            f.write(f"{item.nodeid}\t{_cpu_s() - t0:.3f}\t{w0:.2f}\t{time.time():.2f}\n")


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session):
    """The session's own CPU outside the tests (collection, start-up): one line ``<session>``."""
    out = os.environ.get("TAOS_TEST_CPU_DIR")
    if out and Path(out).is_dir():
        with open(Path(out) / f"cpu-{os.getpid()}.tsv", "a") as f:
            f.write(f"<session {os.getpid()}>\t{_cpu_s():.3f}\n")
