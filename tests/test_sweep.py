"""``taos sweep``: the figures checked against independent references, the design, unstable
variants, resume after an interruption, and bad input (one line, exit 2, nothing written).

Where a test is about the figures and files, the command runs through the console script's entry
in this process (:mod:`tests.inprocess`: no second process start-up per call); the Ctrl-C,
the printed summary and a bad value's exit status run the console script in a subprocess."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from tests import _daskproc, _forkserver
from tests.conftest import MODELS, ROOT, inline_actuator_set, run_cli
from tests.inprocess import taos_json

AMBIENT = MODELS / "rs25_ambient.toml"
FLIGHT_MODEL = MODELS / "rs25_flight.toml"
FLIGHT = MODELS / "flight" / "core_stage.toml"
#: 1 lbf/in in N/m: 4.4482216152605 N / 0.0254 m (NIST SP 811, exact definitions of lbf and in)
LBF_PER_IN = 4.4482216152605 / 0.0254
STIFFNESS_LBF_IN = (80_000, 115_000, 150_000, 205_000)


def sweep_json(tmp_path: Path, *args, name="s.json") -> dict:
    """``taos sweep ARGS --json tmp_path/name`` (in this process): exit 0, the JSON."""
    return taos_json(tmp_path / name, "sweep", *args)


def _si(text: str) -> float:
    """The model file's SI values, written in SI units there: '0.8 m' -> 0.8."""
    num, unit = text.split(maxsplit=1)
    assert unit in ("m", "kg*m**2", "N*m/rad"), unit
    return float(num)


def test_load_resonance_over_a_stiffness_sweep_matches_the_closed_form(tmp_path):
    """w_L = sqrt((K_L R^2 + K_n) / J) (seed paper eq. 1) from the file's R, J and K_n read here
    and K_L converted with the exact lbf/in; the notch of the command -> piston response (a
    frequency-response search, not the formula) sits on it within the 0.5 % load-path damping's
    shift (measured 1e-4)."""
    doc = tomllib.loads(AMBIENT.read_text())
    R, J = _si(doc["actuator"]["moment_arm"]), _si(doc["engine"]["inertia_pitch"])
    Kn = _si(doc["engine"]["rotational_stiffness"])
    values = ",".join(f"{k} lbf/in" for k in STIFFNESS_LBF_IN)
    d = sweep_json(tmp_path, AMBIENT, "--set", f"structure.load_stiffness={values}",
                   "--metric", "load_resonance_hz,notch_hz")
    assert d["counts"] == {"points": 4, "ok": 4, "failed": 0, "unstable": 0}
    assert d["grid"]["shape"] == [4] and d["factor_units"] == {"structure.load_stiffness": "lbf/in"}
    for p, k in zip(d["points"], STIFFNESS_LBF_IN):
        ref = math.sqrt((k * LBF_PER_IN * R * R + Kn) / J) / (2 * math.pi)
        assert p["factors"]["structure.load_stiffness"] == k
        assert p["metrics"]["load_resonance_hz"] == pytest.approx(ref, rel=1e-12)
        assert p["metrics"]["notch_hz"] == pytest.approx(ref, rel=3e-4)
    prov = d["provenance"]
    assert prov["model_sha256"] and prov["package_version"] and prov["inputs_sha256"]
    assert prov["definition"]["keys"][0]["values"][0] == "80000 lbf/in"
    assert d["timing"]["executor"] == "in-process"


def test_a_swept_value_is_the_same_model_as_a_file_holding_it(tmp_path):
    """Overrides go through the loader exactly as the file's own values: a key of the shared
    actuator set (piston area) and a key of the file (load stiffness) give the model a copy of
    the file with those values gives."""
    from taos.model import load_model

    text = inline_actuator_set(AMBIENT.read_text())
    doc = tomllib.loads(text)
    assert "piston_area" in doc["actuator"]
    lines = []
    for line in text.splitlines():
        if line.startswith("piston_area"):
            line = 'piston_area = "13.5 in**2"'
        elif line.startswith("load_stiffness"):
            line = 'load_stiffness = "140000 lbf/in"'
        lines.append(line)
    copy = tmp_path / "variant.toml"
    copy.write_text("\n".join(lines) + "\n")
    a = load_model(copy)
    b = load_model(AMBIENT, overrides={"actuator.piston_area": "13.5 in**2",
                                       "structure.load_stiffness": "140000 lbf/in"})
    assert (a.actuator, a.structure, a.friction, a.engine, a.avionics) == \
        (b.actuator, b.structure, b.friction, b.engine, b.avionics)
    assert b.actuator != load_model(AMBIENT).actuator


def test_unstable_variants_are_results_listed_apart(tmp_path):
    """A servo loop gain far above the file's makes the linear block unstable: those points
    are reported unstable with their mode, their figures null, the others computed; exit 0."""
    d = sweep_json(tmp_path, AMBIENT, "--set", "actuator.loop_gain=10 1/s,100 1/s,5000 1/s",
                   "--metric", "engine_bandwidth_hz,gain_margin_db")
    assert d["counts"] == {"points": 3, "ok": 2, "failed": 0, "unstable": 1}
    (u,) = d["unstable"]
    assert u["set"] == {"actuator.loop_gain": "5000 1/s"} and "unstable" in u["reason"] and "Hz" in u["reason"]
    assert d["points"][2]["metrics"] == {"engine_bandwidth_hz": None, "gain_margin_db": None}
    assert d["points"][0]["metrics"]["gain_margin_db"] > d["points"][1]["metrics"]["gain_margin_db"]


def test_a_point_whose_figures_fail_is_stored_failed_with_its_reason(ambient):
    """The run kind keeps going past a point it cannot compute: status failed, the reason, NaN."""
    from taos.montecarlo.store import STATUS
    from taos.montecarlo.sweep import SweepRuns

    kind = SweepRuns((ambient, ambient), np.array([[1.0], [2.0]]), ("lco", "load_resonance_hz"), "pitch", None, "x")
    out = kind.run_batch(("k",), np.array([[2.0], [1.0]]), np.zeros(2, np.int64))
    assert list(out["status"]) == [STATUS["failed"]] * 2
    assert "need a flight file" in out["error"][0] and np.isnan(out["load_resonance_hz"]).all()


@pytest.mark.slow
def test_latin_hypercube_puts_one_sample_in_each_stratum(tmp_path):
    """--samples N over a range: every sample inside it, one in each of N equal strata; a listed
    key sampled among its values; the same seed, the same points; the values as text with the
    range's unit."""
    args = (AMBIENT, "--samples", "8", "--set", "structure.load_stiffness=80000 lbf/in:160000 lbf/in",
            "--set", "friction.model=dahl,lugre", "--metric", "load_resonance_hz")
    d = sweep_json(tmp_path, *args, "--seed", "7")
    k = np.array([p["factors"]["structure.load_stiffness"] for p in d["points"]])
    assert d["grid"]["design"] == "latin-hypercube" and len(k) == 8
    assert np.all((k >= 80_000) & (k <= 160_000))
    assert sorted(np.floor((k - 80_000) / 10_000).astype(int)) == list(range(8))
    assert {p["set"]["friction.model"] for p in d["points"]} == {"dahl", "lugre"}
    assert all(p["set"]["structure.load_stiffness"].endswith(" lbf/in") for p in d["points"])
    again = sweep_json(tmp_path, *args, "--seed", "7", name="again.json")
    assert [p["factors"] for p in again["points"]] == [p["factors"] for p in d["points"]]


def test_sobol_indices_of_the_load_resonance_fall_on_the_load_stiffness(tmp_path):
    """w_L = sqrt((K_L R^2 + K_n)/J) (seed paper eq. 1) has no piston area in it: on Saltelli's
    design the other key's first-order and total indices are zero (the estimators difference
    equal outputs), the load stiffness carries the variance (ST = 1 within the estimator's noise
    at N = 8)."""
    d = sweep_json(tmp_path, AMBIENT, "--sensitivity", "sobol", "--samples", "8",
                   "--set", "structure.load_stiffness=100000 lbf/in:130000 lbf/in",
                   "--set", "actuator.piston_area=13.5 in**2:16.5 in**2", "--metric", "load_resonance_hz")
    assert d["grid"]["design"] == "sobol" and d["counts"]["ok"] == 8 * (2 + 2)
    rows = {r["parameter"]: r for r in d["sensitivity"]["load_resonance_hz"]["indices"]}
    assert rows["actuator.piston_area"]["S1"] == pytest.approx(0, abs=1e-12)
    assert rows["actuator.piston_area"]["ST"] == pytest.approx(0, abs=1e-12)
    assert rows["structure.load_stiffness"]["ST"] == pytest.approx(1, abs=0.3)


def test_plot_of_a_two_key_grid(tmp_path):
    png = tmp_path / "sweep.png"
    r = run_cli("sweep", AMBIENT, "--set", "structure.load_stiffness=100000 lbf/in,150000 lbf/in",
                "--set", "actuator.piston_area=12 in**2,15 in**2", "--metric", "engine_peaking_db,phase_margin_deg",
                "--plot", png)
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "4 points: 4 ok, 0 unstable, 0 failed" in r.stdout


def _store_done(path: Path) -> int:
    from taos.montecarlo.store import status
    st = status(path)
    return 0 if st is None else int(np.sum(st != 0))


@pytest.mark.slow
def test_an_interrupted_sweep_resumes_where_it_stopped(tmp_path):
    """Ctrl-C during a sweep: exit 130 with the finished batches stored; --resume computes only
    the rest, and the result equals an uninterrupted sweep's, value for value."""
    values = ",".join(f"{k} lbf/in" for k in range(80_000, 200_000, 5_000))   # 24 points
    args = ["sweep", AMBIENT, "--set", f"structure.load_stiffness={values}", "--metric",
            "phase_margin_deg,lab_peaking_db,load_mode_hz", "--batch", "1"]
    exe = Path(sys.executable).parent / "taos"
    out = tmp_path / "run"
    p = _forkserver.popen([str(exe), *map(str, args), "--out", str(out)], ROOT)
    _daskproc.wait_stored(lambda: _store_done(out / "sweep.zarr"), out / "sweep.zarr" / "status", 3,
                          lambda: p.poll() is None)
    p.send_signal(signal.SIGINT)
    _, err = _daskproc.communicate(p, 120)
    assert p.returncode == 130 and "Traceback" not in err, err
    done = _store_done(out / "sweep.zarr")
    assert 3 <= done < 24
    # the resume is a new process, as a user's would be (the store's inputs hash is of the files a
    # fresh process reads; a resume inside this test process would also count fewer of them)
    r = run_cli(*args, "--out", out, "--resume", "--json", tmp_path / "resumed.json")
    assert r.returncode == 0, r.stderr
    resumed = json.loads((tmp_path / "resumed.json").read_text())
    assert resumed["timing"]["points_executed"] == 24 - done
    fresh = sweep_json(tmp_path, *args[1:], name="fresh.json")
    assert [p["metrics"] for p in resumed["points"]] == [p["metrics"] for p in fresh["points"]]
    assert resumed["counts"]["ok"] == 24


_CUT_WRITE = """
import argparse, os, signal, sys, time
import numpy as np
import zarr.storage._local as local
from taos.errors import run_cli
from taos.montecarlo import store

put, calls = local._put, []
def cut(*a, **k):  # the first chunk file of the batch: Ctrl-C arrives while it is being written
    calls.append(1)
    if len(calls) == 1:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.3)
    return put(*a, **k)

def cmd(args):
    store.create(args.path, labels=np.arange(4), names=("a",), factors=np.zeros((4, 1)), seeds=np.arange(4),
                 scalars=("x",), flags=(), trace_t_s=np.zeros(0), batch=2, attrs={})
    local._put = cut
    store.write_batch(args.path, 0, {"x": np.ones(2), "status": np.ones(2)})
    return 0

ap = argparse.ArgumentParser(prog="taos")
ap.add_argument("path")
ap.set_defaults(func=cmd)
sys.exit(run_cli(ap, None))
"""


def test_ctrl_c_inside_a_store_write_exits_with_one_line_and_a_readable_store(tmp_path):
    """A Ctrl-C that lands while Zarr writes a batch (its I/O runs on Zarr's own thread): exit
    130 with the one interrupt line and nothing else on standard error (no "Task was destroyed"
    from a write the interpreter's exit cut short), the store still readable, and the cut batch
    still pending, so a resume runs it again."""
    from taos.montecarlo import store

    path = tmp_path / "s.zarr"
    r = _forkserver.run([sys.executable, "-c", _CUT_WRITE, path], tmp_path, timeout=120)
    assert r.returncode == 130, r.stderr
    assert r.stderr.splitlines() == ["taos: interrupted (Ctrl-C); no partial output written"], r.stderr
    assert store.status(path).tolist() == [0, 0, 0, 0]
    store.write_batch(path, 0, {"x": np.full(2, 2.0), "status": np.ones(2)})
    ds = store.open_store(path, dask=False)
    assert ds["status"].values.tolist() == [1, 1, 0, 0] and ds["x"].values[:2].tolist() == [2.0, 2.0]


def test_waiting_for_the_store_after_an_interrupt_survives_a_half_finished_import(monkeypatch):
    """The interrupt may cut an import short (seen: ``asyncio`` half initialised, its import
    raising NameError): the wait for Zarr's I/O then gives up quietly, and the run still ends with
    its one line and 130 (``test_a_signal_at_any_moment_is_one_line_and_its_status``)."""
    import asyncio
    import threading
    import types

    from taos.montecarlo.store import finish_pending_io

    loop = asyncio.new_event_loop()
    th = threading.Thread(target=loop.run_forever, daemon=True)
    th.start()
    try:
        monkeypatch.setitem(sys.modules, "zarr.core.sync", types.SimpleNamespace(loop=[loop]))
        monkeypatch.setitem(sys.modules, "asyncio", None)   # "import asyncio" raises
        finish_pending_io(timeout_s=0.1)
    finally:
        loop.call_soon_threadsafe(loop.stop)
        th.join(5)
        loop.close()


@pytest.mark.slow
def test_lco_verdict_flips_between_the_papers_soft_and_stiff_structure(tmp_path):
    """Seed paper sec. 3.2, figs. 7-8: the soft load path (115,000 lbf/in) flies a limit cycle,
    the stiff one (205,000 lbf/in) none, with a margin left; computed on a local Dask cluster of
    two workers: the same figures as in this process."""
    args = (FLIGHT_MODEL, "--flight", FLIGHT, "--set", "structure.load_stiffness=115000 lbf/in,205000 lbf/in",
            "--metric", "lco,lco_engine_amplitude_deg,lco_margin_db", "--amplitudes-deg", "0.01,0.05,0.2,1",
            "--freq-hz", "0.05,0.1,0.2,0.5")
    d = sweep_json(tmp_path, *args, "--workers", "2")
    soft, stiff = (p["metrics"] for p in d["points"])
    assert soft["lco"] is True and soft["lco_engine_amplitude_deg"] > 0 and soft["lco_margin_db"] == 0
    assert stiff["lco"] is False and stiff["lco_engine_amplitude_deg"] is None and stiff["lco_margin_db"] > 0
    assert d["timing"]["executor"] == "LocalCluster" and d["provenance"]["flight_sha256"]
    local = sweep_json(tmp_path, *args, name="local.json")
    assert [p["metrics"] for p in local["points"]] == [p["metrics"] for p in d["points"]]



@pytest.mark.slow
def test_time_domain_verdict_equals_taos_lco_on_each_point(tmp_path):
    """``lco_confirmed`` is ``taos lco``'s verdict (the flight loop flown in the time domain
    decides): over the paper's soft and stiff load paths (sec. 3.2: a cycle with the soft one,
    none with the stiff one) each point equals the ``taos lco --load-stiffness`` command run on
    its own, amplitude and frequency included."""
    grid = ("--amplitudes-deg", "0.01,0.05,0.2,1", "--freq-hz", "0.05,0.1,0.2,0.5")
    d = sweep_json(tmp_path, FLIGHT_MODEL, "--flight", FLIGHT, "--set",
                   "structure.load_stiffness=115000 lbf/in,205000 lbf/in", "--metric",
                   "lco,lco_confirmed,lco_confirmed_engine_amplitude_deg,lco_confirmed_frequency_hz", *grid)
    soft, stiff = (p["metrics"] for p in d["points"])
    assert soft["lco_confirmed"] is True and stiff["lco_confirmed"] is False
    for point, k in ((soft, "115000 lbf/in"), (stiff, "205000 lbf/in")):
        lco = taos_json(tmp_path / f"lco_{k.split()[0]}.json", "lco", FLIGHT_MODEL, "--flight", FLIGHT,
                        "--load-stiffness", k, *grid)
        assert point["lco_confirmed"] is lco["verdict"]["lco"]
        assert point["lco"] is lco["lco"]
        td = lco["time_domain"]
        assert point["lco_confirmed_engine_amplitude_deg"] == td["engine_amplitude_deg"]
        assert point["lco_confirmed_frequency_hz"] == td["frequency_hz"]

BAD = [
    (["--set", "structure.load_stifness=1 lbf/in"], "--set structure.load_stifness: expected a known key"),
    (["--set", "foo.bar=1"], "--set foo.bar"),
    (["--set", "structure.load_stiffness=-5 lbf/in"], "positive"),
    (["--set", "structure.load_stiffness=5 kg"], "[mass]"),
    (["--set", "structure.load_stiffness=1e7"], "no unit"),
    (["--set", "structure.load_stiffness=1e99 lbf/in"], "expected a value from"),
    (["--set", "structure.load_stiffness=1 lbf/in,,2 lbf/in"], "no empty value"),
    (["--set", "structure.load_stiffness=1e5 lbf/in,1e5 lbf/in"], "each value once"),
    (["--set", "structure.load_stiffness=1e5 lbf/in:2 kg"], "one dimension"),
    (["--set", "structure.load_stiffness=1e5 lbf/in:2e5 lbf/in"], "--samples"),
    (["--set", "structure.load_stiffness=9**9**9 lbf/in"], "structure.load_stiffness"),
    (["--set", "actuator.valve_order=3"], "1 or 2"),
    (["--set", "friction.static_torque=100 in*lbf"], "friction.static_torque"),
    (["--set", "load_stiffness=1 lbf/in"], "section.key"),
    (["--set", "structure.load_stiffness=1e5 lbf/in", "--metric", "peaking"], "--metric"),
    (["--set", "structure.load_stiffness=1e5 lbf/in", "--metric", "lco"], "--flight"),
    (["--set", "structure.load_stiffness=1e5 lbf/in", "--set", "structure.load_stiffness=2e5 lbf/in"], "each key once"),
    (["--set", "structure.load_stiffness=" + ",".join(f"{k} lbf/in" for k in range(100_000, 100_200)),
      "--set", "actuator.piston_area=" + ",".join(f"{a} in**2" for a in range(10, 61))], "at most 10000 points"),
    (["--samples", "20000", "--set", "structure.load_stiffness=1e5 lbf/in:2e5 lbf/in"], "--samples"),
    ([*[x for i in range(7) for x in ("--set", f"engine.k{i}=1")]], "one to 6 swept keys"),
    (["--set", "structure.load_stiffness=1e5 lbf/in,2e5 lbf/in", "--set", "actuator.piston_area=12 in**2",
      "--set", "engine.mass=3000 kg", "--plot", "x.png"], "--plot"),
    (["--set", "structure.load_stiffness=1e5 lbf/in", "--resume"], "--resume"),
    (["--set", "structure.load_stiffness=1e5 lbf/in", "--workers", "0"], "--workers"),
    (["--sensitivity", "sobol", "--samples", "6", "--set", "structure.load_stiffness=1e5 lbf/in:2e5 lbf/in"],
     "a power of two"),
    (["--sensitivity", "sobol", "--samples", "8", "--set", "structure.load_stiffness=1e5 lbf/in,2e5 lbf/in"],
     "a range LO:HI of real values"),
]


@pytest.mark.parametrize("extra,needle", BAD, ids=[str(i) for i in range(len(BAD))])
def test_bad_input_is_one_line_and_exit_2_with_nothing_written(tmp_path, monkeypatch, capsys, extra, needle):
    """Through the console script's entry (:func:`taos.cli.main`) in this process."""
    from taos.cli import main

    if "--metric" not in extra:
        extra = [*extra, "--metric", "load_resonance_hz"]
    monkeypatch.chdir(tmp_path)
    code = main(["sweep", str(AMBIENT), *extra, "--json", str(tmp_path / "s.json"), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and needle in err, err
    assert not (tmp_path / "s.json").exists() and not (tmp_path / "o").exists() and not (tmp_path / "x.png").exists()


def test_a_bad_value_from_the_console_script_is_one_line(tmp_path):
    r = run_cli("sweep", AMBIENT, "--set", "structure.load_stiffness=5 kg", "--metric", "notch_hz",
                "--json", tmp_path / "s.json")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "--set structure.load_stiffness" in r.stderr
    assert not (tmp_path / "s.json").exists()


def test_list_metrics_names_every_family():
    r = run_cli("sweep", "--list-metrics")
    assert r.returncode == 0
    for name in ("load_resonance_hz", "phase_margin_deg", "lco", "flight_low_gain_margin_db"):
        assert name in r.stdout


def test_a_fresh_sweep_load_records_the_same_inputs_as_a_second(tmp_path):
    """The sweep's inputs hash does not depend on what the process imported before: the first
    load of a fresh ``taos sweep`` process (which imports the flight modules, and numba with them,
    on demand) records the same input files as a second load, the model's and the flight's."""
    code = ("import json, sys\nfrom taos.montecarlo.sweep import SweepDefinition, load_runs\n"
            "from taos.montecarlo.sweep_define import make_design, parse_set\n"
            "d = make_design([parse_set('structure.load_stiffness=115000 lbf/in,205000 lbf/in')])\n"
            "defn = SweepDefinition(sys.argv[1], d, ('lco',), flight_file=sys.argv[2])\n"
            "print(json.dumps([[t['file'] for t in load_runs(defn)[1]] for _ in range(2)]))")
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    r = subprocess.run([sys.executable, "-c", code, str(FLIGHT_MODEL), str(FLIGHT)], capture_output=True, text=True,
                       env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    first, second = json.loads(r.stdout)
    assert first == second and str(FLIGHT.resolve()) in first and str(FLIGHT_MODEL.resolve()) in first
