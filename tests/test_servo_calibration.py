"""The shipped servoactuator against a heritage-like flight-actuator specification (issue 24.1).

The one parameter set ``models/actuators/tvc_actuator.toml`` is checked, in the LABORATORY
condition (rigid load K_L -> 1e12 N/m, no gimbal friction, unity avionics: the linear simplex
block, which takes the command after the avionics and the friction torque as a separate input),
against:

- command -> engine peaking <= 3 dB above its DC gain;
- position-loop margins >= 45 deg and 6 dB, the loop broken at the command summing junction:
  T = x_p / (R theta_c), L = T / (1 - T) (as ``masv coupling`` breaks it);

and, with the public hot-fire load path (205,000 lbf/in), the load mode damped to zeta ~ 0.25 (0.241)
by the servo's own physics while it stays stiff in the flight LCO band; and the static stiffness / DC tracking the paper relies on (sec. 3.1:
the piston nulls its error at DC). Each figure is computed by a route independent of the code
under test where one exists: margins by python-control (``control.margin`` on the loop built by
``control.feedback``) against :func:`taos.stability.loop_margins` on the sampled response;
peaking by python-control's frequency response; damping from the eigenvalues of A; stiffness
against the closed-form servo compliance (Merritt ch. 8, valve and oil column neglected).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from taos.model import load_model
from taos.planar.simplex import simplex_state_space
from taos.stability import loop_margins

from .conftest import MODELS, run_cli

LBF_PER_IN = 4.4482216152605 / 0.0254  # N/m
RS25 = ["rs25_ambient", "rs25_hotfire", "rs25_flight"]


def _lab(m):
    """Laboratory condition: rigid load path (friction and avionics are outside the linear block)."""
    return dataclasses.replace(m, structure=dataclasses.replace(m.structure, load_stiffness_N_per_m=1e12))


def _ctl(m, inp="command_rad", out="x_p_m", scale=1.0):
    import control

    ss = simplex_state_space(m, "pitch")
    i, o = ss.input_index(inp), ss.output_index(out)
    return control.ss(ss.A, ss.B[:, [i]], scale * ss.C[[o], :], ss.D[[o]][:, [i]])


def _T(m):
    """T = x_p / (R theta_c) as a python-control system."""
    return _ctl(m, scale=1.0 / m.actuator.moment_arm_m)


@pytest.fixture(scope="module")
def hot():
    return load_model(MODELS / "rs25_hotfire.toml")


def test_one_servo_for_the_three_files():
    acts = [load_model(MODELS / f"{n}.toml").actuator for n in RS25]
    assert acts[1] == acts[0] and acts[2] == acts[0]


@pytest.mark.parametrize("cond", ["lab", "hotfire"])
def test_position_loop_margins(hot, cond):
    """>= 45 deg and 6 dB in the lab; the hot-fire load keeps them (the old servo had 30.6 deg)."""
    import control

    m = _lab(hot) if cond == "lab" else hot
    L = control.feedback(_T(m), 1, sign=1)            # T / (1 - T)
    gm, pm, wcg, wcp = control.margin(L)
    gm_db = 20 * math.log10(gm)
    f = np.logspace(-2, 2.5, 6000)
    ss = simplex_state_space(m, "pitch")
    T = ss.freqresp(f, "command_rad", "x_p_m") / m.actuator.moment_arm_m
    lm = loop_margins(f, T / (1 - T))
    assert lm.min_phase_margin[0] == pytest.approx(pm, abs=0.05)
    assert lm.min_gain_margin_db == pytest.approx(gm_db, abs=0.05)
    assert pm >= 45 and gm_db >= 6
    # the shipped figures quoted in models/actuators/tvc_actuator.toml
    want = {"lab": (20.9, 64.5), "hotfire": (16.7, 58.9)}[cond]
    assert (gm_db, pm) == (pytest.approx(want[0], abs=0.06), pytest.approx(want[1], abs=0.06))


def test_lab_peaking_at_most_3_db(hot):
    import control

    m = _lab(hot)
    sys = _ctl(m, out="theta_rad")
    w = 2 * math.pi * np.logspace(-2, 2, 8000)
    mag = np.abs(control.frequency_response(sys, w).frdata[0, 0])
    dc = abs(control.dcgain(sys))
    assert dc == pytest.approx(_dc_engine_gain(m), rel=1e-9)
    peak_db = 20 * math.log10(mag.max() / dc)
    assert peak_db <= 3.0
    assert peak_db == pytest.approx(0.0, abs=0.02)
    bw_hz = w[np.argmax(20 * np.log10(mag / dc) < -3)] / (2 * math.pi)
    assert bw_hz == pytest.approx(5.6, abs=0.03)   # the cost: the flat band ends near 6 Hz


def _least_damped_load_mode(m):
    ev = np.linalg.eigvals(simplex_state_space(m, "pitch").A)
    osc = [e for e in ev if e.imag > 1.0 and abs(e) / (2 * math.pi) < 40.0]
    e = min(osc, key=lambda e: -e.real / abs(e))
    return -e.real / abs(e), abs(e) / (2 * math.pi)


def test_hotfire_load_mode_damped_by_the_servo(hot):
    """zeta ~ 0.25 (issue 24.1): 0.241, the most the DPF gives while the servo stays stiff in the
    flight LCO band (test_servo_stiff_in_the_flight_lco_band; the trade is stated in the set)."""
    zeta, f = _least_damped_load_mode(hot)
    assert zeta >= 0.24
    assert (zeta, f) == (pytest.approx(0.241, abs=0.002), pytest.approx(4.84, abs=0.02))
    # the damping is the dynamic pressure feedback's: without it the mode is barely damped
    bare = dataclasses.replace(hot, actuator=dataclasses.replace(hot.actuator, pressure_feedback_gain_m_per_s_Pa=0.0))
    assert _least_damped_load_mode(bare)[0] < 0.1


def test_soft_ambient_load_path_stays_peaky(ambient):
    """The finding, shown: with the public ambient K_L, R, J the load resonance lies inside the
    servo's band and the credible servo leaves it peaky (+8.5 dB) and less damped (0.14)."""
    import control

    zeta, _ = _least_damped_load_mode(ambient)
    assert zeta == pytest.approx(0.141, abs=0.002)
    sys = _ctl(ambient, out="theta_rad")
    mag = np.abs(control.frequency_response(sys, 2 * math.pi * np.logspace(-2, 1.5, 6000)).frdata[0, 0])
    assert 20 * math.log10(mag.max() / abs(control.dcgain(sys))) == pytest.approx(8.5, abs=0.05)


def _static_compliance(a):
    """Servo static compliance c = (K_c + C_l) / (A^2 K_v) [m/N]: at DC the washout removes the
    pressure feedback and the valve flow K_v A e balances the pressure flow (K_c + C_l) F / A."""
    return (a.flow_pressure_coefficient_m3_per_s_Pa + a.leakage_coefficient_m3_per_s_Pa) / (
        a.piston_area_m2 ** 2 * a.loop_gain_per_s)


def _dc_engine_gain(m):
    """theta/theta_c at DC: x_p = R theta_c - c F_L, theta = x_p/R - F_L/(K_L R), R F_L = K_n theta,
    so theta/theta_c = 1 / (1 + K_n (c + 1/K_L) / R^2)."""
    R = m.actuator.moment_arm_m
    return 1.0 / (1.0 + m.engine.rotational_stiffness_Nm_per_rad
                  * (_static_compliance(m.actuator) + 1.0 / m.structure.load_stiffness_N_per_m) / R ** 2)


def test_dc_tracking_and_static_stiffness(hot):
    """Paper sec. 3.1: the piston nulls its error at DC. Under a steady load F the piston's error
    is c F (c the static compliance above), a stiffness 10 x the hot-fire K_L; the engine's DC
    gain is short of 1 only by the feedline spring K_n on the load path and servo; and at the
    bounding flight friction torque the piston error is below one command LSB of engine angle."""
    import control

    a = hot.actuator
    assert control.dcgain(_ctl(hot, out="theta_rad")) == pytest.approx(_dc_engine_gain(hot), rel=1e-9)
    assert control.dcgain(_T(_lab(hot))) == pytest.approx(_dc_engine_gain(_lab(hot)), rel=1e-6)
    xp = control.dcgain(_ctl(hot, inp="friction_torque_Nm", out="x_p_m"))
    fl = control.dcgain(_ctl(hot, inp="friction_torque_Nm", out="load_force_N"))
    k_static = 1.0 / _static_compliance(a)
    assert -fl / xp == pytest.approx(k_static, rel=1e-6)
    assert k_static / hot.structure.load_stiffness_N_per_m > 10
    err_deg = math.degrees(144000 * LBF_PER_IN * 0.0254 ** 2 / a.moment_arm_m / k_static / a.moment_arm_m)
    assert err_deg < math.degrees(hot.avionics.lsb_rad)


def test_servo_stiff_in_the_flight_lco_band(hot):
    """The pressure feedback makes the servo compliant above its washout corner; in the 0.1-0.2 Hz
    flight LCO band the servo stiffness |F/x_p| = A |s + K_v| / |K_pf s tau/(1 + s tau) + K_c/A|
    stays >= 4.6 x the flight load stiffness (115,000 lbf/in), so the piston follows its command
    while friction holds the engine (paper sec. 3.1; figures quoted in the parameter set)."""
    a = hot.actuator
    f = np.array([0.15, 0.2])
    ss = simplex_state_space(hot, "pitch")
    k_model = np.abs(ss.freqresp(f, "friction_torque_Nm", "load_force_N")
                     / ss.freqresp(f, "friction_torque_Nm", "x_p_m"))
    s = 2j * math.pi * f
    tau = a.pressure_feedback_time_constant_s
    k_formula = np.abs(a.piston_area_m2 * (s + a.loop_gain_per_s) / (
        a.pressure_feedback_gain_m_per_s_Pa * s * tau / (1 + s * tau)
        + (a.flow_pressure_coefficient_m3_per_s_Pa + a.leakage_coefficient_m3_per_s_Pa) / a.piston_area_m2))
    assert k_model == pytest.approx(k_formula, rel=0.03)  # 2.4 %: the formula neglects the oil column and valve
    assert k_model / LBF_PER_IN == pytest.approx([694_000, 537_000], rel=0.005)
    assert np.all(k_model >= 4.6 * 115000 * LBF_PER_IN)


@pytest.mark.parametrize("name", RS25)
def test_taos_info_shows_the_servo_figures_python_control_finds(name):
    """``taos info --json`` reports the servo's figures (``servo``: position-loop margins with the
    model's load and in the laboratory, laboratory peaking and bandwidth, load-mode frequency and
    damping); checked against python-control on the state-space loop (``control.margin`` of
    T/(1-T), eigenvalues of A), not against the sampled route that computes them."""
    import json

    import control

    m = load_model(MODELS / f"{name}.toml")
    r = run_cli("info", name, "--json", "-")
    assert r.returncode == 0, r.stderr
    sv = json.loads(r.stdout)["servo"]["pitch"]
    for cond, mm in (("position_loop", m), ("laboratory", _lab(m))):
        gm, pm, _, wcp = control.margin(control.feedback(_T(mm), 1, sign=1))
        got = sv[cond]
        assert got["gain_margin_db"] == pytest.approx(20 * math.log10(gm), abs=0.02)
        assert got["phase_margin_deg"] == pytest.approx(pm, abs=0.02)
        assert got["crossover_hz"] == pytest.approx(wcp / (2 * math.pi), rel=2e-3)
    zeta, f = _least_damped_load_mode(m)
    assert sv["load_mode"]["damping_ratio"] == pytest.approx(zeta, rel=1e-9)
    assert sv["load_mode"]["freq_hz"] == pytest.approx(f, rel=1e-9)
    sys_ = _ctl(_lab(m), out="theta_rad")
    mag = np.abs(control.frequency_response(sys_, 2 * math.pi * np.logspace(-2, 2, 8000)).frdata[0, 0])
    assert sv["laboratory"]["engine_peaking_db"] == pytest.approx(20 * math.log10(mag.max() / abs(control.dcgain(sys_))),
                                                                  abs=0.02)
    assert sv["laboratory"]["engine_bandwidth_3db_hz"] == pytest.approx(5.6, abs=0.03)
