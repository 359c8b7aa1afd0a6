"""A parameter sweep over model-file keys, run as a campaign on the Monte Carlo engine.

Every point of the design (:mod:`taos.montecarlo.sweep_define`) is a variant of one model file
with some keys replaced: the client builds each variant with the model loader
(:func:`taos.model.load_model` with ``overrides``: the same checks as a file holding those
values; a bad value stops the sweep before any work, one line, exit 2) and records the content
hash of every file read (:mod:`taos.montecarlo.inputs`). The variants travel to the workers by
value in the run kind :class:`SweepRuns`; a worker opens no file.

A point's figures (:mod:`taos.montecarlo.sweep_metrics`) are computed on a worker; a variant
whose linear block is unstable is stored with the engine's status "diverged" (reported as
**unstable**, the reason its least-damped right-half-plane mode) and a point whose figures could
not be computed as "failed" with its reason: both are results of the sweep, listed apart.

Output folder (``--out``; only these names are written)::

    sweep.json    manifest: model and input hashes, the sweep definition, the batch size
    sweep.zarr    the store (:mod:`taos.montecarlo.store` layout: ``factor`` (run, parameter),
                  ``status``, ``error``, one variable per metric)

``resume`` runs the batches not yet stored when the definition and every input are unchanged.
Without a folder the store lives in a temporary folder removed at the end.
"""

from __future__ import annotations

import json
import math
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from taos.errors import InputError, SimulationUnstable
from taos.montecarlo import engine, store
from taos.montecarlo.engine import Design, Part
from taos.montecarlo.sweep_define import SweepDesign
from taos.montecarlo.sweep_metrics import METRICS, LcoSettings, evaluate, run_cost_s, unstable_reason
from taos.results import model_provenance

FORMAT = "taos-sweep-1"
MANIFEST = "sweep.json"
STORE = "sweep.zarr"
MAX_WORKERS = 64
STATUS_NAMES = {store.STATUS["ok"]: "ok", store.STATUS["failed"]: "failed", store.STATUS["diverged"]: "unstable",
                store.STATUS["pending"]: "not run"}


@dataclass(frozen=True, eq=False)
class SweepRuns:
    """The engine's run kind of a sweep: ``models[i]`` is the variant of design row
    ``factors[i]``; ``metrics`` the figures computed per point on ``axis``."""

    models: tuple
    factors: np.ndarray
    metrics: tuple[str, ...]
    axis: str
    lco: LcoSettings | None
    inputs_sha256: str
    index: dict = field(init=False, repr=False)

    def __post_init__(self):
        rows = np.ascontiguousarray(np.asarray(self.factors, float))
        object.__setattr__(self, "index", {r.tobytes(): i for i, r in enumerate(rows)})

    @property
    def scalars(self) -> tuple[str, ...]:
        return tuple(m for m in self.metrics if not METRICS[m].flag)

    @property
    def flags(self) -> tuple[str, ...]:
        return tuple(m for m in self.metrics if METRICS[m].flag)

    @property
    def trace_t_s(self) -> np.ndarray:
        return np.zeros(0)

    @property
    def run_cost_s(self) -> float:
        return run_cost_s(self.metrics, self.lco)

    def run_batch(self, names, factors: np.ndarray, seeds: np.ndarray) -> dict:
        n = len(seeds)
        out = {"status": np.zeros(n, np.int8), "error": [""] * n, "trace": np.zeros((n, 0)),
               **{k: np.full(n, np.nan) for k in self.scalars}, **{k: np.zeros(n, bool) for k in self.flags}}
        rows = np.ascontiguousarray(np.asarray(factors, float))
        for i in range(n):
            model = self.models[self.index[rows[i].tobytes()]]
            why = unstable_reason(model, self.axis)
            if why:
                out["status"][i], out["error"][i] = store.STATUS["diverged"], why
                continue
            try:
                vals = evaluate(model, self.metrics, self.axis, self.lco)
            except (SimulationUnstable, InputError, ValueError, ArithmeticError, np.linalg.LinAlgError) as e:
                out["status"][i] = store.STATUS["failed"]
                out["error"][i] = f"{type(e).__name__}: {str(e).splitlines()[0][:300] if str(e) else ''}"
                continue
            for k, v in vals.items():
                out[k][i] = bool(v) if METRICS[k].flag else v
            out["status"][i] = store.STATUS["ok"]
        return out


def _where(texts: dict) -> str:
    return ", ".join(f"{k}={v}" for k, v in texts.items())


def build_models(model_file: str, design: SweepDesign, friction: str | None) -> tuple:
    """Every variant of the design, checked by the model loader here, on the client. A value
    the loader refuses is re-raised naming ``--set KEY`` (and the point, when another field
    of the file is the one that fails)."""
    from taos.model import load_model

    swept = [k.key for k in design.keys]
    models = []
    for over, texts in zip(design.overrides, design.texts):
        try:
            models.append(load_model(model_file, friction=friction, overrides=over))
        except InputError as e:
            hit = next((k for k in swept if e.field == k or e.field.startswith(k + "[")
                        or e.field == k.split(".")[0]), None)
            if hit is not None:
                raise InputError("command line", f"--set {hit}", e.expected,
                                 got=f"{e.got if e.got is not None else texts.get(hit)} (in {model_file})") from None
            raise InputError(e.source, e.field, e.expected, got=f"{e.got} with --set {_where(texts)}") from None
    return tuple(models)


@dataclass(frozen=True)
class SweepDefinition:
    """What to sweep: the model file, the design, the metrics and their settings."""

    model_file: str
    design: SweepDesign
    metrics: tuple[str, ...]
    axis: str = "pitch"
    friction: str | None = None
    flight_file: str | None = None
    avionics: str = "bounding"
    amplitudes_deg: tuple[float, ...] | None = None
    freq_hz: tuple[float, ...] | None = None

    def to_dict(self) -> dict:
        return {"model_file": self.model_file, **self.design.to_dict(), "metrics": list(self.metrics),
                "axis": self.axis, "friction": self.friction, "flight_file": self.flight_file,
                "avionics": self.avionics, "amplitudes_deg": self.amplitudes_deg and list(self.amplitudes_deg),
                "freq_hz": self.freq_hz and list(self.freq_hz)}


def check_metrics(names: tuple[str, ...], flight_file: str | None) -> None:
    if not names or len(names) > len(METRICS) or len(set(names)) != len(names):
        raise InputError("command line", "--metric", "metric names, each once", got=",".join(names)[:80])
    for n in names:
        if n not in METRICS:
            from taos.errors import nearest
            g = nearest(n, list(METRICS))
            raise InputError("command line", "--metric", ("a known metric" + (f" (did you mean {g!r}?)" if g else
                             " (taos sweep --list-metrics)")), got=repr(n))
    if flight_file is None and any(METRICS[n].family in ("lco", "lco_time") for n in names):
        raise InputError("command line", "--flight", "a flight file for the LCO metrics (e.g. "
                         "models/flight/core_stage.toml)", got="none")


def load_runs(defn: SweepDefinition) -> tuple[SweepRuns, list[dict], dict]:
    """The run kind with every variant built and checked here, the table of input files, and
    the base model's provenance."""
    from taos.flight.vehicle import load_flight
    from taos.model import load_model
    from taos.montecarlo.inputs import digest, recording

    check_metrics(defn.metrics, defn.flight_file)
    with recording() as files:   # the modules imported before it: an import reads files that are not inputs
        base = load_model(defn.model_file, friction=defn.friction)
        lco = None
        if defn.flight_file is not None:
            flight = load_flight(defn.flight_file)
            lco = LcoSettings(flight, defn.avionics,
                              None if defn.amplitudes_deg is None else tuple(map(math.radians, defn.amplitudes_deg)),
                              defn.freq_hz)
        models = build_models(defn.model_file, defn.design, defn.friction)
    settings = json.dumps({"format": FORMAT, "definition": defn.to_dict()}, sort_keys=True)
    sha, table = digest(files, settings)
    kind = SweepRuns(models, defn.design.factors, defn.metrics, defn.axis, lco, sha)
    prov = {**model_provenance(base), "friction_model": base.friction.name}
    if lco is not None:
        prov |= {"flight_file": lco.flight.source, "flight_sha256": lco.flight.sha256}
    return kind, table, prov


def _check_out(out: Path, manifest: dict, resume: bool) -> dict | None:
    """The stored manifest when resuming (None for a new sweep); refuses, before any write, a
    folder that is a file, a folder holding a sweep without ``resume``, a resume of another
    sweep or with other inputs, and names taos would have to replace."""
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", "a folder for the sweep (or a new path)", got=f"{out} (a file)")
    mpath = out / MANIFEST
    if not mpath.exists():
        if (out / STORE).exists():
            raise InputError("command line", "--out", "a folder whose sweep file names are free (files taos "
                             "did not write are never replaced)", got=f"{out / STORE} exists")
        if resume:
            raise InputError("command line", "--resume", "a folder holding a sweep to continue", got=str(out))
        return None
    try:
        old = json.loads(mpath.read_text())
    except (OSError, ValueError):
        raise InputError(str(mpath), "(file)", "a sweep manifest written by taos sweep", got="an unreadable file") \
            from None
    if not resume:
        raise InputError("command line", "--out", "a folder without a sweep in it (or --resume to continue it)",
                         got=str(out))
    for k in ("format", "definition_sha256", "inputs_sha256"):
        if old.get(k) != manifest[k]:
            what = {"inputs_sha256": "inputs (a file changed)", "definition_sha256": "sweep definition"}.get(k, k)
            raise InputError(str(mpath), k, f"the same {what} to resume this sweep",
                             got=f"{manifest[k]!r} (stored: {old.get(k)!r})")
    return old


def run_sweep(defn: SweepDefinition, out_dir: str | Path | None = None, *, workers: int = 1,
              scheduler: str | None = None, resume: bool = False, progress: bool = False,
              batch: int | None = None, connect_timeout_s: float = engine.CONNECT_TIMEOUT_S) -> "SweepResult":
    """Run the sweep on the engine into ``out_dir`` (None: a temporary folder): ``workers`` 1
    runs in this process, more a LocalCluster of that many one-thread workers; ``scheduler`` an
    existing Dask scheduler instead, waited for at most ``connect_timeout_s`` [s] (0.1 to 600;
    also how long a lost scheduler is waited for before the sweep stops). Returns the result
    read back from the store."""
    from taos.results import atomic_write, package_version

    if not 1 <= workers <= MAX_WORKERS:
        raise InputError("command line", "--workers", f"1 to {MAX_WORKERS} workers", got=str(workers))
    if batch is not None and not 1 <= batch <= engine.MAX_BATCH:
        raise InputError("command line", "--batch", f"1 to {engine.MAX_BATCH} points per task", got=str(batch))
    if isinstance(connect_timeout_s, bool) or not isinstance(connect_timeout_s, (int, float)) \
            or not 0.1 <= connect_timeout_s <= 600:   # (also NaN)
        raise InputError("command line", "--connect-timeout", "0.1 to 600 s", got=str(connect_timeout_s))
    if resume and out_dir is None:
        raise InputError("command line", "--resume", "--out FOLDER of the sweep to continue", got="no --out")
    kind, table, base = load_runs(defn)   # every variant checked before anything is written
    d = defn.design
    design = Design(tuple(k.key for k in d.keys), d.factors, np.zeros(d.n, np.int64))
    manifest = {"format": FORMAT, "inputs_sha256": kind.inputs_sha256, "input_files": table,
                "definition": defn.to_dict(), "definition_sha256": d.sha256(), "design_sha256": design.sha256()}
    tmp = tempfile.TemporaryDirectory(prefix="taos-sweep-") if out_dir is None else None
    out = Path(tmp.name if tmp is not None else out_dir)
    try:
        old = _check_out(out, manifest, resume)
        spath = out / STORE
        t0 = time.perf_counter()
        with engine.connected(0 if scheduler is None and workers == 1 else workers, scheduler,
                              connect_timeout_s) as client:
            n_workers = len(client.scheduler_info().get("workers", {})) if client is not None else 1
            if old is not None and store.status(spath) is not None:
                manifest["batch"] = int(old["batch"])
            else:
                manifest["batch"] = batch or engine.batch_size(d.n, kind.run_cost_s, n_workers)
                out.mkdir(parents=True, exist_ok=True)
                if spath.exists():   # a store this sweep began (its manifest is ours) but did not finish creating
                    shutil.rmtree(spath)
                atomic_write(out / MANIFEST, lambda q: q.write_text(json.dumps(manifest, indent=1) + "\n"))
                store.create(spath, labels=np.arange(d.n), names=design.names, factors=design.factors,
                             seeds=design.seeds, scalars=kind.scalars, flags=kind.flags, trace_t_s=kind.trace_t_s,
                             batch=manifest["batch"], attrs={"format": FORMAT, "inputs_sha256": kind.inputs_sha256,
                                                            "model_sha256": base["model_sha256"]})
            try:
                executed = engine.execute(spath, kind, [Part(None, design)], manifest["batch"], client,
                                          progress=progress)
            except engine.CampaignStopped as e:
                if tmp is None:
                    raise   # its line: the points kept in out_dir, resume to continue
                raise InputError(e.source, e.field, e.expected,   # a temporary store is removed below
                                 got=f"{e.reason}; nothing kept (no out_dir / --out: the store was temporary)") \
                    from None
        wall = time.perf_counter() - t0
        ds = store.open_store(spath, dask=False).load()
    finally:
        if tmp is not None:
            tmp.cleanup()
    prov = {**base, "inputs_sha256": kind.inputs_sha256, "input_files": table, "package_version": package_version(),
            "definition": defn.to_dict(), "definition_sha256": d.sha256(), "store": None if tmp else str(spath),
            "cpu_targets": sorted({str(v) for v in np.unique(ds["cpu"].values)} - {""})}
    timing = {"wall_s": wall, "points_executed": executed, "batch": manifest["batch"],
              "workers": n_workers, "executor": scheduler or ("in-process" if workers == 1 else "LocalCluster")}
    return SweepResult(defn, np.asarray(ds["status"].values, np.int8), [str(e) for e in ds["error"].values],
                       {m: np.asarray(ds[m].values, float) for m in defn.metrics}, prov, timing)


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


@dataclass(frozen=True, eq=False)
class SweepResult:
    """Per point: ``status`` (store codes), ``errors``, ``values[metric]`` (n,) (flags 0/1; NaN
    where a point is not ok or a figure does not exist)."""

    definition: SweepDefinition
    status: np.ndarray
    errors: list[str]
    values: dict[str, np.ndarray]
    provenance: dict
    timing: dict

    def status_name(self, i: int) -> str:
        return STATUS_NAMES[int(self.status[i])]

    def grid(self, metric: str) -> np.ndarray:
        """The metric over the grid's shape (grid designs), NaN where a point is not ok."""
        v = np.where(self.status == store.STATUS["ok"], self.values[metric], np.nan)
        shape = self.definition.design.shape
        return v if shape is None else v.reshape(shape)

    def to_dict(self) -> dict:
        d = self.definition.design
        points, failed, unstable = [], [], []
        for i in range(d.n):
            st = self.status_name(i)
            row = {"index": i, "set": dict(d.texts[i]),
                   "factors": {k.key: float(d.factors[i, j]) for j, k in enumerate(d.keys)}, "status": st,
                   "metrics": {m: (None if st != "ok" else bool(self.values[m][i]) if METRICS[m].flag
                                   else _num(self.values[m][i])) for m in self.definition.metrics}}
            if st != "ok":
                row["reason"] = self.errors[i]
                (unstable if st == "unstable" else failed).append({"index": i, "set": dict(d.texts[i]),
                                                                    "reason": self.errors[i] or st})
            points.append(row)
        counts = {"points": d.n, "ok": int(np.sum(self.status == store.STATUS["ok"])), "failed": len(failed),
                  "unstable": len(unstable)}
        out = {"format": FORMAT, "model_file": self.definition.model_file, "axis": self.definition.axis,
                "grid": d.to_dict(), "factor_units": {k.key: k.unit for k in d.keys},
                "metrics": [{"name": m, "meaning": METRICS[m].meaning} for m in self.definition.metrics],
                "counts": counts, "points": points, "failed": failed, "unstable": unstable,
                "provenance": self.provenance, "timing": self.timing}
        if d.design == "sobol":
            out["sensitivity"] = {m: self.sensitivity(m) for m in self.definition.metrics if not METRICS[m].flag}
        return out

    def sensitivity(self, metric: str, confidence: float = 0.95) -> dict:
        """First-order and total Sobol' indices of ``metric`` with their bootstrap half-widths
        (:func:`taos.montecarlo.sensitivity.indices`; a Sobol' design only); ``indices`` None
        with the reason when a point is not ok or the figure does not exist everywhere."""
        from taos.montecarlo import sensitivity

        d = self.definition.design
        if d.design != "sobol":
            raise ValueError("Sobol' indices need the sobol design")
        y = self.values[metric]
        base = {"method": "sobol", "output": metric, "points": d.n, "confidence": confidence}
        bad = int(np.sum((self.status != store.STATUS["ok"]) | ~np.isfinite(y)))
        if bad:
            return base | {"indices": None, "error": f"{bad} points failed, unstable or without the figure: "
                           "the estimators need every point"}
        prob = {"num_vars": len(d.keys), "names": [k.key for k in d.keys],
                "bounds": [list(k.numbers) for k in d.keys], "dists": ["unif"] * len(d.keys)}
        rows = sensitivity.indices("sobol", prob, d.factors, y, seed=d.seed, confidence=confidence)
        return base | {"indices": rows, "warnings": sensitivity.sobol_warnings(rows, d.n // (len(d.keys) + 2))}
