"""Dask scheduler and worker processes for the cluster tests, forked by the test suite's fork
server (:mod:`tests._forkserver`) when it can, as ``dask scheduler ARGS`` / ``dask worker ARGS``.

``dask scheduler`` and ``dask worker`` are ``distributed.cli.dask_scheduler:main`` and
``distributed.cli.dask_worker:main`` (the ``dask_cli`` entry points the ``dask`` script loads).
Here each runs as ``python -c CODE KIND ENV ARGS``: through :func:`tests._forkserver.popen`, a
child of the zygote, which has numpy, scipy, numba and taos's command modules imported already
(a worker's first batch otherwise pays them, ~1-1.5 CPU-s a process), or a real process when the
fork server cannot run it (:func:`tests._forkserver.eligible`). Either way the process is a
separate one with its own pid, sockets and signals: the tests kill it (SIGKILL) or stop it
(SIGTERM) as they would the ``dask`` command's process. Its standard output and error go to
``/dev/null`` (as the tests had them), ``ENV`` (JSON) is set in its environment before
Dask is imported, and it runs in the folder it is given. :func:`communicate` is
``Popen.communicate`` for either kind of process (the tests that read a command's output)."""

from __future__ import annotations

import json
import os
import sys

from tests import _forkserver

_CODE = """
import json, os, sys
_null = os.open(os.devnull, os.O_WRONLY)
os.dup2(_null, 1)
os.dup2(_null, 2)
os.close(_null)
_kind, _env = sys.argv[1], json.loads(sys.argv[2])
os.environ.update(_env)
sys.argv = ["dask " + _kind, *sys.argv[3:]]
if _kind == "worker":
    from distributed.cli.dask_worker import main
else:
    from distributed.cli.dask_scheduler import main
main()
"""


def start(kind: str, args: list[str], cwd=None, env: dict[str, str] | None = None):
    """``dask KIND ARGS`` (``kind`` ``"scheduler"`` or ``"worker"``) started in ``cwd`` (this
    process's folder by default) with ``env`` added to the environment: a process object with
    ``pid``, ``poll``, ``wait`` (a timeout raising ``subprocess.TimeoutExpired``),
    ``send_signal`` and ``kill`` (:class:`tests._forkserver.Child` or ``subprocess.Popen``).
    Keep a reference while it should run: a forked child whose object is collected is killed."""
    if kind not in ("scheduler", "worker"):
        raise ValueError(kind)
    argv = [sys.executable, "-c", _CODE, kind, json.dumps(env or {}), *map(str, args)]
    return _forkserver.popen(argv, os.fspath(cwd) if cwd is not None else os.getcwd())


def communicate(p, timeout: float) -> tuple[str, str]:
    """``p.communicate(timeout=timeout)`` for a ``subprocess.Popen`` or a
    :class:`tests._forkserver.Child` (text pipes): both streams read to their end, the process
    waited for; ``subprocess.TimeoutExpired`` (the process killed) if that takes longer."""
    import subprocess
    import threading
    import time

    if isinstance(p, subprocess.Popen):
        return p.communicate(timeout=timeout)
    got: dict[str, str] = {}
    readers = [threading.Thread(target=lambda k=k: got.setdefault(k, getattr(p, k).read()), daemon=True)
               for k in ("stdout", "stderr")]
    for th in readers:
        th.start()
    deadline = time.monotonic() + timeout
    for th in readers:
        th.join(max(deadline - time.monotonic(), 0.0))
    if any(th.is_alive() for th in readers):
        p.kill()
        p.wait()
        raise subprocess.TimeoutExpired(p.args, timeout)
    p.wait(timeout=max(deadline - time.monotonic(), 5.0))   # (its pipes closed: it is ending)
    p.stdout.close()
    p.stderr.close()
    return got["stdout"], got["stderr"]


def wait_stored(count, status_dir, n: int, running=lambda: True, timeout_s: float = 240.0,
                poll_s: float = 0.05, recount_s: float = 1.0) -> int:
    """Until ``count()`` (the runs or points a store holds) reaches ``n``, ``running()`` turns
    false or ``timeout_s`` s pass; returns the last count. Polled every ``poll_s`` s, as the
    tests did, but ``count()`` (opening the store: ~10 ms of CPU) is called only when the
    modification time of ``status_dir`` (the store's ``status`` array folder: every batch write
    replaces its chunk file there, Zarr's atomic rename) changed, or ``recount_s`` s after the
    last count (a change within one tick of the file system's clock)."""
    import time

    deadline = time.monotonic() + timeout_s
    seen, last_t, done = None, -float("inf"), 0
    while True:
        try:
            stamp = os.stat(status_dir).st_mtime_ns
        except OSError:
            stamp = None
        now = time.monotonic()
        if stamp != seen or now - last_t >= recount_s:
            seen, last_t, done = stamp, now, count()
        if done >= n or not running() or now > deadline:
            return done
        time.sleep(poll_s)
