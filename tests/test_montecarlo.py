"""Monte Carlo campaigns on Dask: reproducible on any executor, resumable, no run lost."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from taos.cli import main
from taos.montecarlo import load_campaign, run_campaign, wilson_interval
from taos.montecarlo.campaign import run_factors

DATA = Path(__file__).resolve().parent / "data"
SHORT = DATA / "mc_short.toml"
RUNS = 20


def _stats(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())["statistics"]


def test_wilson_interval_textbook_values():
    """Wilson (1927) score interval, 95 %: 5/10 -> (0.2366, 0.7634); 0/10 -> (0, 0.2775);
    81/263 -> (0.2553, 0.3662) (Newcombe, Stat. Med. 17 (1998) 857, table I)."""
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(81, 263) == pytest.approx((0.2553, 0.3662), abs=1e-4)


def test_runs_are_pure_functions_of_seed_and_index():
    c = load_campaign(SHORT)
    a = [run_factors(c, i) for i in range(5)]
    assert a == [run_factors(c, i) for i in range(5)]
    assert len({s for s, _ in a}) == 5
    assert run_factors(c, -1)[1] == {d.name: 1.0 for d in c.dispersions}


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("mc") / "default"
    assert main(["montecarlo", str(SHORT), "--runs", str(RUNS), "--out", str(out), "--no-progress"]) == 0
    return out


@pytest.mark.slow
def test_default_executor_writes_every_run_and_the_statistics(default_run):
    s = _stats(default_run)
    assert s["runs"] == RUNS and s["runs_ok"] + s["runs_failed"] == RUNS
    assert len(list((default_run / "runs").glob("run_*.json"))) == RUNS
    f = s["lco_fraction"]
    assert f["ci_low"] <= f["value"] <= f["ci_high"]
    assert {p.name for p in default_run.iterdir()} == {"campaign.json", "runs", "summary.json", "campaign.h5",
                                                       "montecarlo.png"}
    prov = json.loads((default_run / "summary.json").read_text())["provenance"]
    assert prov["campaign_sha256"] and prov["model_sha256"] and prov["ascent_sha256"] and prov["seed"] == 7


@pytest.mark.slow
def test_one_worker_gives_identical_statistics(default_run, tmp_path):
    out = tmp_path / "w1"
    assert main(["montecarlo", str(SHORT), "--runs", str(RUNS), "--workers", "1", "--out", str(out),
                 "--no-progress"]) == 0
    assert _stats(out) == _stats(default_run)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def cluster():
    """A Dask scheduler and two workers as separate processes on loopback."""
    port = _free_port()
    bindir = Path(sys.executable).parent
    env = dict(os.environ)
    sched = subprocess.Popen([str(bindir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                              "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    addr = f"tcp://127.0.0.1:{port}"
    workers = [subprocess.Popen([str(bindir / "dask"), "worker", addr, "--nthreads", "1", "--nworkers", "1",
                                 "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env) for _ in range(2)]
    from dask.distributed import Client
    deadline = time.time() + 60
    while True:
        try:
            with Client(addr, timeout="5s") as c:
                c.wait_for_workers(2, timeout=30)
            break
        except Exception:
            if time.time() > deadline:
                raise
            time.sleep(0.5)
    yield addr, workers
    for p in workers + [sched]:
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
    for p in workers + [sched]:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()


@pytest.mark.slow
def test_scheduler_executor_gives_identical_statistics(cluster, default_run, tmp_path):
    addr, _ = cluster
    out = tmp_path / "sched"
    assert main(["montecarlo", str(SHORT), "--runs", str(RUNS), "--scheduler", addr, "--out", str(out),
                 "--no-progress"]) == 0
    assert _stats(out) == _stats(default_run)


@pytest.mark.slow
def test_killing_a_worker_loses_no_run(cluster, default_run, tmp_path):
    """A worker killed mid-campaign: Dask re-runs its tasks on the other one; the campaign ends
    with every run and the same statistics."""
    addr, workers = cluster
    out = tmp_path / "kill"
    rc = {}

    def go():
        rc["rc"] = main(["montecarlo", str(SHORT), "--runs", str(RUNS), "--scheduler", addr, "--out", str(out),
                         "--no-progress"])
    th = threading.Thread(target=go)
    th.start()
    deadline = time.time() + 120
    while len(list((out / "runs").glob("run_*.json"))) < 3 and time.time() < deadline:
        time.sleep(0.05)
    workers[0].kill()
    th.join(timeout=300)
    assert rc.get("rc") == 0
    assert len(list((out / "runs").glob("run_*.json"))) == RUNS
    assert _stats(out) == _stats(default_run)


@pytest.mark.slow
def test_resume_after_interruption_gives_the_same_statistics(default_run, tmp_path):
    """Resume: a campaign stored in part (runs missing, as after a kill) is completed by
    --resume to the same statistics; without --resume the folder is refused."""
    out = tmp_path / "resume"
    assert main(["montecarlo", str(SHORT), "--runs", "8", "--workers", "1", "--out", str(out), "--no-progress"]) == 0
    for p in list((out / "runs").glob("run_00000[2-5].json")):
        p.unlink()
    assert main(["montecarlo", str(SHORT), "--runs", str(RUNS), "--workers", "1", "--out", str(out),
                 "--no-progress"]) == 2
    assert main(["montecarlo", str(SHORT), "--runs", str(RUNS), "--workers", "1", "--out", str(out),
                 "--resume", "--no-progress"]) == 0
    assert _stats(out) == _stats(default_run)


BAD = [
    ("dispersions.coulomb_torqe", 'coulomb_torqe = { distribution = "normal", mean = 1.0, std = 0.1 }'),
    ("dispersions.wind.std", 'wind = { distribution = "normal", mean = 1.0, std = -0.1 }'),
    ("dispersions.wind.high", 'wind = { distribution = "uniform", low = 1.5, high = 0.5 }'),
    ("dispersions.wind.distribution", 'wind = { distribution = "cauchy", low = 0.5, high = 1.5 }'),
]


@pytest.mark.parametrize("field, line", BAD)
def test_bad_campaign_files_one_line_exit_2_no_campaign(tmp_path, capsys, field, line):
    text = SHORT.read_text().replace('ascent = "../../models/flight/ascent.toml"',
                                     f'ascent = "{(DATA / "../../models/flight/ascent.toml").resolve()}"')
    text = "\n".join(ln for ln in text.splitlines() if not ln.startswith(line.split(" =")[0] + " ="))
    p = tmp_path / "bad.toml"
    p.write_text(text + "\n" + line + "\n")
    out = tmp_path / "out"
    assert main(["montecarlo", str(p), "--runs", "3", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not out.exists()


def test_zero_runs_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["montecarlo", str(SHORT), "--runs", "0", "--out", str(out)]) == 2
    assert "--runs" in capsys.readouterr().err and not out.exists()
