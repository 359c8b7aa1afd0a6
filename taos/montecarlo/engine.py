"""The campaign engine: a list of parameter sets (a :class:`Design`) and a run function (a
:class:`RunKind`), run in batches on Dask and stored as they arrive.

* **Inputs by value.** The run kind carries its parsed inputs (models, tables: no file path a
  worker would open) and their content hash ``inputs_sha256``. It is sent to the cluster once per
  campaign, as the pickled argument of a task the batches depend on (recomputed from the
  scheduler's copy if a worker holding it dies); nothing is cached on a worker under any other
  key, so a persistent cluster flies whatever the client loaded.
* **Batches.** A task is a batch of runs (:func:`batch_size`: about ``TASK_S`` seconds of work,
  50 to 1000 runs rounded up to a multiple of :data:`BATCH_MULTIPLE`, fewer when the campaign is
  too small to keep every worker busy). A batch's
  results are written into the store (:mod:`taos.montecarlo.store`) the moment they arrive and
  released from the workers; the client never holds more than one batch of outputs.
* **No run lost.** A worker that dies: Dask re-runs its batches elsewhere (``RETRIES``); a batch
  cancelled all the same is submitted again with the run kind sent anew (``RESUBMITS``). A run
  that fails in itself is stored as failed with its reason. An interrupted campaign resumes by
  running the batches whose status is still "not run".
* **One code everywhere.** At connect every worker's taos version and code hash
  (:func:`code_identity`: SHA-256 of the package's Python source, whence the kernels come) are
  fetched with ``client.run`` and compared with the client's; a worker running other code, or
  no taos at all, is refused with one line naming both (:class:`~taos.errors.InputError`, exit
  2) before anything is written. A worker joining later is checked by every batch it runs
  (:func:`run_task` compares its own identity with the client's and refuses to run).
* **A cluster that fails is reported, never waited on in silence.** No batch stored for
  ``STALL_S`` while a worker is paused (Dask pauses a worker at 80 % of its memory limit), a
  batch that kept killing its workers (``KilledWorker``), a worker with other code, or the
  scheduler lost: the campaign stops with :class:`CampaignStopped` (an
  :class:`~taos.errors.InputError`: one line, exit 2) saying what happened; the stored batches
  stay, and ``--resume`` continues. No worker at all for ``STALL_S`` (a batch queue not started
  yet) is said once on standard error, and the campaign waits.
* **Reproducible.** A run is a pure function of its design row and seed, so the stored values are
  bit-identical for any worker count, batch size or scheduler on one CPU type; each run records
  the CPU/compile target its kernels ran with (:func:`cpu_target`).

``workers=0`` runs the batches in this process (no Dask): the same code path for the runs and
the store, for tests and debugging.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import logging
import math
import os
import threading
import time
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
#: runs per task a multiple of the flight runs' kernel call (:data:`taos.flight.ascent_sim.LANES`,
#: 32 runs in lockstep): calls of 21-31 runs measured 1.2-1.8x the kernel time a run of a 32-run call
#: (benchmarks/RESULTS.md, section mcfast; the vector loops across the runs leave a scalar rest)
BATCH_MULTIPLE = 32
CONNECT_TIMEOUT_S = 20.0
#: no batch stored for this long with a worker paused: the campaign stops [s]
STALL_S = 120.0
#: the polling interval of the cluster's health while waiting for batches [s]
POLL_S = 0.05


class CampaignStopped(InputError):
    """The cluster failed mid-campaign (``reason``); the batches stored so far stay and the
    campaign continues with ``resume`` (``--resume``)."""

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__("(cluster)", "campaign", "a cluster that runs the campaign to its end",
                         got=f"{reason}; the runs stored so far are kept (resume to continue)")


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


@functools.cache
def code_sha256() -> str:
    """SHA-256 of the taos package's Python source as this process imports it: every ``*.py``
    file under the package folder, in sorted relative-path order, path and bytes (compiled
    caches and data left out). Two processes with the same value run the same code."""
    import taos
    root = Path(taos.__file__).resolve().parent
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py"), key=lambda q: q.relative_to(root).as_posix()):
        h.update(f.relative_to(root).as_posix().encode() + b"\0")
        h.update(f.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def code_identity() -> dict:
    """``{"taos": version, "code_sha256": ...}`` of this process (:func:`code_sha256`)."""
    from taos.results import package_version
    return {"taos": package_version(), "code_sha256": code_sha256()}


def describe_identity(ident) -> str:
    if not isinstance(ident, dict):
        return f"no usable taos ({type(ident).__name__}: {str(ident).splitlines()[0][:80] if str(ident) else ''})"
    return f"taos {ident.get('taos')} (code sha256 {str(ident.get('code_sha256'))[:16]})"


class WorkerCodeMismatch(RuntimeError):
    """A batch landed on a worker whose taos code differs from the client's (raised there)."""


def check_workers(client) -> None:
    """Refuse (one line, :class:`InputError`) a cluster with a worker whose taos version or code
    hash (:func:`code_identity`, fetched with ``client.run``) is not the client's."""
    mine = code_identity()
    theirs = client.run(code_identity, on_error="return")
    for addr, ident in sorted(theirs.items()):
        if ident != mine:
            raise InputError("command line", "--scheduler", f"workers running this client's {describe_identity(mine)}",
                             got=f"worker {addr} runs {describe_identity(ident)}")


def run_task(kind: RunKind, names: tuple[str, ...], factors: np.ndarray, seeds: np.ndarray,
             expect: dict | None = None) -> dict:
    """One batch as a Dask task (module level, so workers import it); ``expect``: the client's
    :func:`code_identity`, refused (:class:`WorkerCodeMismatch`) by a worker with other code."""
    if expect is not None and code_identity() != expect:
        raise WorkerCodeMismatch(f"this worker runs {describe_identity(code_identity())}, the client "
                                 f"{describe_identity(expect)}")
    out = kind.run_batch(names, factors, seeds)
    out["cpu"] = [cpu_target()] * len(seeds)
    out["inputs_sha256"] = [kind.inputs_sha256] * len(seeds)
    return out


def batch_size(n: int, run_cost_s: float, workers: int) -> int:
    """Runs per task: about ``TASK_S`` s of work, from 50 to 1000 rounded up to a multiple of
    :data:`BATCH_MULTIPLE`, but at most a quarter of a worker's share so that every worker has
    work to the end."""
    b = int(np.clip(round(TASK_S / max(run_cost_s, 1e-9)), MIN_BATCH, MAX_BATCH))
    b = -(-b // BATCH_MULTIPLE) * BATCH_MULTIPLE
    return max(1, min(b, math.ceil(n / (4 * max(workers, 1)))))


def connect(workers: int, scheduler: str | None, timeout_s: float = CONNECT_TIMEOUT_S):
    """(client, cluster): an existing scheduler (waited for at most ``timeout_s``) or a
    LocalCluster of ``workers`` one-thread processes; (None, None) for ``workers=0``."""
    if scheduler is None and workers == 0:
        return None, None
    import dask
    from dask.distributed import Client, LocalCluster
    if scheduler is None:
        # silence_logs: the level of the "distributed" stream handlers, here and in each worker
        # process (Dask's default prints a worker's errors): CRITICAL, as _quiet_dask_logs, so a
        # worker whose scheduler closes first (SIGTERM or Ctrl-C mid-campaign) does not print
        # "Failed to communicate with scheduler during heartbeat" and its traceback beside the
        # campaign's one line; what goes wrong on a worker reaches the campaign as an exception
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.CRITICAL)
        client = Client(cluster)
        _checked(client, cluster)
        return client, cluster
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
    _checked(box["client"], None)
    return box["client"], None


def _checked(client, cluster) -> None:
    """:func:`check_workers`, the client (and cluster) closed when it refuses."""
    try:
        check_workers(client)
    except BaseException:
        with contextlib.suppress(Exception):
            client.close()
            if cluster is not None:
                cluster.close()
        raise


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
    quiet = _quiet_dask_logs() if client_needed(workers, scheduler) else contextlib.nullcontext()
    with quiet:   # (the close too: a client whose scheduler is gone logs its reconnect failure there)
        try:
            client, cluster = connect(workers, scheduler, timeout_s)
            yield client
        finally:
            try:
                try:
                    if client is not None:
                        with contextlib.suppress(Exception):   # a scheduler already gone: nothing to close
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


def client_needed(workers: int, scheduler: str | None) -> bool:
    return scheduler is not None or workers != 0


@contextlib.contextmanager
def _quiet_dask_logs():
    """Dask's client-side loggers silenced during a campaign: a lost scheduler or worker is
    reported once, by the campaign (:class:`CampaignStopped`), not by Dask's "Failed to
    reconnect" and connection-closed lines on standard error. Restored on exit."""
    names = ("distributed", "distributed.client", "distributed.comm", "distributed.core", "distributed.batched",
             "tornado", "asyncio")
    loggers = [logging.getLogger(n) for n in names]
    levels = [lg.level for lg in loggers]
    try:
        for lg in loggers:
            lg.setLevel(logging.CRITICAL)
        yield
    finally:
        for lg, lv in zip(loggers, levels):
            lg.setLevel(lv)


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
    from distributed.scheduler import KilledWorker
    blob = cloudpickle.dumps(kind)
    mine = code_identity()
    gen = [0, client.submit(_unpickled, blob, pure=False, retries=RETRIES)]  # generation, the run kind

    def submit(p: Part, s: int, tries: int):
        d = p.design
        f = client.submit(run_task, gen[1], d.names, d.factors[s:s + batch], d.seeds[s:s + batch], mine,
                          pure=False, retries=RETRIES)
        meta[f.key] = (p, s, tries, gen[0])
        return f

    meta: dict = {}
    ac = as_completed([submit(p, s, 0) for p, s in todo])
    watch = _Watch(client)
    while not ac.is_empty():
        if not ac.has_ready():
            watch.check()
            time.sleep(POLL_S)
            continue
        f = next(ac)
        p, s, tries, g = meta.pop(f.key)
        try:
            out = f.result()
        except CancelledError:
            if client.status in ("closing", "closed") or tries >= RESUBMITS:
                raise CampaignStopped(_lost(client, f"batch at run {s} cancelled {tries + 1} times")) from None
            if g == gen[0]:  # the run kind this batch waited on is gone: send it again, once
                gen[:] = [g + 1, client.submit(_unpickled, blob, pure=False, retries=RETRIES)]
            f.release()
            ac.add(submit(p, s, tries + 1))
            continue
        except WorkerCodeMismatch as e:
            raise CampaignStopped(f"a worker that joined runs other code: {e}") from None
        except KilledWorker as e:
            raise CampaignStopped(f"workers died running the batch at run {s} and Dask gave up on it "
                                  f"(KilledWorker: out of memory, or killed?): {str(e).splitlines()[0][:120]}") from None
        except (OSError, TimeoutError) as e:   # the scheduler's connection (CommClosedError is an OSError)
            raise CampaignStopped(_lost(client, f"{type(e).__name__}")) from None
        stored(p, s, out)
        watch.progress()
        f.release()  # the batch's results leave the worker once stored


def _lost(client, what: str) -> str:
    if client.status in ("closing", "closed") or not _scheduler_answers(client):
        return "the Dask scheduler was lost (no answer within the connect timeout)"
    return what


def _scheduler_answers(client, timeout_s: float = 5.0) -> bool:
    """The scheduler answers a call within ``timeout_s`` [s] (asked, not the client's cached
    ``scheduler_info()``, which swallows a connection error and answers from memory)."""
    try:
        client.sync(client.scheduler.identity, callback_timeout=timeout_s)
        return True
    except Exception:  # noqa: BLE001 - any failure to ask is a scheduler gone
        return False


class _Watch:
    """The cluster's health while a campaign waits: stop when no batch has been stored for
    ``STALL_S`` and a worker is paused; say once when no worker is there at all."""

    def __init__(self, client):
        self.client, self.last, self.said = client, time.monotonic(), False

    def progress(self) -> None:
        self.last, self.said = time.monotonic(), False

    def check(self) -> None:
        if time.monotonic() - self.last < STALL_S:
            return
        if self.client.status in ("closing", "closed"):
            raise CampaignStopped("the Dask scheduler was lost (client closed)")
        try:
            workers = self.client.scheduler_info(n_workers=-1).get("workers", {})
        except TypeError:   # (an older distributed: every worker listed anyway)
            workers = self.client.scheduler_info().get("workers", {})
        except Exception as e:  # noqa: BLE001 - the scheduler does not answer
            raise CampaignStopped(f"the Dask scheduler was lost ({type(e).__name__})") from None
        paused = sorted(a for a, w in workers.items() if str(w.get("status", "")).endswith("paused"))
        if paused:
            mem = [workers[a].get("metrics", {}).get("memory") for a in paused]
            lim = [workers[a].get("memory_limit") for a in paused]
            detail = ", ".join(f"{a} ({m / 2 ** 30:.2f} of {lim_ / 2 ** 30:.2f} GiB)" if m and lim_ else a
                               for a, m, lim_ in zip(paused, mem, lim))
            raise CampaignStopped(f"no batch stored for {STALL_S:g} s while {len(paused)} of {len(workers)} workers "
                                  f"are paused (memory above Dask's pause fraction): {detail}")
        if not workers and not self.said:
            import sys
            print(f"taos: no Dask worker connected to the scheduler for {STALL_S:g} s; waiting (Ctrl-C stops, "
                  "the stored runs stay for --resume)", file=sys.stderr)
            self.said = True


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
