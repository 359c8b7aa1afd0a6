"""Issue 40, the cluster's failure modes: workers with other code refused, a paused or dying
worker and a lost scheduler reported with the runs kept and the resume line, SIGTERM reported
truthfully, statistics that warn when they cannot be trusted, diverged runs in the headline, a
self-describing (CF) store with NaN for the runs not done, the scheduler address forms and
``--scheduler-file``, and the dask-jobqueue recipe of docs/guide/montecarlo.md."""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from taos.cli import main
from taos.cli.montecarlo import scheduler_address
from taos.errors import InputError
from taos.montecarlo import Design, Ishigami, engine, load_campaign, run_campaign, run_design, store
from taos.montecarlo import sensitivity as sens
from taos.montecarlo.run import FLAGS, SCALARS
from taos.montecarlo.stats import spearman, spearman_exact_p, summarise

from tests import _daskproc, _forkserver
from tests.test_montecarlo import ROOT, SHORT

BIN = Path(sys.executable).parent


@dataclass(frozen=True)
class Slow:
    """A run kind that takes ``delay_s`` per batch: y = the sum of the factors, flag ``big``
    when y > 10 (a campaign slow enough to stop in the middle)."""

    delay_s: float = 0.3
    scalars: tuple = ("y",)
    flags: tuple = ("big",)
    run_cost_s: float = 0.1
    inputs_sha256: str = "slow"
    kill_when: str | None = None   # a file whose existence makes a batch kill its worker process

    @property
    def trace_t_s(self) -> np.ndarray:
        return np.zeros(0)

    def run_batch(self, names, factors, seeds) -> dict:
        if self.kill_when is not None and os.path.exists(self.kill_when):
            os._exit(17)   # a worker dying mid-batch (out of memory, killed by the batch system)
        time.sleep(self.delay_s)
        n, y = len(seeds), factors.sum(axis=1)
        return {"status": np.full(n, store.STATUS["ok"], np.int8), "error": [""] * n, "y": y, "big": y > 10,
                "trace": np.zeros((n, 0))}


def _design(n: int = 24) -> Design:
    return Design(("x",), np.arange(float(n))[:, None], np.zeros(n, np.int64))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(procs) -> None:
    for p in procs:
        if p.poll() is None:
            p.kill()
        p.wait()


def _scheduler(tmp: Path, env=None, workers: int = 1, scheduler_file: Path | None = None):
    """A scheduler and one-thread workers (no nanny) as processes on loopback (``dask scheduler``
    and ``dask worker``: :mod:`tests._daskproc`; workers with their own ``env``, which a worker's
    interpreter reads at its start, e.g. ``PYTHONPATH``, as new processes of that environment)."""
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    sched = _daskproc.start("scheduler", ["--host", "127.0.0.1", "--port", str(port), "--no-dashboard",
                                          *(["--scheduler-file", str(scheduler_file)] if scheduler_file else [])])
    wargs = [addr, "--nthreads", "1", "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"]
    if env is None:
        ws = [_daskproc.start("worker", wargs, cwd=tmp) for _ in range(workers)]
    else:
        ws = [subprocess.Popen([str(BIN / "dask"), "worker", *wargs], stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, env=env, cwd=tmp) for _ in range(workers)]
    from dask.distributed import Client
    deadline = time.time() + 90
    while True:
        try:
            with Client(addr, timeout="5s") as c:
                c.wait_for_workers(workers, timeout=30)
            return addr, sched, ws
        except Exception:
            if time.time() > deadline:
                _stop([sched, *ws])
                raise
            time.sleep(0.5)


def _stored(path: Path, group=None) -> int:
    st = store.status(path, group)
    return 0 if st is None else int((st != store.STATUS["pending"]).sum())


# -- a self-describing store ------------------------------------------------------------------------

def _flight_store(path: Path, status, lco, amp, batch: int = 2, written: int | None = None) -> None:
    """A store in the flight runs' layout (taos.montecarlo.run) with the first ``written`` rows
    written batch by batch as the engine writes them."""
    n = len(status)
    store.create(path, labels=np.arange(n), names=("wind",), factors=np.linspace(0.5, 1.5, n)[:, None],
                 seeds=np.arange(n), scalars=SCALARS, flags=FLAGS, trace_t_s=np.linspace(0.0, 2.0, 3), batch=batch,
                 attrs={"inputs_sha256": "x"})
    for s in range(0, n if written is None else written, batch):
        sl = slice(s, s + batch)
        m = len(status[sl])
        out = {k: np.full(m, 0.5) for k in SCALARS} | {"amplitude_deg": np.asarray(amp[sl], float),
                                                       "lco": np.asarray(lco[sl], bool),
                                                       "trace": np.full((m, 3), 0.01), "error": [""] * m,
                                                       "cpu": ["c"] * m, "inputs_sha256": ["x"] * m,
                                                       "status": np.asarray(status[sl], np.int8)}
        store.write_batch(path, s, out)


def test_store_is_cf_self_describing_and_nan_for_runs_not_done(tmp_path):
    """Opened with xarray and cf_xarray: units in UDUNITS spelling from each name's suffix (the
    trace in rad, the scalars in degree, Hz, degree s-1), a long name on every variable, time as
    the CF time axis; a store with 4 of 8 runs written reads NaN for the 4 not run in every
    float output and in the ``lco`` flag, so ``ds.lco.mean()`` is the fraction over the runs
    done (3 of 4 = 0.75, never 3 of 8)."""
    import cf_xarray  # noqa: F401 - registers the .cf accessor
    import xarray as xr
    p = tmp_path / "s.zarr"
    _flight_store(p, [1] * 8, [1, 1, 0, 1, 1, 1, 1, 1], np.arange(8.0), written=4)
    ds = xr.open_zarr(p, zarr_format=2)
    assert ds.attrs["Conventions"].startswith("CF-")
    want = {"trace": "rad", "amplitude_deg": "degree", "engine_amplitude_deg": "degree", "frequency_hz": "Hz",
            "peak_engine_rate_deg_s": "degree s-1", "peak_attitude_deg": "degree", "time": "s"}
    assert {k: ds[k].attrs.get("units") for k in want} == want
    assert "units" not in ds["growth"].attrs and "units" not in ds["lco"].attrs
    assert all(ds[k].attrs.get("long_name") for k in ds.variables)
    assert ds.cf.standard_names == {"time": ["time"]} and ds.cf.axes == {"T": ["time"]}
    assert ds.cf["time"].name == "time"
    lco = ds["lco"].values
    assert np.array_equal(lco[:4], [1, 1, 0, 1]) and np.isnan(lco[4:]).all()
    assert float(ds["lco"].mean()) == pytest.approx(0.75)
    assert np.isnan(ds["amplitude_deg"].values[4:]).all() and np.isnan(ds["trace"].values[4:]).all()
    assert (ds["status"].values[4:] == store.STATUS["pending"]).all()


def test_an_interrupted_campaign_store_reads_nan_for_the_runs_not_done(tmp_path, monkeypatch):
    """A real flight campaign stopped after its first batch (an interrupt inside the write of
    the second): the nominal and 2 runs stored, the other 2 read NaN (lco too) and pending."""
    import xarray as xr
    real, calls = store.write_batch, []

    def write_then_stop(path, start, out, group=None):
        calls.append(start)
        if len(calls) == 3:
            raise KeyboardInterrupt
        real(path, start, out, group)
    monkeypatch.setattr(store, "write_batch", write_then_stop)
    with pytest.raises(KeyboardInterrupt):
        run_campaign(load_campaign(SHORT), tmp_path / "mc", runs=4, workers=0, batch=2)
    ds = xr.open_zarr(tmp_path / "mc" / "campaign.zarr", zarr_format=2)
    st = ds["status"].values
    assert (st[:2] == store.STATUS["ok"]).all() and (st[2:] == store.STATUS["pending"]).all()
    assert np.isin(ds["lco"].values[:2], [0, 1]).all() and np.isnan(ds["lco"].values[2:]).all()
    assert np.isfinite(ds["amplitude_deg"].values[:2]).all() and np.isnan(ds["amplitude_deg"].values[2:]).all()
    assert ds["amplitude_deg"].attrs["units"] == "degree" and ds["trace"].attrs["units"] == "rad"


# -- statistics that warn ----------------------------------------------------------------------------

def test_spearman_exact_p_matches_a_brute_force_permutation_test():
    """The exact p-value (the share of orderings with |rho| at least the observed one) against
    scipy's rho over all 6! orderings of y, one by one (an independent implementation), with
    ties."""
    from scipy.stats import spearmanr
    rng = np.random.default_rng(3)
    x, y = rng.normal(size=6), np.array([1.0, 2.0, 2.0, 5.0, 3.0, 9.0])
    obs = abs(spearmanr(x, y)[0])
    hits = [abs(spearmanr(x, y[list(q)])[0]) >= obs - 1e-12 for q in itertools.permutations(range(6))]
    ref = sum(hits) / math.factorial(6)
    assert spearman_exact_p(x, y) == pytest.approx(ref, abs=1e-12)


def test_spearman_on_four_runs_calls_nothing_significant():
    """The hostile case: 4 runs, 4 factors (one with no effect), a perfect rank order for three
    of them. The exact two-sided p of rho = 1 on 4 pairs is 2/24 = 0.083; Holm over 4 factors
    makes it 0.33: nothing is significant (scipy's t approximation gave p = 0)."""
    f = np.array([[1, 1, 1, 3.0], [2, 2, 2, 1.0], [3, 3, 3, 4.0], [4, 4, 4, 2.0]])
    y = np.array([0.1, 0.2, 0.3, 0.4])
    rows = spearman(["a", "b", "c", "none"], f, y)
    assert not any(r["significant"] for r in rows)
    top = [r for r in rows if r["parameter"] == "a"][0]
    assert top["p_value"] == pytest.approx(2 / 24) and top["p_holm"] == pytest.approx(min(1.0, 4 * 2 / 24))
    assert top["p_method"] == "exact permutation"


def test_headline_counts_diverged_runs_and_warns(tmp_path):
    """Half the runs hit the stops: the headline does not say "100 % LCO" alone; it counts the
    2 diverged runs and gives the fraction over all runs as 50-100 %; warnings name the diverged
    runs and the small n (Wilson interval of 2 of 2: 34.2-100 %, E. B. Wilson 1927)."""
    p = tmp_path / "s.zarr"
    _flight_store(p, [1, 3, 1, 3], [1, 0, 1, 0], [0.2, np.nan, 0.3, np.nan])
    nom = tmp_path / "n.zarr"
    _flight_store(nom, [1], [1], [0.25], batch=1)
    res = summarise("t", "soft", store.open_store(p, dask=False), store.open_store(nom, dask=False))
    s = res.summary
    assert s["runs_diverged"] == 2 and s["runs_lco"] == 2 and s["runs_ok"] == 2
    assert s["headline"].startswith("4 runs: 2 limit cycle, 0 none, 2 diverged (hard stops)")
    assert "over all 4 runs between 50.0 and 100.0 %" in s["headline"]
    assert "CI 34.2-100.0 %" in s["headline"]
    w = " | ".join(s["warnings"])
    assert "2 of 4 runs diverged or failed" in w and "fewer than 100" in w and "no distribution-free" in w


def test_sobol_at_small_n_warns_and_at_large_n_matches_ishigami_without_warning():
    """Ishigami (closed-form indices, Saltelli et al. 2008): at N = 16 the estimates break the
    bounds 0 <= S1 <= ST, sum S1 <= 1 or have intervals wider than 0.1 and are warned about,
    each warning saying N is too small; at N = 4096 there is no warning and every index lies
    within 3 half-widths (+ 0.01) of the exact value."""
    k, prob = Ishigami(), Ishigami.problem()
    exact = k.analytic_indices()
    for seed in (1, 2):
        x = sens.design("sobol", prob, 16, seed=seed)
        rows = sens.indices("sobol", prob, x, k.run_batch(("x1", "x2", "x3"), x, np.zeros(len(x)))["y"], seed=seed)
        w = sens.sobol_warnings(rows, 16)
        assert w and all("N = 16: N is too small" in t for t in w)
    x = sens.design("sobol", prob, 4096, seed=1)
    rows = sens.indices("sobol", prob, x, k.run_batch(("x1", "x2", "x3"), x, np.zeros(len(x)))["y"], seed=1)
    assert sens.sobol_warnings(rows, 4096) == []
    for r in rows:
        i = ("x1", "x2", "x3").index(r["parameter"])
        for key in ("S1", "ST"):
            assert abs(r[key] - exact[key][i]) < 3 * r[f"{key}_conf"] + 0.01, (r, key)


def test_sobol_warnings_name_each_broken_bound():
    rows = [{"parameter": "a", "S1": 0.9, "S1_conf": 0.02, "ST": 0.5, "ST_conf": 0.02},
            {"parameter": "b", "S1": 0.5, "S1_conf": 0.02, "ST": -0.2, "ST_conf": 0.05}]
    w = sens.sobol_warnings(rows, 64)
    assert any("sum to 1.4 > 1 beyond its interval" in t for t in w)
    assert any(t.startswith("a: S1 0.9 > ST 0.5 beyond") for t in w)
    assert any(t.startswith("b: ST -0.2 < 0 beyond") for t in w)


# -- code identity ------------------------------------------------------------------------------------

def test_a_batch_on_a_worker_with_other_code_is_refused_there():
    d = _design(4)
    out = engine.run_task(Ishigami(), ("x1", "x2", "x3"), np.zeros((4, 3)), d.seeds, engine.code_identity())
    assert (out["status"] == store.STATUS["ok"]).all()
    other = engine.code_identity() | {"code_sha256": "0" * 64}
    with pytest.raises(engine.WorkerCodeMismatch, match="0000000000000000"):
        engine.run_task(Ishigami(), ("x1", "x2", "x3"), np.zeros((4, 3)), d.seeds, other)


# -- scheduler addresses ---------------------------------------------------------------------------

@pytest.mark.parametrize("text, want", [
    ("tcp://10.0.0.5:8786", "tcp://10.0.0.5:8786"), ("10.0.0.5:8786", "tcp://10.0.0.5:8786"),
    ("tls://sched.example:8786", "tls://sched.example:8786"), ("tcp://[::1]:8786", "tcp://[::1]:8786"),
    ("[::1]:8786", "tcp://[::1]:8786"), ("node7", "tcp://node7:8786")])
def test_scheduler_address_forms_dask_accepts(text, want):
    assert scheduler_address(text) == want


@pytest.mark.parametrize("text, why", [("inproc://10.0.0.5/1/2", "inproc"), ("ucx://h:1", "ucx"),
                                       ("tcp://127.0.0.1:99999", "port 1 to 65535"), ("tcp://:8786", ""),
                                       ("tcp://a b:1", "")])
def test_bad_scheduler_addresses_one_line_exit_2(tmp_path, capsys, text, why):
    out = tmp_path / "out"
    assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler", text, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler" in err[0] and why in err[0], err
    assert not out.exists()


@pytest.mark.parametrize("content, field", [("not json", "(file)"), ('{"type": "Scheduler"}', "address"),
                                            ('{"address": "inproc://x/1/2"}', "address"), (None, "(file)")])
def test_bad_scheduler_files_one_line_exit_2(tmp_path, capsys, content, field):
    f = tmp_path / "scheduler.json"
    if content is not None:
        f.write_text(content)
    out = tmp_path / "out"
    assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler-file", str(f), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(f) in err[0] and field in err[0], err
    assert not out.exists()


def test_scheduler_file_with_a_dead_address_refused_in_time(tmp_path, capsys):
    f = tmp_path / "scheduler.json"
    f.write_text(json.dumps({"type": "Scheduler", "address": f"tcp://127.0.0.1:{_free_port()}"}))
    t0 = time.perf_counter()
    assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler-file", str(f), "--connect-timeout", "2",
                 "--out", str(tmp_path / "out")]) == 2
    assert time.perf_counter() - t0 < 20
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "answering within 2 s" in err[0], err
    assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler-file", str(f), "--workers", "2",
                 "--out", str(tmp_path / "out")]) == 2
    assert "one of --workers, --scheduler, --scheduler-file" in capsys.readouterr().err


@pytest.mark.slow
def test_scheduler_file_and_bare_address_run_a_campaign(tmp_path, capsys):
    """A LocalCluster whose scheduler writes Dask's scheduler file: ``--scheduler-file`` runs
    the campaign; the same scheduler as a bare ``host:port`` runs a design through the engine."""
    from dask.distributed import LocalCluster
    f = tmp_path / "scheduler.json"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", dashboard_address=":0",
                      scheduler_kwargs={"scheduler_file": str(f)}) as cluster:
        assert json.loads(f.read_text())["address"] == cluster.scheduler_address
        out = tmp_path / "mc"
        assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler-file", str(f), "--out", str(out),
                     "--no-progress"]) == 0
        assert _stored(out / "campaign.zarr") == 2
        bare = cluster.scheduler_address.removeprefix("tcp://")
        ds = run_design(Ishigami(), Design(("x1", "x2", "x3"), np.zeros((4, 3)), np.zeros(4, np.int64)),
                        tmp_path / "i.zarr", scheduler=scheduler_address(bare), batch=2)
        assert (ds["status"].values == store.STATUS["ok"]).all()
    assert "4 runs" not in capsys.readouterr().err


# -- workers with other code ---------------------------------------------------------------------------

@pytest.mark.slow
def test_a_worker_running_other_taos_code_is_refused_naming_both(tmp_path, capsys):
    """A worker importing a copy of taos with one comment added (PYTHONPATH): the campaign is
    refused before anything is written, one line naming the worker's code hash and the
    client's; the engine refuses it the same way."""
    alt = tmp_path / "alt"
    shutil.copytree(ROOT / "taos", alt / "taos", ignore=shutil.ignore_patterns("__pycache__"))
    with open(alt / "taos" / "montecarlo" / "stats.py", "a") as fh:
        fh.write("# a worker with other code\n")
    env = dict(os.environ, PYTHONPATH=str(alt))
    addr, sched, ws = _scheduler(tmp_path, env=env)
    out = tmp_path / "mc"
    try:
        mine = engine.code_sha256()[:16]
        from dask.distributed import Client
        with Client(addr, timeout="10s") as c:
            theirs = c.run(engine.code_identity)
            assert [v["code_sha256"] != engine.code_sha256() for v in theirs.values()] == [True]
            with pytest.raises(InputError, match="code sha256"):
                engine.check_workers(c)
        assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler", addr, "--out", str(out)]) == 2
    finally:
        _stop([*ws, sched])
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and mine in err[0], err
    other = next(iter(theirs.values()))["code_sha256"][:16]
    assert other in err[0] and "worker tcp://127.0.0.1" in err[0]
    assert not out.exists()


# -- a paused worker, a dying worker, a lost scheduler, SIGTERM -----------------------------------------

def _when_stored(path: Path, n: int, then, timeout_s: float = 120) -> threading.Thread:
    def go():
        _daskproc.wait_stored(lambda: _stored(path), path / "status", n, timeout_s=timeout_s)
        then()
    th = threading.Thread(target=go, daemon=True)
    th.start()
    return th


@pytest.mark.slow
def test_a_paused_worker_stops_the_campaign_with_the_runs_kept(tmp_path, monkeypatch):
    """The only worker paused by Dask's memory monitor (its memory limit lowered under its
    process memory mid-campaign, as an out-of-memory worker is): after ``STALL_S`` without a
    batch the campaign stops with one line naming the paused worker; the batches stored stay,
    and a resume finishes the store with the values an uninterrupted run gives."""
    from dask.distributed import Client, LocalCluster
    monkeypatch.setattr(engine, "STALL_S", 3.0)
    p = tmp_path / "s.zarr"
    d = _design(24)

    def starve(dask_worker):
        dask_worker.memory_manager.memory_limit = 1   # the monitor pauses it at its next tick

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        with Client(cluster) as c:
            _when_stored(p, 4, lambda: c.run(starve))
            with pytest.raises(engine.CampaignStopped, match="paused") as e:
                run_design(Slow(), d, p, scheduler=cluster.scheduler_address, batch=2)
    assert "1 of 1 workers are paused" in str(e.value) and "\n" not in str(e.value)
    done = _stored(p)
    assert 4 <= done < 24
    ds = run_design(Slow(delay_s=0.0), d, p, workers=0, resume=True)
    assert (ds["status"].values == store.STATUS["ok"]).all()
    assert np.array_equal(ds["y"].values, np.arange(24.0)) and np.array_equal(ds["big"].values, np.arange(24) > 10)


@pytest.mark.slow
def test_a_batch_that_kills_its_workers_stops_the_campaign_with_the_runs_kept(tmp_path):
    """Once 4 runs are stored, every batch kills the worker process running it (os._exit, as
    the out-of-memory killer does): Dask gives up on the batch (KilledWorker) and the campaign
    stops with one line; the batches stored before stay (a batch finished but not yet fetched
    dies with its worker), and a resume finishes the store."""
    import cloudpickle
    import dask
    from dask.distributed import LocalCluster
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    p, flag = tmp_path / "s.zarr", tmp_path / "kill"
    env = dict(os.environ)   # (the nanny sets its workers' OMP_NUM_THREADS, ... here: put back below, so
    try:                     # that the fork server's commands after this test need no new zygote)
        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
                _when_stored(p, 4, flag.touch)   # from the 3rd stored batch on, every batch kills its worker
                with pytest.raises(engine.CampaignStopped, match="KilledWorker") as e:
                    run_design(Slow(delay_s=0.3, kill_when=str(flag)), _design(24), p,
                               scheduler=cluster.scheduler_address, batch=2)
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
        os.environ.clear()
        os.environ.update(env)
    assert "workers died running the batch at run" in str(e.value) and "\n" not in str(e.value)
    st = store.status(p)   # (a batch finished but not yet fetched when its worker died is lost with it)
    assert 4 <= (st == store.STATUS["ok"]).sum() < 24
    ds = run_design(Slow(delay_s=0.0), _design(24), p, workers=0, resume=True)
    assert np.array_equal(ds["y"].values, np.arange(24.0))


def _resume_line(err: str) -> list[str]:
    m = re.search(r"continue with: (taos montecarlo .*--resume)$", err.strip())
    assert m, err
    return shlex.split(m.group(1))[1:]


@pytest.mark.slow
def test_scheduler_loss_is_one_line_with_the_runs_kept_and_the_resume_line(tmp_path):
    """The scheduler killed mid-campaign: the taos process ends with exit 2 and one line
    saying the scheduler was lost, how many runs are stored and the exact command to resume
    (never "internal error: ClosedClientError"); the store reads; that command on a new
    scheduler at the same address finishes the campaign."""
    addr, sched, ws = _scheduler(tmp_path, workers=1)
    out = tmp_path / "mc"
    try:
        p = _forkserver.popen([str(BIN / "taos"), "montecarlo", str(SHORT), "--runs", "10", "--scheduler", addr,
                               "--batch", "2", "--connect-timeout", "3", "--out", str(out), "--no-progress"], ROOT)
        _daskproc.wait_stored(lambda: _stored(out / "campaign.zarr"), out / "campaign.zarr" / "status", 4,
                              lambda: p.poll() is None)
        sched.kill()
        _, err = _daskproc.communicate(p, 120)
    finally:
        _stop([*ws, sched])
    assert p.returncode == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "scheduler was lost" in lines[0] and "internal error" not in lines[0], err
    n = _stored(out / "campaign.zarr")
    assert f"{n + _stored(out / 'campaign.zarr', 'nominal')} of 11 runs stored" in lines[0]
    argv = _resume_line(lines[0])
    assert argv[argv.index("--scheduler") + 1] == addr
    # resumed on this machine's workers in place of the lost scheduler (the manifest does not
    # bind the executor)
    argv[argv.index("--scheduler"):argv.index("--scheduler") + 2] = ["--workers", "1"]
    assert main(argv + ["--no-progress"]) == 0
    assert _stored(out / "campaign.zarr") == 10


@pytest.mark.slow
def test_sigterm_says_how_many_runs_are_kept_and_how_to_resume(tmp_path):
    """SIGTERM (a batch system's time limit) mid-campaign: exit 143 and one line saying how
    many runs the store keeps and the resume command (not "no partial output written"); the
    resume command finishes the campaign."""
    out = tmp_path / "mc"
    p = _forkserver.popen([str(BIN / "taos"), "montecarlo", str(SHORT), "--runs", "8", "--workers", "1", "--batch", "2",
                           "--out", str(out), "--no-progress"], ROOT)
    _daskproc.wait_stored(lambda: _stored(out / "campaign.zarr"), out / "campaign.zarr" / "status", 2,
                          lambda: p.poll() is None)
    p.send_signal(signal.SIGTERM)
    _, err = _daskproc.communicate(p, 120)
    assert p.returncode == 143, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("taos: terminated (signal 15); "), err
    assert "no partial output" not in lines[0]
    n = _stored(out / "campaign.zarr") + _stored(out / "campaign.zarr", "nominal")
    assert f"{n} of 9 runs stored in {out / 'campaign.zarr'} (kept)" in lines[0]
    argv = _resume_line(lines[0])
    assert argv[-1] == "--resume" and argv[argv.index("--out") + 1] == str(out)
    assert main(argv + ["--no-progress"]) == 0
    assert _stored(out / "campaign.zarr") == 8


# -- the dask-jobqueue recipe ---------------------------------------------------------------------------

def _recipe() -> str:
    text = (ROOT / "docs" / "guide" / "montecarlo.md").read_text()
    m = re.search(r"```python\n(# slurm_workers\.py.*?)```", text, re.S)
    assert m, "the SLURM recipe is in docs/guide/montecarlo.md"
    return m.group(1)


def test_the_documented_slurm_recipe_builds_the_job_script_it_describes(tmp_path, monkeypatch):
    """The recipe of docs/guide/montecarlo.md, run up to the cluster's creation (no SLURM: the
    job script only): one single-threaded worker per job with the documented memory, the numba
    cache on node-local disk, the warm-up and the taos version check in the prologue."""
    pytest.importorskip("dask_jobqueue")
    import dask
    code = _recipe().split("cluster.scale(")[0]
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    with dask.config.set({"distributed.scheduler.dashboard-address": ":0"}):
        exec(compile(code, "slurm_workers.py", "exec"), ns)   # noqa: S102 - the documentation's own code
    cluster = ns["cluster"]
    try:
        script = cluster.job_script()
        assert json.loads((tmp_path / "scheduler.json").read_text())["address"] == cluster.scheduler_address
    finally:
        cluster.close()
    head = [ln for ln in script.splitlines() if ln.startswith("#SBATCH")]
    assert {"#SBATCH --cpus-per-task=1", "#SBATCH --mem=2G", "#SBATCH -t 04:00:00",
            "#SBATCH --constraint=x86_64"} <= set(head), script
    worker = script.strip().splitlines()[-1]
    assert "--nthreads 1" in worker and "--memory-limit 1.86GiB" in worker, worker
    pro = script.split("\n".join(head))[1].split(worker)[0]
    assert "export NUMBA_CACHE_DIR=" in pro and "python -m taos.cli.warmup" in pro, pro
    assert pro.index("NUMBA_CACHE_DIR") < pro.index("taos.cli.warmup")
