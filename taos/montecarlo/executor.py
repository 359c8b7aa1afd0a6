"""Running a campaign on Dask: a LocalCluster by default, or an existing scheduler.

Every run is the pure function :func:`taos.montecarlo.run.run_one` of (campaign file, case,
friction law, run index), executed as a Dask task; its result is written to
``OUT/runs/run_NNNNNN.json`` (atomically) the moment it arrives, so an interrupted campaign
resumes where it stopped (``resume=True`` skips the stored runs). A worker that dies loses no
run: Dask re-runs its tasks elsewhere (up to ``RETRIES`` times), and a run that fails in itself
is stored with its seed, factors and reason. The statistics are computed from the stored runs
sorted by index, so the same seeds give the same statistics on any executor.

Output folder (only these names are written; anything else in it is left alone)::

    campaign.json     manifest: campaign file and hash, case, runs, seed, friction law
    runs/             one JSON per run (and nominal.json)
    summary.json      statistics (:mod:`taos.montecarlo.stats`) + provenance + timing
    campaign.h5       every run: scalars, factors, traces, envelopes, provenance
    montecarlo.png    figure-9-style plot (drawn by the ``taos montecarlo`` command)
"""

from __future__ import annotations

import json
import logging
import time
from functools import lru_cache
from pathlib import Path

import numpy as np

from taos.errors import InputError
from taos.montecarlo.campaign import Campaign, base_models, check_case, load_campaign
from taos.montecarlo.run import RunResult, run_one
from taos.montecarlo.stats import CampaignResult, summarise
from taos.results import atomic_write, package_version, write_provenance

FORMAT = "taos-montecarlo-1"
MANIFEST = "campaign.json"
OUTPUT_NAMES = (MANIFEST, "runs", "summary.json", "campaign.h5", "montecarlo.png")
RETRIES = 3
MAX_RUNS = 100_000
MAX_WORKERS = 64


@lru_cache(maxsize=4)
def _loaded(path: str, sha256: str, friction: str | None):
    """Campaign and base models, once per worker process and campaign."""
    c = load_campaign(path)
    if c.sha256 != sha256:
        raise InputError(path, "(file)", "the campaign file unchanged while the campaign runs", got="a changed file")
    return c, base_models(c, friction)


def run_task(path: str, sha256: str, case: str, friction: str | None, index: int) -> dict:
    """One run as a Dask task (module-level, so workers import it): returns the run's JSON dict."""
    c, base = _loaded(path, sha256, friction)
    return run_one(c, case, index, base=base).to_dict()


def _run_path(runs_dir: Path, index: int) -> Path:
    return runs_dir / ("nominal.json" if index < 0 else f"run_{index:06d}.json")


def _read_run(p: Path) -> RunResult | None:
    try:
        return RunResult.from_dict(json.loads(p.read_text()))
    except (OSError, ValueError, TypeError, KeyError):
        return None  # missing or unreadable: run it (again)


def _prepare_out(out: Path, manifest: dict, resume: bool) -> None:
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", "a folder for the campaign (or a new path)", got=f"{out} (a file)")
    mpath = out / MANIFEST
    if mpath.exists():
        try:
            old = json.loads(mpath.read_text())
        except (OSError, ValueError):
            raise InputError(str(mpath), "(file)", "a campaign manifest written by taos montecarlo",
                             got="an unreadable file") from None
        if not resume:
            raise InputError("command line", "--out", "a folder without a campaign in it (or --resume to continue it)",
                             got=str(out))
        same = ("format", "campaign_sha256", "case", "seed", "friction")
        diff = [k for k in same if old.get(k) != manifest[k]]
        if diff:
            raise InputError(str(mpath), diff[0], f"the same {diff[0]} to resume this campaign",
                             got=f"{manifest[diff[0]]!r} (stored: {old.get(diff[0])!r})")
    else:
        clash = [n for n in OUTPUT_NAMES if (out / n).exists()]
        if clash:
            raise InputError("command line", "--out", "a folder whose campaign file names are free "
                             "(files taos did not write are never replaced)", got=f"{out / clash[0]} exists")


def _client(workers: int | None, scheduler: str | None):
    from dask.distributed import Client, LocalCluster
    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as e:
            raise InputError("command line", "--scheduler", "the address of a running Dask scheduler",
                             got=f"{scheduler} ({type(e).__name__})") from None
    cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_campaign(c: Campaign, out_dir: str | Path, *, runs: int, case: str | None = None, friction: str | None = None,
                 workers: int | None = None, scheduler: str | None = None, resume: bool = False,
                 progress: bool = False) -> CampaignResult:
    """Run ``runs`` dispersed runs of case ``case`` (and the nominal) of campaign ``c`` into
    ``out_dir`` (module docstring); returns the statistics. ``workers`` size of the default
    LocalCluster (one thread each); ``scheduler`` an existing Dask scheduler instead."""
    if not 1 <= runs <= MAX_RUNS:
        raise InputError("command line", "--runs", f"a number of runs from 1 to {MAX_RUNS}", got=str(runs))
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise InputError("command line", "--workers", f"1 to {MAX_WORKERS} workers", got=str(workers))
    case = check_case(c, case)
    friction = friction or c.friction
    ascent, model = base_models(c, friction)  # checks files (and the law) before any work starts
    out = Path(out_dir)
    manifest = {"format": FORMAT, "campaign_file": c.source, "campaign_sha256": c.sha256, "case": case,
                "runs": runs, "seed": c.seed, "friction": friction}
    _prepare_out(out, manifest, resume)
    runs_dir = out / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    atomic_write(out / MANIFEST, lambda p: p.write_text(json.dumps(manifest, indent=2) + "\n"))
    results: dict[int, RunResult] = {}
    for i in [-1, *range(runs)]:
        r = _read_run(_run_path(runs_dir, i)) if resume else None
        if r is not None and r.index == i:
            results[i] = r
    pending = [i for i in [-1, *range(runs)] if i not in results]
    t0 = time.perf_counter()
    n_workers = None
    if pending:
        from dask.distributed import as_completed
        client, cluster = _client(workers, scheduler)
        bar = None
        try:
            n_workers = len(client.scheduler_info().get("workers", {}))
            if progress:
                from tqdm import tqdm
                bar = tqdm(total=runs + 1, initial=runs + 1 - len(pending), desc="montecarlo", unit="run")
            futs = client.map(run_task, [c.source] * len(pending), [c.sha256] * len(pending), [case] * len(pending),
                              [friction] * len(pending), pending, pure=False, retries=RETRIES)
            for fut in as_completed(futs):
                d = fut.result()
                r = RunResult.from_dict(d)
                atomic_write(_run_path(runs_dir, r.index), lambda p, d=d: p.write_text(json.dumps(d) + "\n"))
                results[r.index] = r
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
            client.close()
            if cluster is not None:
                cluster.close()
    wall = time.perf_counter() - t0
    res = summarise(c.name, case, [results[i] for i in range(runs)], results[-1], c.start_s, c.trace_interval_s)
    prov = {"campaign_file": c.source, "campaign_sha256": c.sha256, "ascent_file": ascent.source,
            "ascent_sha256": ascent.sha256, "model_file": model.source, "model_sha256": model.sha256,
            "package_version": package_version(), "seed": c.seed, "case": case, "friction_model": model.friction.name,
            "solver": {"method": "rk4-fixed-step", "dt_s": c.dt_s}, "segment_s": [c.start_s, c.start_s + c.duration_s]}
    timing = {"wall_s": wall, "runs_executed": len(pending), "workers": n_workers,
              "runs_per_s_per_worker": (len(pending) / wall / n_workers) if pending and n_workers else None,
              "executor": scheduler or "LocalCluster"}
    _write_outputs(res, out, prov, timing)
    return res


def _write_outputs(res: CampaignResult, out: Path, prov: dict, timing: dict) -> None:
    payload = {"statistics": res.summary, "provenance": prov, "timing": timing}
    atomic_write(out / "summary.json", lambda p: p.write_text(json.dumps(payload, indent=1, allow_nan=False) + "\n"))

    def h5(tmp):
        import h5py
        ok = [r for r in res.runs]
        names = sorted(res.runs[0].factors) if res.runs else []
        with h5py.File(tmp, "w") as f:
            write_provenance(f, prov)
            f.create_dataset("index", data=np.array([r.index for r in ok]))
            f.create_dataset("seed", data=np.array([r.seed for r in ok], dtype=np.int64))
            for k in ("ok", "lco"):
                f.create_dataset(k, data=np.array([getattr(r, k) for r in ok], bool))
            for k in ("amplitude_deg", "engine_amplitude_deg", "frequency_hz", "growth", "peak_engine_deg",
                      "peak_engine_rate_deg_s", "peak_attitude_deg"):
                f.create_dataset(k, data=np.array([getattr(r, k) for r in ok], float))
            fac = f.create_dataset("factors", data=np.array([[r.factors[n] for n in names] for r in ok], float)
                                   .reshape(len(ok), len(names)))
            fac.attrs["names"] = ",".join(names)
            f.create_dataset("trace_t_s", data=res.trace_t_s)
            f.create_dataset("traces_rad", data=res.traces_rad, compression="gzip")
            f.create_dataset("nominal_trace_rad", data=res.nominal_trace_rad)
            f.attrs["statistics"] = json.dumps(res.summary)
    atomic_write(out / "campaign.h5", h5)
