"""The hydraulic duty cycle of an LCO (issue 43, part 2; taos.flight.duty on the ``taos lco``
time-domain run): the from-rest run records load pressure, valve flow and piston rate, and its
JSON carries ``time_domain.duty`` over the measurement window, the same summary the ascent gives."""

from __future__ import annotations

import json

import numpy as np
import pytest

from taos.flight.lco import analyse_lco
from taos.flight.vehicle import load_flight
from taos.harmonics import harmonic_amplitudes
from taos.model import Structure, load_model

from .conftest import MODELS

LBF_IN = 4.4482216152605 / 0.0254


@pytest.fixture(scope="module")
def report():
    """Paper fig. 7's soft case (115,000 lbf/in, Dahl): a limit cycle of about 0.1 deg at 0.12 Hz.
    A 2 x 2 describing-function map (the time domain is what is measured here)."""
    fl = load_flight(MODELS / "flight" / "core_stage.toml")
    m = load_model(MODELS / "rs25_flight.toml", friction="dahl").replace(structure=Structure(115000 * LBF_IN))
    return analyse_lco(fl, m, amplitudes_rad=np.radians([0.05, 0.2]), freq_hz=[0.1, 0.2], duration_s=160.0,
                       window_s=60.0, extend=0)


def test_lco_duty_flow_integrates_to_piston_travel_and_reversals_are_twice_the_frequency(report):
    """Over the measurement window: the piston flow A v_p integrates to A times the travel read from
    the recorded positions (sum |dx_p|) within 1 %; the valve flow obeys continuity
    int (A q - (K_c + C_l) P_L) dt = A dx_p + (V_t / 4 beta) dP_L within 1 % of int |A q| dt; and a
    limit cycle reverses twice per cycle: the reversals counted over the window T are 2 f T to
    within the one reversal a count can miss at the window's ends."""
    d = report.to_dict()
    td = d["time_domain"]
    assert td["lco"], "the soft Dahl case limit-cycles (paper fig. 7)"
    duty = td["duty"]
    yaw = duty["axes"]["yaw"]
    h, m = report.history, report.model
    sel = h.t_s >= h.t_s[-1] - td["window_s"]
    assert yaw["start_s"] == pytest.approx(h.t_s[sel][0]) and yaw["end_s"] == pytest.approx(h.t_s[-1])
    act = m.actuator
    A = act.piston_area_m2
    x = h.piston_m[sel]
    travel = float(np.sum(np.abs(np.diff(x))))
    assert yaw["piston_volume_m3"] == pytest.approx(A * travel, rel=0.01)
    assert yaw["piston_travel_m"] == pytest.approx(travel, rel=0.01)
    P, q, t = h.load_pressure_Pa[sel], h.valve_flow_m_s[sel], h.t_s[sel]
    net = np.trapezoid(A * q - (act.flow_pressure_coefficient_m3_per_s_Pa + act.leakage_coefficient_m3_per_s_Pa) * P, t)
    expect = A * (x[-1] - x[0]) + act.trapped_volume_m3 / (4 * act.oil_bulk_modulus_Pa) * (P[-1] - P[0])
    assert abs(net - expect) < 0.01 * float(np.trapezoid(np.abs(A * q), t))
    T = yaw["end_s"] - yaw["start_s"]
    print(f"reversals {yaw['reversals']} in {T:g} s, 2 f T = {2 * td['frequency_hz'] * T:.3f}; "
          f"rate {yaw['reversals_per_s']:.4f} /s against 2 f = {2 * td['frequency_hz']:.4f} /s")
    assert abs(yaw["reversals"] - 2 * td["frequency_hz"] * T) <= 1.0
    assert yaw["reversals_per_s"] == pytest.approx(2 * td["frequency_hz"], abs=1.0 / T)
    # a near-sinusoidal cycle sweeps 4 X_p a cycle: mean |Q_p| = 4 A X_p f (X_p the piston's fundamental;
    # within 5 %, its harmonics' share: achieved -1.4 %)
    xp = harmonic_amplitudes(t, x, td["frequency_hz"])[0]
    assert yaw["piston_volume_m3"] / T == pytest.approx(4 * A * xp * td["frequency_hz"], rel=0.05)
    # against the model's limits, as the ascent's summary (taos.flight.duty.duty_summary)
    assert yaw["flow_limit_m3_s"] == act.rated_flow_m3_per_s > 0
    assert 0 < yaw["peak_flow_fraction_of_limit"] < 1 and duty["engine"]["mean_flow_fraction_of_pump"] > 0
    json.dumps(d, allow_nan=False)


def test_lco_history_records_the_hydraulics(report, tmp_path):
    import h5py

    h = report.history
    assert h.has_hydraulics and h.axes == ("yaw",) and h.signal("load_pressure_Pa", "yaw") is h.load_pressure_Pa
    h.to_hdf5(tmp_path / "h.h5")
    with h5py.File(tmp_path / "h.h5") as f:
        assert np.array_equal(f["valve_flow_m_s"][()], h.valve_flow_m_s)
    rep = analyse_lco(report.prediction.flight, report.model, df=report.prediction.df, avionics="model",
                      time_domain=False, extend=0)
    assert rep.to_dict()["time_domain"] is None and rep.duty() is None
