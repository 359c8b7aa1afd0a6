"""Periodic steady state by shooting (taos.planar.steady) and whole N(A, w) maps in one call.

The shooting solution (linear-orbit start, reduced rank extrapolation of the one-period map) is
checked against an independent route to the same orbit: plain integration from rest for 60 s,
about ten times the default settling time, on three friction laws. The several-amplitude
output of ``taos freqresp`` is checked against single-amplitude calls bit for bit, and the
describing-function map of ``taos lco`` against the same family.
"""

from __future__ import annotations

import dataclasses

import json
import math

import numpy as np
import pytest

from taos.planar.freqresp import linear_freqresp, sine_dwell_family, sine_dwell_points
from taos.linear import gain_db
from taos.model import load_model

from .conftest import MODELS, run_cli

DEG = math.pi / 180
AMPS = np.repeat(np.array([0.05, 0.4]) * DEG, 2)
FREQ = np.tile(np.array([1.0, 3.0]), 2)


@pytest.mark.parametrize("law", ["dahl", "lugre", "coulomb-smooth"])
def test_shooting_matches_long_integration(law):
    model = load_model(MODELS / "rs25_flight.toml", friction=law)
    st = sine_dwell_points(model, AMPS, FREQ, method="shoot", tol=1e-8, measure_cycles=1)
    assert st.converged.all() and (st.residual <= 1e-8).all()
    ref = sine_dwell_points(model, AMPS, FREQ, settle_s=60.0, measure_cycles=1)
    for h, r in ((st.engine, ref.engine), (st.piston, ref.piston)):
        # measured: <= 1.1e-5 dB and 2.0e-4 deg (coulomb-smooth), 1e-8 dB for the bristle laws
        assert np.max(np.abs(gain_db(h) - gain_db(r))) < 5e-5
        assert np.max(np.abs(np.degrees(np.angle(h / r)))) < 1e-3
    # the shortcut is real: far fewer periods than the 60 s reference integrates
    assert (st.periods < 0.5 * 60.0 * FREQ).all()


def test_shooting_without_friction_is_the_linear_orbit():
    """Friction off and ideal avionics: the linear start is periodic up to the RK4 error
    (shooting converges at once), and the response is the exact linear one."""
    model = load_model(MODELS / "rs25_flight.toml", friction="none")
    model = model.replace(avionics=model.avionics.ideal())
    # the ideal valve (the pressure limit's square-root law is a nonlinearity, off for this identity)
    model = model.replace(actuator=dataclasses.replace(model.actuator, pressure_limited=False))
    f = np.array([1.0, 3.0, 7.0])
    st = sine_dwell_points(model, np.full(3, 0.1 * DEG), f, method="shoot", measure_cycles=1)
    lin = linear_freqresp(model, f)
    assert st.converged.all() and (st.periods <= 2).all()
    assert np.max(np.abs(gain_db(st.engine) - gain_db(lin.engine))) < 1e-4
    assert np.max(np.abs(np.degrees(np.angle(st.engine / lin.engine)))) < 1e-3


@pytest.mark.slow
def test_amplitude_list_equals_single_calls_bit_for_bit(tmp_path):
    args = ["freqresp", MODELS / "rs25_ambient.toml", "--freq-hz", "2,5"]
    r = run_cli(*args, "--amplitude-deg", "0.1,0.4", "--json", tmp_path / "many.json",
                "--plot", tmp_path / "family.png")
    assert r.returncode == 0, r.stderr
    many = json.loads((tmp_path / "many.json").read_text())
    assert many["amplitude_deg"] == [0.1, 0.4] and (tmp_path / "family.png").stat().st_size > 0
    assert np.shape(many["piston"]["gain_db"]) == (2, 2)
    for i, a in enumerate(("0.1", "0.4")):
        r = run_cli(*args, "--amplitude-deg", a, "--json", tmp_path / f"one{i}.json")
        assert r.returncode == 0, r.stderr
        one = json.loads((tmp_path / f"one{i}.json").read_text())
        assert one["amplitude_deg"] == many["amplitude_deg"][i]
        assert one["freq_hz"] == many["freq_hz"]
        assert one["engine_held"] == many["engine_held"][i]
        for k in ("piston", "engine"):
            for q in ("gain_db", "phase_deg"):
                assert one[k][q] == many[k][q][i]  # exact float equality


def test_lco_map_and_freqresp_family_share_one_path(hotfire):
    """The LCO describing-function map and the freqresp family are the same dwells."""
    from taos.flight.describing import describing_function_map
    amps = np.array([0.05, 0.2]) * DEG
    f = np.array([1.0, 4.0])
    df = describing_function_map(hotfire, amps, f, settle_s=1.0)
    fam = sine_dwell_family(hotfire, f, amps, settle_s=1.0)
    for i in range(2):
        assert np.array_equal(df.engine[i], fam[i].engine) and np.array_equal(df.piston[i], fam[i].piston)


def test_shooting_family_reports_its_residual(tmp_path):
    r = run_cli("freqresp", MODELS / "rs25_hotfire.toml", "--freq-hz", "1,4", "--amplitude-deg", "0.1,0.3",
                "--steady", "shoot", "--json", tmp_path / "s.json")
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["provenance"]["steady_state"] == "shoot"
    assert len(d["provenance"]["shooting_max_residual"]) == 2
    assert all(x <= 1e-4 for x in d["provenance"]["shooting_max_residual"])


def test_taos_family_equals_single_amplitude_calls(hotfire):
    """The 3-D model's amplitude family is one parallel batch; each row is the single call's."""
    from taos.taos3d import taos_freqresp, taos_freqresp_family, taos_model
    tm = taos_model(hotfire)
    f = [2.0, 5.0]
    amps = [0.1 * DEG, 0.3 * DEG]
    fam = taos_freqresp_family(tm, f, amps, settle_s=0.3)
    for k, a in enumerate(amps):
        one = taos_freqresp(tm, f, a, settle_s=0.3)
        assert np.array_equal(one.engine, fam[k].engine) and np.array_equal(one.piston, fam[k].piston)
        assert one.amplitude_rad == fam[k].amplitude_rad


@pytest.mark.parametrize("kw", [{"integrator": "rk4"}, {"method": "shoot", "max_cycles": 2},
                                {"method": "shoot", "max_cycles": 2, "integrator": "rk4"}])
def test_dwell_batches_on_one_and_two_threads_are_bit_identical(hotfire, kw):
    """The RK4 and shooting dwell batches (one dwell a task on the threads, the longest first)
    give the same bits on one thread as on two (the ETDRK4 one: tests/test_expstep.py)."""
    import numba
    nt = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = sine_dwell_points(hotfire, AMPS, FREQ, settle_s=0.2, **kw)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = sine_dwell_points(hotfire, AMPS, FREQ, settle_s=0.2, **kw)
    finally:
        numba.set_num_threads(nt)
    assert np.array_equal(one.engine, two.engine) and np.array_equal(one.piston, two.piston)
    if one.method == "shoot":
        for q in ("residual", "periods", "converged"):
            assert np.array_equal(getattr(one, q), getattr(two, q))


def test_taos_dwells_on_one_and_two_threads_are_bit_identical(hotfire):
    """The 3-D model's dwell batch (one dwell a task on the threads): one thread's bits on two."""
    import numba
    from taos.taos3d import taos_freqresp_family, taos_model
    tm = taos_model(hotfire)
    nt = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = taos_freqresp_family(tm, [2.0, 5.0], [0.1 * DEG, 0.3 * DEG], settle_s=0.2)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = taos_freqresp_family(tm, [2.0, 5.0], [0.1 * DEG, 0.3 * DEG], settle_s=0.2)
    finally:
        numba.set_num_threads(nt)
    for a, b in zip(one, two):
        assert np.array_equal(a.engine, b.engine) and np.array_equal(a.piston, b.piston)


def test_lco_map_makes_one_describing_function_per_tvc_variant(monkeypatch):
    """The describing function depends on the TVC only: a verdict map over a TVC parameter and a
    flight-loop gain makes one map per TVC value (2, not 4), and every point equals the
    stand-alone prediction for that point exactly."""
    import taos.flight.lco as lco
    from taos.flight.lco_map import SweepAxis, apply_value, lco_map
    from taos.flight.vehicle import load_flight
    from taos.model import load_model

    fl = load_flight(MODELS / "flight" / "core_stage.toml")
    m = load_model(MODELS / "rs25_flight.toml", friction="dahl")
    amps, f = np.array([0.02, 0.1, 0.5]) * DEG, np.array([0.08, 0.15, 0.3])
    calls = []
    real = lco.describing_function_map
    monkeypatch.setattr(lco, "describing_function_map", lambda *a, **k: calls.append(1) or real(*a, **k))
    axes = (SweepAxis("bristle_stiffness", (0.8e7, 2.2e7)), SweepAxis("integral_gain", (0.6, 0.9)))
    mp = lco_map(fl, m, axes, amplitudes_rad=amps, freq_hz=f)
    assert len(calls) == 2
    for i, s0 in enumerate(axes[0].values):
        for j, ki in enumerate(axes[1].values):
            fl2, m2 = apply_value(*apply_value(fl, m, "bristle_stiffness", s0), "integral_gain", ki)
            d = lco.analyse_lco(fl2, m2, amplitudes_rad=amps, freq_hz=f, time_domain=False).to_dict()
            assert bool(mp.lco[i, j]) == d["lco"]
            if d["lco"]:
                assert mp.engine_amplitude_deg[i, j] == d["engine_amplitude_deg"]
            else:
                assert mp.margin_db[i, j] == d["margin_db"]
