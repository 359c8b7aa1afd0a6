"""The campaign engine: a list of parameter sets (a :class:`Design`) and a run function (a
:class:`RunKind`), run in batches on Dask and stored as they arrive.

* **Inputs by value.** The run kind carries its parsed inputs (models, tables: no file path a
  worker would open) and their content hash ``inputs_sha256``. It is sent to the cluster once per
  campaign, as the pickled argument of a task the batches depend on (recomputed from the
  scheduler's copy if a worker holding it dies); nothing is cached on a worker under any other
  key, so a persistent cluster flies whatever the client loaded.
* **Batches.** A task is a batch of runs (:func:`batch_size`: about ``TASK_S`` seconds of work,
  50 to 1000 runs, fewer when the campaign is too small to keep every worker busy). A batch's
  results are written into the store (:mod:`taos.montecarlo.store`) the moment they arrive and
  released from the workers; the client never holds more than one batch of outputs.
* **No run lost.** A worker that dies: Dask re-runs its batches elsewhere (``RETRIES``); a batch
  cancelled all the same is submitted again with the run kind sent anew (``RESUBMITS``). A run
  that fails in itself is stored as failed with its reason. An interrupted campaign resumes by
  running the batches whose status is still "not run".
* **Reproducible.** A run is a pure function of its design row and seed, so the stored values are
  bit-identical for any worker count, batch size or scheduler on one CPU type; each run records
  the CPU/compile target its kernels ran with (:func:`cpu_target`).

``workers=0`` runs the batches in this process (no Dask): the same code path for the runs and
the store, for tests and debugging.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, Sequence

import numpy as np

from taos.errors import InputError
from taos.montecarlo import store

RETRIES = 3
#: times a batch cancelled with a lost worker is submitted again
RESUBMITS = 5
TASK_S = 10.0
MIN_BATCH, MAX_BATCH = 50, 1000
CONNECT_TIMEOUT_S = 20.0


@dataclass(frozen=True, eq=False)
class Design:
    """``n`` parameter sets: ``factors`` (n, len(names)) and a random ``seeds`` (n,) per run."""

    names: tuple[str, ...]
    factors: np.ndarray
    seeds: np.ndarray

    def __post_init__(self):
        f = np.asarray(self.factors, float).reshape(len(self.seeds), len(self.names))
        object.__setattr__(self, "factors", f)
        object.__setattr__(self, "seeds", np.asarray(self.seeds, np.int64))

    @property
    def n(self) -> int:
        return len(self.seeds)

    def sha256(self) -> str:
        import hashlib
        h = hashlib.sha256(",".join(self.names).encode())
        h.update(np.ascontiguousarray(self.factors).tobytes())
        h.update(np.ascontiguousarray(self.seeds).tobytes())
        return h.hexdigest()


class RunKind(Protocol):
    """What a campaign runs. ``run_batch(names, factors, seeds)`` returns, for the batch's rows,
    ``status`` (int8 codes of :data:`taos.montecarlo.store.STATUS`), ``error`` (list of str), each
    of ``scalars`` (float, NaN when not ok) and ``flags`` (bool) and ``trace`` (rows, len(trace_t_s)).
    It must be picklable and must not read files (its inputs travel with it)."""

    scalars: tuple[str, ...]
    flags: tuple[str, ...]
    inputs_sha256: str

    @property
    def trace_t_s(self) -> np.ndarray: ...

    @property
    def run_cost_s(self) -> float: ...

    def run_batch(self, names: tuple[str, ...], factors: np.ndarray, seeds: np.ndarray) -> dict: ...


@dataclass(frozen=True)
class Part:
    """A design stored in ``group`` of the store (None: the root)."""

    group: str | None
    design: Design


def cpu_target() -> str:
    """The CPU the compiled kernels target on this process (numba's host CPU unless
    ``NUMBA_CPU_NAME`` is set) and the fast-math flags of the flight runs' kernel
    (:func:`taos.planar.dynamics.integrate_segments_lanes`, the friction and avionics kernels it
    calls: compiled without fast-math, so 'off')."""
    import numba
    from llvmlite import binding
    name = numba.config.CPU_NAME or binding.get_host_cpu_name()
    return f"{name};fastmath=off"


def run_task(kind: RunKind, names: tuple[str, ...], factors: np.ndarray, seeds: np.ndarray) -> dict:
    """One batch as a Dask task (module level, so workers import it)."""
    out = kind.run_batch(names, factors, seeds)
    out["cpu"] = [cpu_target()] * len(seeds)
    out["inputs_sha256"] = [kind.inputs_sha256] * len(seeds)
    return out


def batch_size(n: int, run_cost_s: float, workers: int) -> int:
    """Runs per task: about ``TASK_S`` s of work, from 50 to 1000, but at most a quarter of a
    worker's share so that every worker has work to the end."""
    b = int(np.clip(round(TASK_S / max(run_cost_s, 1e-9)), MIN_BATCH, MAX_BATCH))
    return max(1, min(b, math.ceil(n / (4 * max(workers, 1)))))


def connect(workers: int, scheduler: str | None, timeout_s: float = CONNECT_TIMEOUT_S):
    """(client, cluster): an existing scheduler (waited for at most ``timeout_s``) or a
    LocalCluster of ``workers`` one-thread processes; (None, None) for ``workers=0``."""
    if scheduler is None and workers == 0:
        return None, None
    import dask
    from dask.distributed import Client, LocalCluster
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.ERROR)
        return Client(cluster), cluster
    box: dict = {}

    def go():
        try:
            with dask.config.set({"distributed.comm.timeouts.connect": f"{timeout_s}s"}):
                box["client"] = Client(scheduler, timeout=f"{timeout_s}s")
        except Exception as e:  # noqa: BLE001 - any failure to connect is the user's address
            box["error"] = e
    th = threading.Thread(target=go, daemon=True, name="taos-connect")
    th.start()
    th.join(timeout_s + 2.0)
    if "client" not in box:
        e = box.get("error")
        if e is None:
            why = f"no answer in {timeout_s:g} s"
        elif isinstance(e, (OSError, TimeoutError)):
            why = str(e).splitlines()[0][:120] if str(e) else type(e).__name__
        else:  # it answered, but what it sent is not the Dask protocol (e.g. a length of exabytes)
            why = "something answered there, but not as a Dask scheduler"
        raise InputError("command line", "--scheduler", f"the address of a running Dask scheduler answering within "
                         f"{timeout_s:g} s", got=f"{scheduler} ({why})")
    return box["client"], None


@contextlib.contextmanager
def connected(workers: int, scheduler: str | None, timeout_s: float = CONNECT_TIMEOUT_S):
    """:func:`connect` as a context: yields the client (None for ``workers=0``); on exit the
    client and any LocalCluster are closed and this process's environment is as it was before.

    A LocalCluster's nannies set their workers' environment in the process that starts them,
    this one (Dask's ``distributed.nanny.pre-spawn-environ``: ``OMP_NUM_THREADS=1``,
    ``MALLOC_TRIM_THRESHOLD_``, ...; and ``__DASK_PARENT_PID``), at every worker (re)start. Left
    there, every program the caller starts afterwards would run single-threaded BLAS: a library
    call must not change its caller's process."""
    env = dict(os.environ)
    client = cluster = None
    try:
        client, cluster = connect(workers, scheduler, timeout_s)
        yield client
    finally:
        try:
            try:
                if client is not None:
                    client.close()
            finally:
                if cluster is not None:
                    cluster.close()
        finally:
            if scheduler is None and workers != 0:   # a LocalCluster was started (or begun)
                for k in set(os.environ) - set(env):
                    del os.environ[k]
                for k, v in env.items():
                    if os.environ.get(k) != v:
                        os.environ[k] = v


def pending_batches(path: Path, part: Part, batch: int) -> list[int]:
    """Start rows of the batches of ``part`` with a run not yet stored."""
    st = store.status(path, part.group)
    if st is None or len(st) != part.design.n:
        raise InputError(str(path), "(store)", "a readable campaign store of this campaign", got="an unreadable store")
    return [s for s in range(0, part.design.n, batch) if np.any(st[s:s + batch] == store.STATUS["pending"])]


def _unpickled(blob: bytes):
    """The run kind back from its pickled bytes (the task that holds it on the cluster)."""
    import cloudpickle
    return cloudpickle.loads(blob)


def _on_cluster(client, kind: RunKind, todo: list, batch: int, stored) -> None:
    """Submit every batch of ``todo`` ((part, start row) pairs) and hand each result to
    ``stored`` as it arrives.

    The run kind goes to the cluster once, as the pickled argument of a task that returns it
    (:func:`_unpickled`) and every batch depends on: a worker that dies holding it costs a
    recomputation from the scheduler's copy, never the batches (data scattered from the client
    has no such copy: the scheduler forgot it with its last holder and cancelled the batches
    waiting on it, "already forgotten"). A batch cancelled all the same is submitted again, with
    the run kind sent anew, at most ``RESUBMITS`` times."""
    from concurrent.futures import CancelledError

    import cloudpickle
    from dask.distributed import as_completed
    blob = cloudpickle.dumps(kind)
    gen = [0, client.submit(_unpickled, blob, pure=False, retries=RETRIES)]  # generation, the run kind

    def submit(p: Part, s: int, tries: int):
        d = p.design
        f = client.submit(run_task, gen[1], d.names, d.factors[s:s + batch], d.seeds[s:s + batch],
                          pure=False, retries=RETRIES)
        meta[f.key] = (p, s, tries, gen[0])
        return f

    meta: dict = {}
    ac = as_completed([submit(p, s, 0) for p, s in todo])
    for f in ac:
        p, s, tries, g = meta.pop(f.key)
        try:
            out = f.result()
        except CancelledError:
            if tries >= RESUBMITS:
                raise
            if g == gen[0]:  # the run kind this batch waited on is gone: send it again, once
                gen[:] = [g + 1, client.submit(_unpickled, blob, pure=False, retries=RETRIES)]
            f.release()
            ac.add(submit(p, s, tries + 1))
            continue
        stored(p, s, out)
        f.release()  # the batch's results leave the worker once stored


def execute(path: Path, kind: RunKind, parts: Sequence[Part], batch: int, client, progress: bool = False) -> int:
    """Run every pending batch of ``parts`` (stored at ``path``) on ``client`` (None: in this
    process); returns the number of runs executed."""
    todo = [(p, s) for p in parts for s in pending_batches(path, p, batch)]
    total = sum(min(batch, p.design.n - s) for p, s in todo)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=total, desc="montecarlo", unit="run")

    def stored(p: Part, s: int, out: dict) -> None:
        store.write_batch(path, s, out, p.group)
        if bar is not None:
            bar.update(len(out["status"]))
    try:
        if client is None:
            for p, s in todo:
                d = p.design
                stored(p, s, run_task(kind, d.names, d.factors[s:s + batch], d.seeds[s:s + batch]))
            return total
        _on_cluster(client, kind, todo, batch, stored)
        return total
    finally:
        if bar is not None:
            bar.close()
