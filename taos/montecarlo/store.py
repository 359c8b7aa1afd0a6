"""The campaign store: xarray on Zarr, one row per run, written batch by batch.

Layout (``OUT/campaign.zarr``, Zarr format 2, readable with ``xarray.open_zarr``)::

    run        (run)               run index (0 .. n-1), the dimension every per-run variable has
    parameter  (parameter)         names of the dispersed factors
    time       (time)              trace sample times [s]
    factor     (run, parameter)    the run's factors (design row)
    seed       (run)               the run's random seed
    status     (run)  int8         0 not run yet, 1 ok, 2 failed, 3 diverged (attrs: ``flag_meanings``)
    error      (run)  str          why a run failed or diverged ("" when ok)
    cpu        (run)  str          the CPU / compile target the run's kernels ran with
    inputs_sha256 (run) str        the content hash of the inputs the worker flew the run with
    <scalar>   (run)  float        the run kind's scalar outputs (NaN when not ok)
    <flag>     (run)  0/1          the run kind's yes/no outputs (stored int8, -1 the fill value:
                                   read back as float, NaN for a run not run yet)
    trace      (run, time)         the run kind's trace [rad] (NaN when not ok): the FCS command of a flight run
    engine_trace (run, time)       the engine angle [rad] of a flight run at the same times (NaN when not ok or
                                   the run kind has none; absent from stores written before it)

Self-describing (CF conventions 1.10, readable by ``cf_xarray``): every variable has
``long_name`` and, where it has a unit, ``units`` in UDUNITS spelling (:func:`cf_attributes`:
from the SI suffix of its name, ``_deg`` degree, ``_hz`` Hz, ``_s`` s, ``_rad`` rad, ...; the
trace in rad, the scalars in the unit their name says); ``time`` has ``standard_name = "time"``
and ``axis = "T"``; status has ``flag_values``/``flag_meanings``. A run not run yet reads as NaN
in every float output and every flag (so ``ds.lco.mean()`` of a half-finished store is the
fraction over the runs done, never a 0 counted for a run that did not happen).

A second group (``group="nominal"``) holds the nominal run(s) in the same layout. The arrays are
chunked along ``run`` by the batch size, so a batch is whole chunks: writing it costs the same at
the first and the 100,000th run, and ``status`` is written last, so a batch cut short by a kill
reads as not run and is run again on resume. A failed run keeps its row: traces stay aligned with
run indices.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

STATUS = {"pending": 0, "ok": 1, "failed": 2, "diverged": 3}
#: the (run, time) variables
TRACES = ("trace", "engine_trace")
TEXT_WIDTH = 160
#: flags on disk: int8, this value for a run not run yet (decoded to NaN by xarray)
FLAG_FILL = -1
CONVENTIONS = "CF-1.10"
#: UDUNITS spelling of the unit each name suffix states (longest suffix first)
SUFFIX_UNITS = (("_deg_s", "degree s-1"), ("_rad_s", "rad s-1"), ("_n_m", "N m"), ("_deg", "degree"),
                ("_rad", "rad"), ("_hz", "Hz"), ("_db", "dB"), ("_s", "s"), ("_m", "m"), ("_n", "N"))
#: long names of the store's own variables and of the flight runs' outputs (:mod:`taos.montecarlo.run`)
LONG_NAMES = {
    "run": "run index", "parameter": "dispersed factor name", "time": "time from the start of the segment",
    "factor": "factor on the nominal value (design row)", "seed": "random seed of the run",
    "status": "run status", "error": "why the run failed or diverged", "cpu": "CPU / compile target of the kernels",
    "inputs_sha256": "SHA-256 of the inputs the run was flown with",
    "trace": "FCS engine-angle command", "engine_trace": "engine angle",
    "amplitude_deg": "limit-cycle amplitude of the FCS command (fundamental)",
    "engine_amplitude_deg": "limit-cycle amplitude of the engine angle (fundamental)",
    "frequency_hz": "limit-cycle frequency", "growth": "amplitude growth over the analysis window (ratio)",
    "peak_engine_deg": "peak engine angle over the segment", "peak_engine_rate_deg_s": "peak engine rate",
    "peak_attitude_deg": "peak attitude error over the segment", "lco": "sustained limit cycle (1 yes, 0 no)",
}


def cf_attributes(name: str, long_name: str | None = None) -> dict:
    """CF attributes of variable ``name``: ``long_name`` (given, from :data:`LONG_NAMES`, else the
    name in words) and ``units`` from its SI suffix (:data:`SUFFIX_UNITS`; the trace: rad; no
    ``units`` for a dimensionless ratio, a flag, a count or text)."""
    out = {"long_name": long_name or LONG_NAMES.get(name) or name.replace("_", " ")}
    unit = "rad" if name in TRACES else "s" if name == "time" else next(
        (u for sfx, u in SUFFIX_UNITS if name.endswith(sfx)), None)
    if unit is not None:
        out["units"] = unit
    if name == "time":
        out |= {"standard_name": "time", "axis": "T"}
    return out


def _lazy(shape, dtype, chunks, fill):
    import dask.array as da
    return da.full(shape, fill, dtype=dtype, chunks=chunks)


def create(path: Path, *, labels: np.ndarray, names: tuple[str, ...], factors: np.ndarray, seeds: np.ndarray,
           scalars: tuple[str, ...], flags: tuple[str, ...], trace_t_s: np.ndarray, batch: int, attrs: Mapping,
           group: str | None = None, long_names: Mapping[str, str] | None = None) -> None:
    """Write the store's metadata and the design (factors, seeds); every output unset (NaN).
    ``long_names``: the run kind's outputs in words (default :data:`LONG_NAMES`)."""
    import xarray as xr
    n, m = len(labels), len(trace_t_s)
    ch = (min(batch, n),)
    data = {
        "factor": (("run", "parameter"), np.asarray(factors, float).reshape(n, len(names))),
        "seed": (("run",), np.asarray(seeds, np.int64)),
        "status": (("run",), _lazy((n,), np.int8, ch, 0),
                   {"flag_values": np.asarray(list(STATUS.values()), np.int8), "flag_meanings": " ".join(STATUS)}),
        "error": (("run",), _lazy((n,), f"<U{TEXT_WIDTH}", ch, "")),
        "cpu": (("run",), _lazy((n,), "<U64", ch, "")),
        "inputs_sha256": (("run",), _lazy((n,), "<U64", ch, "")),
    }
    for k in TRACES:
        data[k] = (("run", "time"), _lazy((n, m), float, (ch[0], max(m, 1)), np.nan))
    for s in scalars:
        data[s] = (("run",), _lazy((n,), float, ch, np.nan))
    for f in flags:
        data[f] = (("run",), _lazy((n,), float, ch, np.nan), {"flag_values": np.asarray([0, 1], np.int8),
                                                               "flag_meanings": "no yes"})
    ds = xr.Dataset(data, coords={"run": np.asarray(labels, np.int64), "parameter": list(names),
                                  "time": np.asarray(trace_t_s, float)}, attrs={"Conventions": CONVENTIONS, **attrs})
    for k, v in ds.variables.items():
        v.attrs.update(cf_attributes(str(k), (long_names or {}).get(str(k))))
    enc = {f: {"dtype": "int8", "_FillValue": FLAG_FILL} for f in flags}
    ds.to_zarr(path, group=group, compute=False, mode="w-" if group is None else "a", zarr_format=2, encoding=enc)


def write_batch(path: Path, start: int, out: Mapping[str, np.ndarray], group: str | None = None) -> None:
    """Store a batch's outputs at rows ``start``.. (``out``: the variables above, ``status`` last)."""
    import xarray as xr
    n = len(out["status"])
    region = {"run": slice(start, start + n)}
    # (a store written before a variable existed, resumed: that variable is not stored)
    old = [k for k in TRACES[1:] if k in out and not (Path(path) / (group or "") / k / ".zarray").exists()]
    body = {k: ((("run", "time") if k in TRACES else ("run",)), np.asarray(v)) for k, v in out.items()
            if k != "status" and k not in old}
    for k, (dims, v) in body.items():
        if v.dtype == bool:   # a flag: 0/1 (the store's int8 encoding; NaN stays for runs not run)
            body[k] = (dims, v.astype(float))
    if "error" in body:
        body["error"] = (("run",), np.asarray([e[:TEXT_WIDTH] for e in out["error"]], f"<U{TEXT_WIDTH}"))
    for k in ("cpu", "inputs_sha256"):
        if k in body:
            body[k] = (("run",), np.asarray(out[k], "<U64"))
    xr.Dataset(body).to_zarr(path, group=group, region=region, zarr_format=2)
    xr.Dataset({"status": (("run",), np.asarray(out["status"], np.int8))}).to_zarr(path, group=group, region=region,
                                                                                    zarr_format=2)


def open_store(path: Path, group: str | None = None, consolidated: bool | None = None, *, dask: bool = True):
    """The store (or its ``group``) as a lazy :class:`xarray.Dataset`; ``dask=False`` reads it
    without dask arrays, so a read never becomes a task of a Dask client that happens to be
    active in this process (its workers may not see this file system, or may be gone)."""
    import xarray as xr
    return xr.open_zarr(path, group=group, zarr_format=2, consolidated=consolidated,
                        **({} if dask else {"chunks": None}))


def finish_pending_io(timeout_s: float = 5.0) -> None:
    """Let the Zarr I/O that a signal cut off finish (at most ``timeout_s`` [s]) before the run exits.

    Zarr runs its reads and writes as tasks of an event loop on its own thread; a Ctrl-C in the
    main thread stops the wait, not the tasks. Left running into interpreter exit, a task finds
    the thread pool already shut and the loop destroys it mid-write: a chunk file half written and
    "Task was destroyed but it is pending!" on standard error. Called by
    :func:`taos.errors.run_cli` after an interrupt; a no-op when Zarr never ran."""
    import sys

    try:   # (the interrupt may have cut an import short: Zarr or asyncio half initialised)
        zsync = sys.modules.get("zarr.core.sync")
        loop = (getattr(zsync, "loop", None) or [None])[0] if zsync is not None else None
        if loop is None or loop.is_closed() or not loop.is_running():
            return
        import asyncio

        async def rest() -> None:
            me = asyncio.current_task()
            pending = [t for t in asyncio.all_tasks() if t is not me]
            if pending:
                await asyncio.wait(pending, timeout=timeout_s)
        asyncio.run_coroutine_threadsafe(rest(), loop).result(timeout_s + 1.0)
    except Exception:  # the loop stopped meanwhile, the wait ran out, a module half imported
        pass


def status(path: Path, group: str | None = None) -> np.ndarray | None:
    """Every run's status code, or None when the store cannot be read (read in this process)."""
    try:
        return np.asarray(open_store(path, group, consolidated=False, dask=False)["status"].values, np.int8)
    except (OSError, KeyError, ValueError):
        return None
