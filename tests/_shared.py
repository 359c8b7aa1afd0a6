"""A module-scoped result made once per test session, even when pytest-xdist splits its module
over both workers.

tests/_xdist_modules.py keeps a module on one worker where the queue allows it; at the end of
the run, when one module is all that is left, xdist splits it anyway (a split module beats an
idle core), and each worker then builds the module's fixtures itself: tests/test_reduce.py's
reduction (about 30 CPU-s) was made twice in `make test` that way. :func:`shared_dir` lets the
first worker build it into a directory both workers see (the parent of the workers' base
temporary directories, one per session) under an exclusive ``flock``; the other waits on the
lock (no CPU) and reads what was written. Without xdist the directory is the session's own base
temporary directory. A build that fails leaves no completion mark, so the next caller builds
again (and fails the same way, in its own test)."""

from __future__ import annotations

import fcntl
import os
from collections.abc import Callable
from pathlib import Path

import pytest

#: the file a finished build leaves in its directory
DONE = ".done"


def shared_dir(tmp_path_factory: pytest.TempPathFactory, name: str, build: Callable[[Path], None]) -> Path:
    """The directory ``name`` under the session's shared temporary root, ``build(dir)`` run on it
    by the first caller of the session (any xdist worker) and never again."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    d = root / f"shared-{name}"
    with open(root / f"shared-{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            if not (d / DONE).is_file():
                d.mkdir(exist_ok=True)
                build(d)
                (d / DONE).write_text("")
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
    return d
