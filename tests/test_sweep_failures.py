"""Issue 40 point 5 for the other campaign commands, ``taos sweep --out`` and ``taos lco --sweep
--out`` (the verdict map campaign): SIGTERM and a lost scheduler say how many points the store
keeps and the exact command that continues (the words of ``taos montecarlo``:
:class:`taos.cli.montecarlo.KeptStore`), that command finishes the job to the same store as an
uninterrupted run, and ``--scheduler-file`` is read and refused with ``--workers`` /
``--scheduler`` by the same code as montecarlo's."""

from __future__ import annotations

import json
import re
import shlex
import signal
import sys
from pathlib import Path

import numpy as np
import pytest

from taos.cli import main
from taos.montecarlo import store

from tests import _daskproc, _forkserver
from tests.conftest import MODELS, ROOT, run_cli
from tests.test_montecarlo_failures import _free_port, _scheduler, _stop, _stored

BIN = Path(sys.executable).parent
AMBIENT = MODELS / "rs25_ambient.toml"
#: 48 points of about 50 ms each, one per batch: a sweep slow enough to stop in the middle
SWEEP = ["sweep", str(AMBIENT), "--set",
         "structure.load_stiffness=" + ",".join(f"{k} lbf/in" for k in range(80_000, 200_000, 2_500)),
         "--metric", "phase_margin_deg,lab_peaking_db,load_mode_hz", "--batch", "1", "--no-progress"]
N_SWEEP = 48
#: a verdict map of four TVC variants (one Dask batch each), each confirmed in the time domain
LCO = ["lco", str(MODELS / "rs25_flight.toml"), "--flight", str(MODELS / "flight" / "core_stage.toml"),
       "--friction", "dahl", "--amplitudes-deg", "0.01,0.03,0.1,0.3,1", "--freq-hz", "0.06,0.1,0.2,0.5",
       "--sweep", "load_stiffness=80000 lbf/in,100000 lbf/in,130000 lbf/in,150000 lbf/in", "--duration", "120"]
N_LCO = 4


def _start(args, out: Path, *extra):
    """``taos ARGS EXTRA --out OUT`` started (``Popen``'s text pipes; the fork server's child
    where it can: :func:`tests._forkserver.popen`)."""
    return _forkserver.popen([str(BIN / "taos"), *map(str, args), *map(str, extra), "--out", str(out)], ROOT)


def _wait_stored(p, spath: Path, n: int) -> None:
    """Until the store holds ``n`` points (polled, never a guess of the batches' timing)."""
    _daskproc.wait_stored(lambda: _stored(spath), spath / "status", n, lambda: p.poll() is None)
    assert p.poll() is None, "the run ended before the store held its first points"


def _resume_argv(line: str, command: str) -> list[str]:
    m = re.search(rf"continue with: (taos {command} .*--resume)$", line)
    assert m, line
    return shlex.split(m.group(1))


def _same_store(a: Path, b: Path, names) -> None:
    """Two stores of one design hold the same points: status, factors and every value."""
    da, db = store.open_store(a, dask=False).load(), store.open_store(b, dask=False).load()
    for k in ("status", "factor", *names):
        np.testing.assert_array_equal(da[k].values, db[k].values, err_msg=k)


def _kept_line(err: str, prefix: str, spath: Path, noun: str, total: int) -> str:
    # (the map campaign's progress bar, tqdm's "montecarlo: ..." lines, is not a message)
    lines = [ln for ln in re.split(r"[\r\n]+", err) if ln.strip() and not ln.startswith("montecarlo:")]
    assert len(lines) == 1 and lines[0].startswith(prefix), err
    assert "no partial output" not in lines[0] and "Traceback" not in err
    n = _stored(spath)
    assert 0 < n < total
    assert f"{n} of {total} {noun} stored in {spath} (kept); continue with: " in lines[0], lines[0]
    return lines[0]


@pytest.fixture(scope="module")
def fresh_sweep(tmp_path_factory) -> Path:
    """The store of :data:`SWEEP` run uninterrupted in this process (the reference of both
    interrupted sweeps below: the same command on the same inputs, run once for the module)."""
    fresh = tmp_path_factory.mktemp("fresh_sweep") / "fresh"
    assert main([*SWEEP, "--out", str(fresh)]) == 0
    return fresh / "sweep.zarr"


@pytest.mark.slow
def test_sweep_sigterm_keeps_the_store_and_its_resume_line_finishes_it(tmp_path, fresh_sweep):
    """SIGTERM once the store holds points: exit 143, one line with the points kept and the
    resume command; that command (a new process, as a user's) computes only the rest, and the
    store equals an uninterrupted sweep's point for point."""
    out = tmp_path / "s"
    p = _start(SWEEP, out)
    _wait_stored(p, out / "sweep.zarr", 2)
    p.send_signal(signal.SIGTERM)
    _, err = _daskproc.communicate(p, 120)
    assert p.returncode == 143, err
    line = _kept_line(err, "taos: terminated (signal 15); ", out / "sweep.zarr", "points", N_SWEEP)
    done = _stored(out / "sweep.zarr")
    argv = _resume_line_json(line, "sweep", tmp_path / "resumed.json")
    r = _forkserver.run(argv, ROOT, 600)
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "resumed.json").read_text())["timing"]["points_executed"] == N_SWEEP - done
    _same_store(out / "sweep.zarr", fresh_sweep, ("phase_margin_deg", "lab_peaking_db", "load_mode_hz"))


def _resume_line_json(line: str, command: str, json_path: Path) -> list[str]:
    argv = _resume_argv(line, command)
    return [str(BIN / "taos"), *argv[1:], "--json", str(json_path)]


@pytest.mark.slow
def test_lco_map_sigterm_keeps_the_store_and_its_resume_line_finishes_it(tmp_path):
    """The verdict map campaign on a local Dask worker (one batch per TVC variant): SIGTERM once
    a point is stored gives exit 143 and the kept-points line; its resume command finishes the
    map to the same store as the map run uninterrupted in this process."""
    out = tmp_path / "m"
    p = _start(LCO, out, "--workers", "1")
    _wait_stored(p, out / "map.zarr", 1)
    p.send_signal(signal.SIGTERM)
    _, err = _daskproc.communicate(p, 120)
    assert p.returncode == 143, err
    line = _kept_line(err, "taos: terminated (signal 15); ", out / "map.zarr", "points", N_LCO)
    argv = _resume_argv(line, "lco")
    assert argv[argv.index("--out") + 1] == str(out) and argv[argv.index("--workers") + 1] == "1"
    r = _forkserver.run([str(BIN / "taos"), *argv[1:]], ROOT, 600)
    assert r.returncode == 0, r.stderr
    assert _stored(out / "map.zarr") == N_LCO
    fresh = tmp_path / "fresh"
    assert main([*LCO, "--out", str(fresh), "--json", str(tmp_path / "fresh.json")]) == 0
    from taos.flight.lco_map import POINT_FLAGS, POINT_SCALARS
    _same_store(out / "map.zarr", fresh / "map.zarr", POINT_SCALARS + POINT_FLAGS)


@pytest.mark.slow
def test_sweep_scheduler_loss_is_one_line_with_the_points_kept_and_the_resume_line(tmp_path, fresh_sweep):
    """The scheduler killed mid-sweep: exit 2, one line (the scheduler lost, the points kept,
    the resume command; never "internal error"); the resume command, run in this machine's
    process in place of the lost scheduler, finishes the sweep to an uninterrupted run's store.
    (``--connect-timeout 3``: the lost scheduler is waited for 3 s, not the default 20.)"""
    addr, sched, ws = _scheduler(tmp_path, workers=1)
    out = tmp_path / "s"
    try:
        p = _start(SWEEP, out, "--scheduler", addr, "--connect-timeout", "3")
        _wait_stored(p, out / "sweep.zarr", 3)
        sched.kill()
        _, err = _daskproc.communicate(p, 120)
    finally:
        _stop([*ws, sched])
    assert p.returncode == 2, err
    line = _kept_line(err, "taos: (cluster): campaign: ", out / "sweep.zarr", "points", N_SWEEP)
    assert "scheduler was lost" in line and "internal error" not in line
    argv = _resume_argv(line, "sweep")
    assert argv[argv.index("--scheduler") + 1] == addr
    del argv[argv.index("--scheduler"):argv.index("--scheduler") + 2]   # this process instead (not bound)
    r = _forkserver.run([str(BIN / "taos"), *argv[1:]], ROOT, 600)
    assert r.returncode == 0, r.stderr
    _same_store(out / "sweep.zarr", fresh_sweep, ("phase_margin_deg", "lab_peaking_db", "load_mode_hz"))


def test_without_out_a_lost_cluster_says_nothing_is_kept(tmp_path, monkeypatch):
    """No ``out_dir`` (no ``--out``): the store is temporary and removed, so the line of a
    cluster that failed says nothing is kept (not "kept, resume to continue"), and no folder
    stays behind."""
    import tempfile
    from taos.errors import InputError
    from taos.montecarlo import engine
    from taos.montecarlo.sweep import SweepDefinition, run_sweep
    from taos.montecarlo.sweep_define import make_design, parse_set

    def lost(*a, **k):
        raise engine.CampaignStopped("the Dask scheduler was lost (no answer within the connect timeout)")
    monkeypatch.setattr(engine, "execute", lost)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    defn = SweepDefinition(str(AMBIENT), make_design([parse_set("structure.load_stiffness=80000 lbf/in,150000 lbf/in")], None, 0, None),
                           ("load_mode_hz",))
    with pytest.raises(InputError, match="scheduler was lost") as e:
        run_sweep(defn)
    assert not isinstance(e.value, engine.CampaignStopped)
    assert "nothing kept (no out_dir / --out: the store was temporary)" in str(e.value)
    assert "resume" not in str(e.value) and not list(tmp_path.iterdir())
    with pytest.raises(engine.CampaignStopped, match="resume to continue"):   # with a folder: kept
        run_sweep(defn, tmp_path / "kept")


def test_connect_timeout_out_of_range_is_one_line_before_any_work(tmp_path, capsys):
    """``--connect-timeout`` (``connect_timeout_s``) 0.1 to 600 s, as taos montecarlo's: outside,
    one line and exit 2 (InputError in the API), nothing written."""
    from taos.errors import InputError
    from taos.montecarlo.sweep import SweepDefinition, run_sweep
    from taos.montecarlo.sweep_define import make_design, parse_set
    for bad in ("0", "601", "nan"):
        assert main([*SWEEP, "--connect-timeout", bad, "--out", str(tmp_path / "s")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "--connect-timeout" in err[0] and "0.1 to 600 s" in err[0], err
    assert not (tmp_path / "s").exists()
    defn = SweepDefinition(str(AMBIENT), make_design([parse_set("structure.load_stiffness=80000 lbf/in")], None, 0, None),
                           ("load_mode_hz",))
    for bad in (0.0, "20", True):
        with pytest.raises(InputError, match="connect-timeout"):
            run_sweep(defn, connect_timeout_s=bad)


def test_a_foreign_campaign_in_out_is_not_reported_as_kept(tmp_path):
    """A manifest that was in ``--out`` before this run (another run's, not resumed) is never
    announced as this run's kept store; one this run wrote, or resumes, is."""
    from taos.cli.montecarlo import KeptStore
    (tmp_path / "sweep.json").write_text("{}")
    assert KeptStore(tmp_path, "sweep.json", "sweep.zarr", "points", "taos sweep x --resume", False).describe() is None
    resumed = KeptStore(tmp_path, "sweep.json", "sweep.zarr", "points", "taos sweep x --resume", True).describe()
    assert resumed == f"none of the points stored yet in {tmp_path / 'sweep.zarr'} (kept); continue with: " \
                      "taos sweep x --resume"
    new = KeptStore(tmp_path / "new", "sweep.json", "sweep.zarr", "points", "c --resume", False)
    assert new.describe() is None
    (tmp_path / "new").mkdir()
    store.create(tmp_path / "new" / "sweep.zarr", labels=np.arange(4), names=("a",), factors=np.zeros((4, 1)),
                 seeds=np.arange(4), scalars=("x",), flags=(), trace_t_s=np.zeros(0), batch=2, attrs={})
    store.write_batch(tmp_path / "new" / "sweep.zarr", 0, {"x": np.ones(2), "status": np.ones(2, np.int8)})
    (tmp_path / "new" / "sweep.json").write_text("{}")
    assert new.describe().startswith("2 of 4 points stored in ")


# -- --scheduler-file --------------------------------------------------------------------------------------

def test_scheduler_file_is_refused_with_workers_or_scheduler(tmp_path):
    """One of --workers, --scheduler, --scheduler-file (the check montecarlo makes), before any
    work: one line, exit 2, nothing written."""
    f = tmp_path / "scheduler.json"
    f.write_text(json.dumps({"type": "Scheduler", "address": f"tcp://127.0.0.1:{_free_port()}"}))
    for cmd in ([*SWEEP, "--out", tmp_path / "s"], [*LCO, "--out", tmp_path / "s", "--no-time-domain"]):
        for other in (["--workers", "2"], ["--scheduler", "tcp://127.0.0.1:8786"]):
            r = run_cli(*cmd, "--scheduler-file", f, *other)
            assert r.returncode == 2, r.stderr
            lines = r.stderr.strip().splitlines()
            assert len(lines) == 1 and "one of --workers, --scheduler, --scheduler-file" in lines[0], r.stderr
    r = run_cli(*LCO[:-4], "--no-time-domain", "--scheduler-file", f)   # no --sweep: no map campaign
    assert r.returncode == 2 and "--scheduler-file" in r.stderr and "--sweep" in r.stderr, r.stderr
    r = run_cli(*LCO[:-4], "--requirements", MODELS / "specs" / "flight_signoff_notional.toml",
                "--scheduler-file", f)   # the sign-off runs in this process: the option would be ignored
    assert r.returncode == 2 and "--scheduler-file" in r.stderr and "--requirements" in r.stderr, r.stderr
    bad = tmp_path / "bad.json"
    bad.write_text('{"address": "inproc://x/1/2"}')
    r = run_cli(*SWEEP, "--scheduler-file", bad, "--out", tmp_path / "s")
    assert r.returncode == 2 and str(bad) in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "s").exists()


@pytest.mark.slow
def test_scheduler_file_of_a_local_cluster_runs_the_sweep_and_the_map(tmp_path):
    """A LocalCluster whose scheduler writes Dask's scheduler file: ``taos sweep`` and ``taos lco
    --sweep --out`` with ``--scheduler-file`` store what they store in this process."""
    from dask.distributed import LocalCluster
    f = tmp_path / "scheduler.json"
    short = SWEEP[:3] + ["structure.load_stiffness=80000 lbf/in,150000 lbf/in"] + SWEEP[4:]
    lco = LCO[:-3] + ["load_stiffness=80000 lbf/in,150000 lbf/in", "--no-time-domain"]
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", dashboard_address=":0",
                      scheduler_kwargs={"scheduler_file": str(f)}):
        assert main([*short, "--scheduler-file", str(f), "--out", str(tmp_path / "s")]) == 0
        assert main([*lco, "--scheduler-file", str(f), "--out", str(tmp_path / "m")]) == 0
    assert main([*short, "--out", str(tmp_path / "s0")]) == 0
    assert main([*lco, "--out", str(tmp_path / "m0")]) == 0
    _same_store(tmp_path / "s" / "sweep.zarr", tmp_path / "s0" / "sweep.zarr",
                ("phase_margin_deg", "lab_peaking_db", "load_mode_hz"))
    from taos.flight.lco_map import POINT_FLAGS, POINT_SCALARS
    _same_store(tmp_path / "m" / "map.zarr", tmp_path / "m0" / "map.zarr", POINT_SCALARS + POINT_FLAGS)
