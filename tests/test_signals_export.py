"""Signals and exports of a test campaign (issue 17 point 7): load pressure, spool and supply
pressure in the simulation output and the data import; a measured record replayed through
``taos simulate``; linear models and responses exported to .mat and CSV."""

from __future__ import annotations

import math

import numpy as np
import pytest

from .conftest import MODELS, run_cli

DATA = MODELS / "data" / "greenrun_hotfire_synthetic.csv"


@pytest.fixture(scope="module")
def run(hotfire):
    from taos.profiles import SineDwell
    from taos.planar.simulate import simulate
    return simulate(hotfire, SineDwell(math.radians(0.4), 0.5, 3), record_every=5)


def test_simulation_records_load_pressure_spool_and_supply(run, hotfire, tmp_path):
    A = hotfire.actuator.piston_area_m2
    # piston force balance at 0.5 Hz: A P_L carries the load force (piston mass and damping small)
    fl, fp = run.load_force_N[0], A * run.load_pressure_Pa[0]
    assert np.sqrt(np.mean((fp - fl) ** 2)) < 0.03 * np.sqrt(np.mean(fl ** 2))
    assert np.all(run.supply_pressure_Pa == hotfire.actuator.supply_pressure_Pa)
    assert np.max(np.abs(run.load_pressure_Pa)) < hotfire.actuator.supply_pressure_Pa
    # spool (no-load flow / A) ~ piston rate at low frequency
    v = np.gradient(run.piston_m[0], run.t_s)
    assert np.corrcoef(run.spool_flow_m_s[0], v)[0, 1] > 0.98
    from taos.planar.simulate import TimeHistory
    run.to_hdf5(tmp_path / "r.h5")
    back = TimeHistory.from_hdf5(tmp_path / "r.h5")
    np.testing.assert_array_equal(back.load_pressure_Pa, run.load_pressure_Pa)
    np.testing.assert_array_equal(back.spool_flow_m_s, run.spool_flow_m_s)


def test_data_import_accepts_the_hydraulic_signals(run, tmp_path):
    from taos.identify.data import from_time_history, load_test_data
    d = from_time_history(run)
    d.to_csv(tmp_path / "rec.csv")
    head = (tmp_path / "rec.csv").read_text().splitlines()
    hdr = next(h for h in head if not h.startswith("#"))
    assert "pitch_load_pressure [psi]" in hdr and "pitch_spool [in/s]" in hdr and "supply_pressure [psi]" in hdr
    back = load_test_data(tmp_path / "rec.csv")
    np.testing.assert_allclose(back.load_pressure_Pa, run.load_pressure_Pa, rtol=1e-6)
    np.testing.assert_allclose(back.supply_pressure_Pa, run.supply_pressure_Pa[0], rtol=1e-6)
    run.to_hdf5(tmp_path / "r.h5")
    h5 = load_test_data(tmp_path / "r.h5")
    np.testing.assert_array_equal(h5.spool_flow_m_s, run.spool_flow_m_s)
    assert h5.metadata["moment_arm_m"] == run.moment_arm_m


@pytest.mark.slow
def test_measured_record_replays_through_taos_simulate(tmp_path):
    r = run_cli("simulate", MODELS / "rs25_hotfire.toml", "--profile", DATA, "--out", tmp_path / "hot.h5")
    assert r.returncode == 0, r.stderr
    lines = [x for x in r.stdout.splitlines() if x.startswith("replay pitch")]
    hot = float(lines[0].split("piston ")[1].split(" in")[0])
    from taos.planar.simulate import TimeHistory
    th = TimeHistory.from_hdf5(tmp_path / "hot.h5")
    assert th.axes == ("pitch", "yaw") and th.t_s[-1] > 30
    r = run_cli("simulate", MODELS / "rs25_ambient.toml", "--profile", DATA, "--out", tmp_path / "amb.h5")
    amb = float([x for x in r.stdout.splitlines() if x.startswith("replay pitch")][0].split("piston ")[1].split(" in")[0])
    print(f"replay of the hot-fire record: hot-fire model {hot:.5f} in, ambient model {amb:.5f} in RMS")
    assert amb > 3 * hot          # the record tells the two conditions apart


def test_linear_model_exports_to_mat_and_csv(hotfire, tmp_path):
    import scipy.io
    import scipy.signal

    from taos.planar.simplex import simplex_state_space
    r = run_cli("export", MODELS / "rs25_hotfire.toml", "--out", tmp_path / "lin.mat", "--freq-hz", "0.5,2,7,10")
    assert r.returncode == 0, r.stderr
    m = scipy.io.loadmat(tmp_path / "lin.mat", simplify_cells=True)["pitch"]
    ss = simplex_state_space(hotfire, "pitch")
    np.testing.assert_allclose(m["A"], ss.A)
    assert list(m["states"]) == list(ss.states) and list(m["outputs"])[0] == "x_p_m"
    # rebuild the engine response from the exported matrices with scipy.signal (another code path)
    sys_ = scipy.signal.StateSpace(m["A"], m["B"][:, [0]], m["C"][[1]], m["D"][[1]][:, [0]])
    _, h = scipy.signal.freqresp(sys_, 2 * np.pi * np.array([0.5, 2, 7, 10]))
    np.testing.assert_allclose(20 * np.log10(np.abs(h)), m["engine_gain_db"], atol=1e-6)
    assert m["engine_phase_deg"][3] < -180       # continuous phase in the export too
    r = run_cli("export", MODELS / "rs25_hotfire.toml", "--out", tmp_path / "csv")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "csv" / "yaw_freqresp.csv").read_text().startswith("# x_p/(R theta_c)")
    A = np.genfromtxt(tmp_path / "csv" / "pitch_A.csv", delimiter=",", skip_header=1)[:, 1:]
    np.testing.assert_allclose(A, ss.A)
    bad = run_cli("export", MODELS / "rs25_hotfire.toml", "--format", "mat", "--out", tmp_path / "x.txt")
    assert bad.returncode == 2 and "--out" in bad.stderr and not (tmp_path / "x.txt").exists()
