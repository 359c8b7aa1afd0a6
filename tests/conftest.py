"""Shared fixtures: the shipped models, paths, and a CLI runner."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest

from tests import _forkserver
from tests._xdist_modules import pytest_xdist_make_scheduler  # noqa: F401  (a hook: worksteal cuts between modules)

# A test run started with SIGINT ignored (a script's background job, ``make test &``: a shell
# without job control ignores SIGINT there) would hand the ignored Ctrl-C to every command the
# tests start, and a command leaves an ignored SIGINT ignored (taos.errors.run_cli). The tests
# that press Ctrl-C mean a command started from a terminal: this process takes Python's own
# handler, so what it starts gets SIGINT at its default. (The ignored case has its own test:
# tests/test_hostile_fuzz.py::test_a_background_jobs_ignored_ctrl_c_stays_ignored.)
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"


@pytest.fixture(scope="session")
def ambient():
    from taos.model import load_model
    return load_model(MODELS / "rs25_ambient.toml")


@pytest.fixture(scope="session")
def hotfire():
    from taos.model import load_model
    return load_model(MODELS / "rs25_hotfire.toml")


#: under ``make test``, the file its documentation build writes its exit status to (Makefile)
DOCS_STATUS_ENV = "TAOS_TEST_DOCS_STATUS"
DOCS_WAIT_S = 1800.0


def docs_build_succeeded() -> bool:
    """Under ``make test`` (:data:`DOCS_STATUS_ENV` set): whether its documentation build
    finished with exit status 0, waiting up to :data:`DOCS_WAIT_S` s for it to finish; False
    without that variable (``make check``, plain pytest)."""
    import os
    import time

    status = os.environ.get(DOCS_STATUS_ENV)
    if not status:
        return False
    status, t0 = Path(status), time.monotonic()
    while not status.is_file() and time.monotonic() - t0 < DOCS_WAIT_S:
        time.sleep(1.0)
    return status.is_file() and status.read_text().strip() == "0"


def run_cli(*args, prog="taos", cwd=ROOT, timeout=300):
    """Run the console script as a new process; returns ``subprocess.run``'s CompletedProcess
    (text; ``subprocess.TimeoutExpired`` after ``timeout`` s). A ``taos`` or ``masv`` command runs
    in a child forked from this test process's fork server (:mod:`tests._forkserver`: the imports
    paid once), which starts it as its new process would start; anything the fork server cannot
    reproduce exactly, and every command with ``TAOS_TEST_NO_FORKSERVER=1``, runs as a real
    process."""
    exe = Path(sys.executable).parent / prog
    return _forkserver.run([str(exe), *map(str, args)], cwd, timeout)


def pytest_sessionfinish(session, exitstatus):
    """The fork server ends with its test process (each xdist worker has its own)."""
    _forkserver.shutdown()


def inline_actuator_set(text: str, path: Path = MODELS / "rs25_ambient.toml") -> str:
    """Model-file text with its ``[actuator] parameter_set`` replaced by the set's keys, so a test
    can edit an actuator value in a copy (the shared set itself may not be overridden)."""
    import tomlkit

    from taos.identify.model_file import inline_actuator_parameter_set

    doc = tomlkit.parse(text)
    inline_actuator_parameter_set(doc, path, str(path))
    return tomlkit.dumps(doc)
