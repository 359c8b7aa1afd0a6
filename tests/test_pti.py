"""What flight shows (issue 43, seed paper sec. 5): the loop broken at the PTI and the TVC
responses reconstructed from a flight record (taos.flight.pti)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.errors import InputError
from taos.flight.ascent import Pti, load_ascent
from taos.flight.pti import analyse_ptis, measure_pti
from taos.flight.pti_record import FlightRecord, load_flight_record


@pytest.fixture(scope="module")
def ascent():
    return load_ascent("ascent")


def _flown(ascent, law, start, end, attitude0_rad=0.0):
    from taos.flight.ascent_sim import simulate_ascent
    from taos.flight.lco import with_bounding_avionics
    from taos.model import load_model

    m = with_bounding_avionics(load_model(ascent.tvc_model, friction=law))
    h = simulate_ascent(ascent, m, axes=("yaw",), start_s=start, end_s=end, dt_s=5e-4, attitude0_rad=attitude0_rad)
    return FlightRecord.from_history(h), m


def test_friction_off_flight_gives_the_linear_open_loop(ascent):
    """Acceptance: the loop reconstructed from a simulated flight without friction equals the
    project's linear open loop (broken at the PTI injection, frozen at the window's middle) at
    every PTI line within 0.5 dB / 3 deg; the piston response its linear one likewise."""
    rec, m = _flown(ascent, "none", 150.0, 212.0)   # from rest: only the PTI moves the loop
    res = analyse_ptis(rec, ascent, m, describing=False)
    (r,) = res.responses
    assert r.kind == "multisine" and r.freq_hz.size == 21 and r.freq_hz[0] == pytest.approx(0.1)
    for meas, model in ((r.loop, r.model.loop), (r.piston, r.model.piston)):
        ratio = meas / model
        assert np.max(np.abs(20 * np.log10(np.abs(ratio)))) < 0.5
        assert np.max(np.abs(np.degrees(np.angle(ratio)))) < 3.0
    v = r.friction()
    assert not v["visible"] and abs(v["low_band_gain_db"]) < 0.2


def _tf_loop_record(tmp_path, noise_rms_rad=0.0):
    """An independent simulator: a known loop L(s) = K (s + z) / (s (s + p) (tau s + 1)) closed
    around the PTI by scipy.signal.lsim (u = (r + d) / (1 + L), u_fcs = u - r), a first-order
    piston x_p = R_m u / (tau_p s + 1), written as telemetry CSV."""
    import scipy.signal as ss

    K, z, p, tau = 1.2, 0.3, 2.0, 0.05
    num = K * np.array([1.0, z])
    den = np.polymul([1.0, p, 0.0], [tau, 1.0])
    pti = Pti(start_s=10.0, kind="multisine", duration_s=20.0, amplitude_rad=math.radians(0.25),
              low_frequency_hz=0.1, high_frequency_hz=3.0, axes=("pitch",))
    t = np.arange(0.0, 60.0, 0.01)
    r = np.where((t >= pti.start_s) & (t <= pti.end_s), pti.signal()(t - pti.start_s), 0.0)
    rng = np.random.default_rng(4)
    d = noise_rms_rad * rng.standard_normal(t.size)
    cl = ss.lti(den, np.polyadd(den, num))          # 1 / (1 + L)
    _, u, _ = ss.lsim(cl, r + d, t)
    Rm, taup = 0.5, 0.02
    _, xp, _ = ss.lsim(ss.lti([Rm], [taup, 1.0]), u, t)
    path = tmp_path / "telemetry.csv"
    np.savetxt(path, np.column_stack([t, r, u, xp]), delimiter=",",
               header="t_s,pitch_pti_rad,pitch_command_rad,pitch_piston_m", comments="")
    s = 2j * np.pi * np.asarray(pti.signal().freqs_hz)
    L = np.polyval(num, s) / np.polyval(den, s)
    return path, pti, L, Rm / (taup * s + 1)


def test_independent_simulator_is_reconstructed_to_its_known_loop(tmp_path):
    """Acceptance: a record made by a test-written loop (scipy.signal.lsim of a known transfer
    function, not taos code) is reconstructed to its known loop and piston response."""
    path, pti, L, Gp = _tf_loop_record(tmp_path)
    rec = load_flight_record(path)
    m = measure_pti(rec, "pitch", pti)
    np.testing.assert_allclose(m.freq_hz, pti.signal().freqs_hz)
    assert np.max(np.abs(20 * np.log10(np.abs(m.loop / L)))) < 0.1
    assert np.max(np.abs(np.degrees(np.angle(m.loop / L)))) < 0.5
    assert np.max(np.abs(m.piston / Gp - 1)) < 0.01


def test_noise_is_covered_by_the_stated_uncertainty(tmp_path):
    """With a white disturbance in the loop the errors against the known loop lie within the
    stated 1-sigma mostly (at least 60 % inside 1.5 sigma, all inside 5 sigma)."""
    path, pti, L, _ = _tf_loop_record(tmp_path, noise_rms_rad=math.radians(0.02))
    m = measure_pti(load_flight_record(path), "pitch", pti)
    err = np.abs(m.loop / L - 1)
    assert np.all(np.isfinite(m.loop_sigma)) and np.all(m.loop_sigma > 0)
    z = err / m.loop_sigma
    assert np.mean(z < 1.5) >= 0.6 and np.all(z < 5)
    assert np.all((m.loop_coherence >= 0) & (m.loop_coherence <= 1)) and m.loop_coherence[:10].min() > 0.8


def test_friction_on_lowers_the_low_frequency_gain_and_the_verdict_says_so(ascent):
    """Acceptance: with gimbal friction (LuGre, the bounding flight level) the reconstructed
    low-frequency loop gain of the 400 s multisine drops below the linear model by more than
    twice its uncertainty (paper sec. 5: a gain reduction consistent with friction), and the
    verdict says so."""
    rec, m = _flown(ascent, "lugre", 340.0, 445.0, attitude0_rad=0.002)   # the limit cycle running
    (r,) = analyse_ptis(rec, ascent, m, describing=False).responses
    v = r.friction()
    assert v["visible"] and v["low_band_gain_db"] < -1.0
    assert v["low_band_gain_db"] < -2 * v["sigma_db"]
    assert v["verdict"].startswith("friction visible")


def test_bad_records_are_refused(tmp_path, ascent):
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,pitch_pti_rad,pitch_command_rad\n0,0,0\n")
    with pytest.raises(InputError, match="pitch_piston_m"):
        load_flight_record(bad)
    path, pti, _, _ = _tf_loop_record(tmp_path)
    rec = load_flight_record(path)
    with pytest.raises(InputError, match="PTI window"):
        analyse_ptis(rec, ascent, None)


def test_cli_bad_input_writes_nothing(tmp_path):
    from taos.cli import main

    out = tmp_path / "o"
    assert main(["pti", str(tmp_path / "missing.h5"), "--flight", "ascent", "--out", str(out)]) == 2
    assert not out.exists()


def test_duty_cycle_flow_integrates_to_piston_travel_times_area(ascent):
    """Duty cycle (taos.flight.duty): the piston flow A v_p integrates to A times the piston
    travel read from the recorded positions (sum |dx_p|) within 1 %, and the valve flow obeys the
    continuity equation int (A q - (K_c + C_l) P_L) dt = A dx_p + (V_t / 4 beta) dP_L within 1 %."""
    from taos.flight.ascent_sim import simulate_ascent
    from taos.flight.duty import duty_cycle
    from taos.flight.lco import with_bounding_avionics
    from taos.model import load_model

    m = with_bounding_avionics(load_model(ascent.tvc_model, friction="lugre"))
    h = simulate_ascent(ascent, m, axes=("yaw",), start_s=340.0, end_s=440.0, dt_s=5e-4, attitude0_rad=0.002,
                        record_interval_s=0.002)
    d = duty_cycle(h, m, "yaw", 380.0, 440.0)
    sel = (h.t_s >= 380.0) & (h.t_s <= 440.0)
    x = h.signal("piston_m", "yaw")[sel]
    travel = float(np.sum(np.abs(np.diff(x))))
    A = m.actuator.piston_area_m2
    assert A * d.piston_travel_m == pytest.approx(A * travel, rel=0.01)
    assert d.piston_volume_m3 == pytest.approx(A * travel, rel=0.01)   # the acceptance sentence, verbatim
    act = m.actuator
    P = h.signal("load_pressure_Pa", "yaw")[sel]
    q = h.signal("valve_flow_m_s", "yaw")[sel]
    net = np.trapezoid(A * q - (act.flow_pressure_coefficient_m3_per_s_Pa + act.leakage_coefficient_m3_per_s_Pa) * P,
                       h.t_s[sel])
    expect = A * (x[-1] - x[0]) + act.trapped_volume_m3 / (4 * act.oil_bulk_modulus_Pa) * (P[-1] - P[0])
    scale = float(np.trapezoid(np.abs(A * q), h.t_s[sel]))
    assert abs(net - expect) < 0.01 * scale
    assert d.reversals > 0 and d.peak_flow_m3_s > d.mean_flow_m3_s > 0 and d.mean_supply_power_W > 0
    # the limits are the model's ([actuator] rated_flow, pump_capacity), read against
    assert d.flow_limit_m3_s == act.rated_flow_m3_per_s > 0
    assert d.to_dict()["peak_flow_fraction_of_limit"] == pytest.approx(d.peak_flow_m3_s / act.rated_flow_m3_per_s)
    from taos.flight.duty import duty_summary
    s = duty_summary(h, m, 380.0, 440.0)
    assert s["engine"]["mean_flow_fraction_of_pump"] == pytest.approx(d.mean_flow_m3_s / act.pump_capacity_m3_per_s)
    assert s["axes"]["yaw"]["piston_volume_m3"] == d.piston_volume_m3


def test_duty_limits_are_model_keys():
    """[actuator] rated_flow and pump_capacity: optional (0: no limit), with units, bounded."""
    from taos.model import load_model
    m = load_model("rs25_flight")
    a = m.actuator
    assert a.rated_flow_m3_per_s == pytest.approx(a.piston_area_m2 * a.max_rate_m_per_s)
    v = m.with_values({"actuator.pump_capacity": "20 gal/min"})
    assert v.actuator.pump_capacity_m3_per_s == pytest.approx(20 * 3.785411784e-3 / 60)
    assert m.with_values({"actuator.rated_flow": "0 m**3/s"}).actuator.rated_flow_m3_per_s == 0.0
    for bad in ("20 psi", "1e-300 m**3/s", "5 m**3/s"):
        with pytest.raises(InputError):
            m.with_values({"actuator.rated_flow": bad})


def test_reversal_counter():
    from taos.flight.duty import reversals
    t = np.linspace(0, 10, 10001)
    assert reversals(np.sin(2 * np.pi * t), 0.01) == 20          # 10 cycles: 20 turning points
    assert reversals(1e-4 * np.sin(2 * np.pi * t), 0.01) == 0     # inside the deadband
