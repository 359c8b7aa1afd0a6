"""A flight campaign, end to end: load the inputs once, run the design on the engine, store,
summarise.

The client loads and checks every input (campaign, ascent, flight, TVC model and the files they
name) once, records the content hash of all of them (:mod:`taos.montecarlo.inputs`) and sends
the parsed inputs to the workers (:mod:`taos.montecarlo.engine`): no worker opens a project file.
The hash is in the manifest, the store and the summary; ``--resume`` refuses a campaign whose
inputs changed in any way.

Designs: ``montecarlo`` (run i draws its factors and seed from SeedSequence([seed, i])), or a
global sensitivity design (``sobol``, ``morris``: :mod:`taos.montecarlo.sensitivity`, every run
with the campaign's seed for the turbulence, so the output is a function of the factors alone).

Output folder (only these names are written; anything else in it is left alone)::

    campaign.json     manifest: inputs and their hash, case, design, runs, seed, batch size
    campaign.zarr     the store (:mod:`taos.montecarlo.store`); group "nominal": the nominal run
    summary.json      statistics (:mod:`taos.montecarlo.stats`), sensitivity, provenance, timing
    montecarlo.png    figure-9-style plot (drawn by the ``taos montecarlo`` command)

Nothing is written before the inputs are checked and the executor (LocalCluster or scheduler)
answers.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import numpy as np

from taos.errors import InputError
from taos.flight.ascent_sim import EXP_INTEGRATOR, INTEGRATOR as ASCENT_INTEGRATOR
from taos.montecarlo import engine, sensitivity, store
from taos.montecarlo.campaign import Campaign, base_models, check_case, run_factors
from taos.montecarlo.engine import Design, Part
from taos.montecarlo.inputs import digest, recording
from taos.montecarlo.run import FlightRuns
from taos.montecarlo.stats import CampaignResult, summarise
from taos.results import atomic_write, package_version
from taos.results import model_provenance

FORMAT = "taos-montecarlo-2"
MANIFEST = "campaign.json"
STORE = "campaign.zarr"
OUTPUT_NAMES = (MANIFEST, STORE, "summary.json", "montecarlo.png")
MAX_RUNS = 200_000
MAX_WORKERS = 64
DESIGNS = ("montecarlo",) + sensitivity.METHODS
SENSITIVITY_OUTPUT = "amplitude_deg"


def flight_runs(c: Campaign, case: str, friction: str | None) -> tuple[FlightRuns, list[dict]]:
    """The campaign's run kind with its inputs loaded once here, and the table of input files."""
    with recording() as files:
        ascent, model = base_models(c, friction)
    settings = json.dumps({"format": FORMAT, "campaign_sha256": c.sha256, "case": case, "friction": friction})
    sha, table = digest(files | {c.source}, settings)
    return FlightRuns(campaign=c, case=case, ascent=ascent, model=model, inputs_sha256=sha), table


def montecarlo_design(c: Campaign, runs: int) -> Design:
    """Runs 0..runs-1: factors and seeds from SeedSequence([campaign seed, index])."""
    names = tuple(d.name for d in c.dispersions)
    seeds, rows = np.empty(runs, np.int64), np.empty((runs, len(names)))
    for i in range(runs):
        s, f = run_factors(c, i)
        seeds[i], rows[i] = s, [f[k] for k in names]
    return Design(names, rows, seeds)


def nominal_design(c: Campaign) -> Design:
    names = tuple(d.name for d in c.dispersions)
    return Design(names, np.ones((1, len(names))), np.array([c.seed]))


def sensitivity_design(c: Campaign, method: str, n: int) -> Design:
    if not c.dispersions:
        raise InputError(c.source, "dispersions", "at least one dispersion for a sensitivity analysis", got="none")
    if method == "sobol" and (n < 2 or n & (n - 1)):
        raise InputError("command line", "--runs", "a power of two (the Sobol' base sample N; N (k + 2) runs)",
                         got=str(n))
    x = sensitivity.design(method, sensitivity.problem(c.dispersions), n, seed=c.seed % 2 ** 32)
    return Design(tuple(d.name for d in c.dispersions), x, np.full(len(x), c.seed))


def _check_out(out: Path, manifest: dict, resume: bool) -> dict | None:
    """The stored manifest when resuming (None for a new campaign); refuses, before any write,
    a folder that is a file, a campaign without --resume and a resume with other inputs."""
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", "a folder for the campaign (or a new path)", got=f"{out} (a file)")
    mpath = out / MANIFEST
    if not mpath.exists():
        clash = [n for n in OUTPUT_NAMES if (out / n).exists()]
        if clash:
            raise InputError("command line", "--out", "a folder whose campaign file names are free "
                             "(files taos did not write are never replaced)", got=f"{out / clash[0]} exists")
        return None
    try:
        old = json.loads(mpath.read_text())
    except (OSError, ValueError):
        raise InputError(str(mpath), "(file)", "a campaign manifest written by taos montecarlo",
                         got="an unreadable file") from None
    if not resume:
        raise InputError("command line", "--out", "a folder without a campaign in it (or --resume to continue it)",
                         got=str(out))
    for k in ("format", "inputs_sha256", "case", "seed", "friction", "design", "runs", "design_sha256"):
        if old.get(k) != manifest[k]:
            what = "inputs (a file changed)" if k == "inputs_sha256" else k
            raise InputError(str(mpath), k, f"the same {what} to resume this campaign",
                             got=f"{manifest[k]!r} (stored: {old.get(k)!r})")
    return old


def _check_args(c, out_dir, runs, case, friction, workers, scheduler, resume, progress, batch, connect_timeout_s):
    """:func:`run_campaign`'s arguments, each refused naming it (with its command-line flag) before
    any model is loaded: a Campaign, a folder place (never under a regular file), whole numbers
    of runs, workers and runs per task in range, True or False, a connection timeout of 0.1 to 600 s."""
    from taos.bounds import check_count, check_flag, check_instance, check_number
    from taos.errors import as_argument, check_path_arg
    from taos.results import check_output_file

    check_instance(c, "c", Campaign, "a Campaign (taos.load_campaign)")
    folder = lambda: check_output_file(Path(check_path_arg(out_dir, "out_dir", "a campaign folder")) / "x", "out_dir")  # noqa: E731
    checks = [("out_dir", "--out", folder),
              ("runs", "--runs", lambda: check_count(runs, "runs", 1, MAX_RUNS)),
              ("workers", "--workers", lambda: workers is None or check_count(workers, "workers", 0, MAX_WORKERS)),
              ("batch", "--batch", lambda: batch is None or check_count(batch, "batch", 1, engine.MAX_BATCH)),
              ("connect_timeout_s", "--connect-timeout",
               lambda: check_number(connect_timeout_s, "connect_timeout_s", 0.1, 600.0, "s"))]
    for field, flag, check in checks:
        try:
            check()
        except InputError as e:
            raise as_argument(e, field, flag) from None
    for field, v in (("case", case), ("friction", friction), ("scheduler", scheduler)):
        if v is not None and not (isinstance(v, str) and v):
            raise InputError("argument", field, "None or a name (text)", got=repr(v)[:40])
    check_flag(resume, "resume")
    check_flag(progress, "progress")


def run_campaign(c: Campaign, out_dir: str | Path, *, runs: int, case: str | None = None, friction: str | None = None,
                 workers: int | None = None, scheduler: str | None = None, resume: bool = False,
                 progress: bool = False, design: str = "montecarlo", batch: int | None = None,
                 connect_timeout_s: float = engine.CONNECT_TIMEOUT_S) -> CampaignResult:
    """Run ``runs`` dispersed runs (or, for ``design`` "sobol"/"morris", the sensitivity design
    of ``runs`` base samples / trajectories) of case ``case`` and the nominal into ``out_dir``
    (module docstring); returns the statistics. ``workers``: size of the default LocalCluster (one
    thread each; 0: in this process); ``scheduler``: an existing Dask scheduler instead;
    ``batch``: runs per task (default from the run cost)."""
    _check_args(c, out_dir, runs, case, friction, workers, scheduler, resume, progress, batch, connect_timeout_s)
    if design not in DESIGNS:
        raise InputError("command line", "--sensitivity", "one of " + ", ".join(sensitivity.METHODS), got=repr(design))
    if not 1 <= runs <= MAX_RUNS:
        raise InputError("command line", "--runs", f"a number of runs from 1 to {MAX_RUNS}", got=str(runs))
    if workers is not None and not 0 <= workers <= MAX_WORKERS:
        raise InputError("command line", "--workers", f"1 to {MAX_WORKERS} workers", got=str(workers))
    if batch is not None and not 1 <= batch <= engine.MAX_BATCH:
        raise InputError("command line", "--batch", f"1 to {engine.MAX_BATCH} runs per task", got=str(batch))
    if not 0.1 <= connect_timeout_s <= 600:
        raise InputError("command line", "--connect-timeout", "0.1 to 600 s", got=str(connect_timeout_s))
    case = check_case(c, case)
    friction = friction or c.friction
    kind, table = flight_runs(c, case, friction)  # every input checked before any work starts
    d = montecarlo_design(c, runs) if design == "montecarlo" else sensitivity_design(c, design, runs)
    if d.n > MAX_RUNS:
        raise InputError("command line", "--runs", f"a design of at most {MAX_RUNS} runs", got=f"{d.n} runs")
    out = Path(out_dir)
    manifest = {"format": FORMAT, "campaign_file": c.source, "inputs_sha256": kind.inputs_sha256,
                "input_files": table, "case": case, "seed": c.seed, "friction": friction, "design": design,
                "runs": runs, "design_runs": d.n, "design_sha256": d.sha256()}
    old = _check_out(out, manifest, resume)
    parts = [Part("nominal", nominal_design(c)), Part(None, d)]
    spath = out / STORE
    t0 = time.perf_counter()
    with engine.connected(2 if workers is None else workers, scheduler, connect_timeout_s) as client:
        n_workers = len(client.scheduler_info().get("workers", {})) if client is not None else 0
        if old is not None and store.status(spath) is not None and store.status(spath, "nominal") is not None:
            manifest["batch"] = int(old["batch"])
        else:
            manifest["batch"] = batch or engine.batch_size(d.n, kind.run_cost_s, max(n_workers, 1))
            out.mkdir(parents=True, exist_ok=True)
            if spath.exists():  # a store this campaign began (its manifest is ours) but could not finish creating
                shutil.rmtree(spath)
            attrs = {"format": FORMAT, "inputs_sha256": kind.inputs_sha256, "campaign": c.name, "case": case,
                     "design": design, "seed": c.seed, "friction_model": kind.model.friction.name,
                     "sanity_bound_engine_deg": kind.gimbal_range_deg}
            atomic_write(out / MANIFEST, lambda q: q.write_text(json.dumps(manifest, indent=1) + "\n"))
            for p in sorted(parts, key=lambda q: q.group is not None):  # the root group first
                store.create(spath, labels=np.arange(p.design.n), names=p.design.names, factors=p.design.factors,
                             seeds=p.design.seeds, scalars=kind.scalars, flags=kind.flags, trace_t_s=kind.trace_t_s,
                             batch=manifest["batch"], attrs=attrs, group=p.group)
        executed = engine.execute(spath, kind, parts, manifest["batch"], client, progress=progress)
    wall = time.perf_counter() - t0
    ds, nom = store.open_store(spath, dask=False), store.open_store(spath, "nominal", dask=False)
    flown = {str(v) for g in (ds, nom) for v in np.unique(g["inputs_sha256"].values)}
    if flown != {kind.inputs_sha256}:
        raise RuntimeError(f"the store holds runs flown with other inputs: {sorted(flown)}")
    res = summarise(c.name, case, ds, nom)
    sens = None
    if design != "montecarlo":
        sens = _sensitivity(c, design, ds)
    prov = {"campaign_file": c.source, "campaign_sha256": c.sha256, "inputs_sha256": kind.inputs_sha256,
            "input_files": table, "ascent_sha256": kind.ascent.sha256, **model_provenance(kind.model),
            "package_version": package_version(), "code_sha256": engine.code_sha256(), "seed": c.seed, "case": case,
            "design": design,
            "friction_model": kind.model.friction.name, "solver": {"method": EXP_INTEGRATOR if c.integrator == "etdrk4" else ASCENT_INTEGRATOR,
                                                          "dt_s": c.dt_s},
            "segment_s": [c.start_s, c.start_s + c.duration_s],
            "cpu_targets": sorted({str(v) for v in np.unique(ds["cpu"].values)} - {""})}
    timing = {"wall_s": wall, "runs_executed": executed, "workers": n_workers or None, "batch": manifest["batch"],
              "runs_per_s_per_worker": (executed / wall / n_workers) if executed and n_workers else None,
              "executor": scheduler or ("in-process" if workers == 0 else "LocalCluster")}
    payload = {"statistics": res.summary, "sensitivity": sens, "provenance": prov, "timing": timing}
    text = json.dumps(payload, indent=1, allow_nan=False) + "\n"
    atomic_write(out / "summary.json", lambda q: q.write_text(text))
    return res


def _sensitivity(c: Campaign, method: str, ds) -> dict:
    st = np.asarray(ds["status"].values)
    y = np.asarray(ds[SENSITIVITY_OUTPUT].values, float)
    base = {"method": method, "output": SENSITIVITY_OUTPUT, "runs": int(len(y)), "confidence": 0.95}
    bad = int(np.sum(st != store.STATUS["ok"]))
    if bad:
        return base | {"indices": None, "error": f"{bad} runs failed or diverged: the estimators need every run"}
    prob = sensitivity.problem(c.dispersions)
    rows = sensitivity.indices(method, prob, np.asarray(ds["factor"].values), y, seed=c.seed % 2 ** 32)
    warn = sensitivity.sobol_warnings(rows, len(y) // (len(rows) + 2)) if method == "sobol" else []
    return base | {"indices": rows, "warnings": warn}
