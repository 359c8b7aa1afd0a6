"""Independent runs on every core, with the numbers of a serial run.

The Green Run's short runs (the two axes of the planar run, the step figures' runs, ...) are
independent: each is one call of a compiled kernel that runs without the GIL
(:func:`taos.planar.dynamics.integrate_samples`), on arrays of its own. Threads of one process
run them at the same time, and each computes exactly what it computes alone (no shared state,
no sum across runs, the same compiled code), so the results are the same bits on any number of
threads and in any order of completion.

:func:`run_tasks` calls a list of such tasks and returns their results in task order. With one
thread it calls them one after the other in this thread, as the serial code did (the identity
tests compare the two); with more, every task runs to its end and the first failure IN TASK
ORDER is raised, the one the serial run raises (a later task's failure, which the serial run
never reaches, is dropped; the tasks not yet started are cancelled, the running ones end
first). Nothing is returned, hence nothing written, when any task fails. An interrupt
(Ctrl-C) is raised at once; the runs still going on end on their own (a compiled call cannot be
stopped), and no further task starts, in this pool or in any pool its tasks opened (one cancel
flag per outermost call, seen by the nested calls through a context variable).

The thread count: ``threads`` given, else numba's (``NUMBA_NUM_THREADS``, default the number of
cores), so ``NUMBA_NUM_THREADS=1`` makes every command serial. Only kernels that are not
``parallel=True`` go to the threads: numba's default (workqueue) threading layer does not
allow two parallel kernels to start at once. The package has no ``parallel=True`` kernel: a
batch of independent dwells is a serial ``nogil`` kernel over a range of dwells, called once
per dwell on the threads (:func:`run_each`), which also spares numba's parallel lowering at
compile time.
"""

from __future__ import annotations

import contextvars
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, Sequence, TypeVar

T = TypeVar("T")

#: the cancel flag of the outermost :func:`run_tasks` call (None outside any), set on an interrupt
_CANCEL: contextvars.ContextVar[threading.Event | None] = contextvars.ContextVar("taos_run_cancel", default=None)


class _Cancelled(Exception):
    """A task not started because its run was interrupted (never reaches the caller)."""


def _start(cancel: threading.Event, task: Callable[[], T]) -> T:
    if cancel.is_set():
        raise _Cancelled()
    return task()

#: more threads than this is refused (a typo, not a machine)
MAX_THREADS = 256


def thread_count(threads: int | None = None) -> int:
    """``threads`` (1 to :data:`MAX_THREADS`), or numba's thread count when None."""
    if threads is None:
        import sys

        if "numba" in sys.modules:
            import numba

            return max(1, int(numba.get_num_threads()))
        return _numba_default_threads()
    if isinstance(threads, bool) or not isinstance(threads, int) or not 1 <= threads <= MAX_THREADS:
        from ..errors import InputError

        raise InputError("argument", "threads", f"an integer from 1 to {MAX_THREADS}", got=repr(threads))
    return threads


def _numba_default_threads() -> int:
    """numba's thread count without importing numba (a dwell command on the C path,
    :mod:`taos.planar._cdwell`): ``NUMBA_NUM_THREADS``, else the cores this process may run on
    (numba's own default, ``numba.core.config``)."""
    import os

    env = os.environ.get("NUMBA_NUM_THREADS", "").strip()
    if env:
        return max(1, int(env))
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def run_tasks(tasks: Sequence[Callable[[], T]], threads: int | None = None,
              done: Callable[[int], None] | None = None, start_order: Sequence[int] | None = None) -> list[T]:
    """Results of ``tasks`` (functions of no arguments) in task order, on ``threads`` threads
    (:func:`thread_count`; module docstring). ``done(i)`` is called in this thread as the
    results are collected, in task order (a progress bar's update). ``start_order``: the order
    in which the threads take the tasks (the longest first balances the threads; default task
    order); the results and the failure raised stay in task order."""
    tasks = list(tasks)
    n = min(thread_count(threads), len(tasks))
    if n <= 1:   # (inside an interrupted pool's task: stop before the next run)
        cancel, out = _CANCEL.get(), []
        for i, task in enumerate(tasks):
            out.append(task() if cancel is None else _start(cancel, task))
            if done is not None:
                done(i)
        return out
    cancel = _CANCEL.get()
    token = _CANCEL.set(threading.Event()) if cancel is None else None
    cancel = _CANCEL.get()
    ex = ThreadPoolExecutor(max_workers=n, thread_name_prefix="taos-run")
    try:
        order = range(len(tasks)) if start_order is None else start_order
        if sorted(order) != list(range(len(tasks))):
            raise ValueError(f"start_order {list(order)} is not a permutation of the {len(tasks)} tasks")
        submitted = {i: ex.submit(contextvars.copy_context().run, _start, cancel, tasks[i]) for i in order}
        futures = [submitted[i] for i in range(len(tasks))]
        out = []
        for i, f in enumerate(futures):   # in task order: the first failure is the serial run's
            out.append(f.result())
            if done is not None:
                done(i)
    except BaseException as e:
        # the tasks not started are dropped; the running ones end (short compiled calls) before
        # the failure is raised, except on an interrupt, which is raised at once
        if isinstance(e, KeyboardInterrupt):
            cancel.set()
        ex.shutdown(wait=not isinstance(e, KeyboardInterrupt), cancel_futures=True)
        raise
    finally:
        if token is not None:
            _CANCEL.reset(token)
    ex.shutdown(wait=True)
    return out


def run_each(call: Callable[[int], object], cost: Sequence[float], threads: int | None = None) -> None:
    """``call(b)`` for every b in ``range(len(cost))`` (a kernel computing item b of a batch into
    arrays of its own, e.g. ``status[b]``, ``out[b]``: nothing returned), on ``threads`` threads
    by :func:`run_tasks` (failures and interrupts as there). The threads take the items costliest
    first (``cost`` in any unit, e.g. steps; ties in item order), one at a time, so that the
    long items do not end up on one thread; one thread calls them in item order."""
    n = len(cost)
    order = sorted(range(n), key=lambda b: -float(cost[b]))
    run_tasks([lambda b=b: call(b) for b in range(n)], threads, start_order=order)
