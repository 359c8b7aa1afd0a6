"""The end of a ``taos``/``masv`` process: the interpreter's own exit, without tearing down the modules.

After ``sys.exit(status)`` CPython's ``Py_FinalizeEx`` (3.11: ``Python/pylifecycle.c``) does, in
this order: (1) ``threading._shutdown()`` (the ``threading._register_atexit`` hooks, e.g. the
thread pools' stop, then every non-daemon thread joined); (2) the :mod:`atexit` callbacks (Dask's
clusters closed, ``weakref.finalize`` objects such as temporary folders, logging flushed, the
meshcat server stopped); (3) ``sys.stdout`` and ``sys.stderr`` flushed (status 120 when that
fails); then (4) a garbage collection and the release of every module and object, which
changes nothing outside the process. Step 4 is the expensive one: with numpy, scipy, numba,
pint, h5py, casadi and matplotlib loaded it takes about 0.1 CPU-s, and in a forked process it
also copies every memory page whose objects it releases (``benchmarks/RESULTS.md``, "exit").

:func:`exit_process` does steps 1-3 as the interpreter does them, flushes the C library's
output buffers (what a C extension printed), and ends the process with ``os._exit(status)``.
Every file ``taos`` writes is closed before its command returns (``with`` blocks, written
beside the target and renamed), so nothing depends on step 4. When the flush of step 3 fails
(standard output a closed pipe), it gives up and raises ``SystemExit(status)``: the
interpreter then reports the failed flush and exits 120 as it always did.
"""

from __future__ import annotations

import os
import sys
from typing import NoReturn


def exit_process(status: int) -> NoReturn:
    """End the process with exit status ``status`` (int, 0-255) as ``sys.exit(status)`` would,
    skipping only the interpreter's release of its modules and objects (see the module
    docstring). Called from a thread other than the main thread, or with the interpreter
    already finalising, it is ``sys.exit(status)``."""
    import atexit
    import threading

    if threading.current_thread() is not threading.main_thread() or sys.is_finalizing():
        raise SystemExit(status)
    shutdown = getattr(threading, "_shutdown", None)   # what Py_FinalizeEx calls first
    if shutdown is not None:
        shutdown()
    atexit._run_exitfuncs()   # runs and clears the callbacks: the fallback below does not repeat them
    try:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
    except Exception:   # the interpreter's exit reports it and exits 120
        raise SystemExit(status) from None
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)   # C stdio buffers: os._exit does not flush them
    except Exception:  # pragma: no cover - no C library to ask (not on Linux/macOS)
        pass
    os._exit(status)
