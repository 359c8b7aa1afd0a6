"""Actuator and gimbal limits (issue 12.5): valve flow saturation (rate limit), supply-pressure
limit (stall force) and hard stops at the gimbal range, in the planar simplex model."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from taos.planar.avionics import Avionics
from taos.model import load_model
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import integrate_plant

from .conftest import MODELS

DEG = math.pi / 180
DT = 2e-4


def _ideal(m):
    """No friction, unity avionics: the limits alone."""
    return m.with_friction("none").replace(avionics=Avionics(gain_table_rad=(0.0,), gain_table=(1.0,)))


def _ideal_valve(m):
    """The same model with the supply-pressure limit off (an ideal valve on an unlimited supply):
    the piston then slews at exactly the valve's no-load rate v_max."""
    return m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False))


def _load_flow_slew(p, sign, act):
    """The slew rate the square-root law gives with the valve open at its no-load rate v_max:
    v_max times the time mean of sqrt(1 - sgn(v) P_L / P_s) over the recorded load pressures
    ``p`` [Pa] (the static load-flow curve, Merritt 1967 ch. 3, oil compressibility neglected)."""
    return sign * act.max_rate_m_per_s * float(np.mean(np.sqrt(1.0 - sign * p / act.supply_pressure_Pa)))


def _step(m, amp_rad, t_end=1.5, t0=0.05):
    plant = simplex_plant(m)
    n = int(t_end / DT)
    t = np.arange(n + 1) * DT
    r = np.where(t >= t0, amp_rad, 0.0).reshape(-1, 1)
    y, _ = integrate_plant(plant, m, r, DT, 1)
    o = plant.ss.output_index
    return t, y[:, o("x_p_m")], y[:, o("theta_rad")], y[:, o("load_force_N")], y[:, o("p_load_Pa")]


@pytest.fixture(scope="module")
def ambient_ideal():
    return _ideal(load_model(MODELS / "rs25_ambient.toml"))


def test_shipped_limits_documented_values(ambient_ideal):
    a, e = ambient_ideal.actuator, ambient_ideal.engine
    assert a.max_rate_m_per_s == pytest.approx(20 * 0.0254)
    assert math.degrees(e.gimbal_range_rad) == pytest.approx(10.5)
    assert a.stall_force_N == pytest.approx(15 * 3000 * 4.4482216152605)  # 45,000 lbf


def test_5_deg_step_is_rate_limited_at_the_documented_rate(ambient_ideal):
    """The piston slews at the valve's no-load rate v_max (20 in/s, engine 36 deg/s) through the
    middle of the step; the engine follows it through the load spring, ringing at the load
    resonance (peak rate below twice the slew), where the unlimited servo reaches twice the slew
    (78 deg/s with the recalibrated K_v = 20 1/s; > 100 deg/s with the former K_v = 40 1/s).
    The piston exceeds v_max only by the oil column's decompression as the load force falls."""
    m = _ideal_valve(ambient_ideal)
    vmax = m.actuator.max_rate_m_per_s
    R = m.actuator.moment_arm_m
    t, xp, th, _, _ = _step(m, 5 * DEG)
    vp = np.gradient(xp, DT)
    assert vp.max() <= vmax * 1.10
    x5 = R * 5 * DEG
    i0, i1 = np.argmax(xp > 0.2 * x5), np.argmax(xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(vmax, rel=0.03)
    assert np.gradient(th, DT).max() < 2 * vmax / R
    assert th[-1] > 4.5 * DEG  # still arriving: K_n and the slow pressure-feedback filter
    # with the supply-pressure limit (the shipped default) the valve's square-root law slows the
    # slew to the load-flow curve's rate at the load pressure the engine's acceleration asks for
    # (measured 0.80 v_max, within 2.7 % of the curve: oil compressibility and K_c), and the load
    # pressure stays below P_s (measured 0.81 P_s)
    t, xp, th, _, p = _step(ambient_ideal, 5 * DEG)
    i0, i1 = np.argmax(xp > 0.2 * x5), np.argmax(xp > 0.8 * x5)
    slew = (xp[i1] - xp[i0]) / (t[i1] - t[i0])
    assert slew == pytest.approx(_load_flow_slew(p[i0:i1], 1.0, ambient_ideal.actuator), rel=0.04)
    assert slew < 0.9 * vmax
    assert np.abs(p).max() <= 1.05 * ambient_ideal.actuator.supply_pressure_Pa
    free = m.replace(actuator=dataclasses.replace(m.actuator, max_rate_m_per_s=0.0))
    _, _, th_free, _, _ = _step(free, 5 * DEG, t_end=0.5)
    assert np.gradient(th_free, DT).max() > 2 * vmax / R


def test_command_beyond_the_hard_stop_holds_the_engine_in_range(ambient_ideal):
    """A 12 deg command against the 10.5 deg stop: the engine settles at the stop plus the
    contact's elastic deflection R F_L / k_s, and never passes it by more than the impact's
    dynamic penetration omega sqrt(J / k_s)."""
    m = ambient_ideal
    e = m.engine
    t, xp, th, fl, _ = _step(m, 12 * DEG, t_end=2.0)
    R = m.actuator.moment_arm_m
    held = th[t > 1.5]
    static = np.abs(R * fl[t > 1.5]).max() / e.hard_stop_stiffness_Nm_per_rad
    assert held.min() >= e.gimbal_range_rad
    assert held.max() <= e.gimbal_range_rad + 1.05 * static
    w_hit = m.actuator.max_rate_m_per_s / R
    assert th.max() <= e.gimbal_range_rad + w_hit * math.sqrt(e.inertia("pitch") / e.hard_stop_stiffness_Nm_per_rad)


def test_supply_pressure_limits_the_piston_force_to_stall(ambient_ideal):
    """With the supply-pressure limit on, pushing against the hard stop holds the piston at the
    stall force A P_s (load pressure P_s); without it the position loop pushes the load path on
    towards x_c, far beyond what the supply can give."""
    act = dataclasses.replace(ambient_ideal.actuator, pressure_limited=True)
    m = ambient_ideal.replace(actuator=act)
    t, xp, th, fl, p = _step(m, 14 * DEG, t_end=2.0)
    # transient: at the stop's impact the load spring drives the piston back into the oil column;
    # the valve's square-root law flows back to supply past P_s and the cross-port relief opens
    # above P_r = P_s (measured 1.004 P_s; the soft flow factor without relief reached 1.23 P_s)
    assert np.abs(p).max() <= act.supply_pressure_Pa * 1.05
    assert p[t > 1.5].mean() == pytest.approx(act.supply_pressure_Pa, rel=0.05)
    _, _, _, _, p_free = _step(_ideal_valve(ambient_ideal), 14 * DEG, t_end=2.0)
    assert np.abs(p_free).max() > 1.5 * act.supply_pressure_Pa


def test_rate_limit_phase_loss_shows_in_the_describing_function_map(ambient_ideal):
    """The describing-function map at 1 Hz: small amplitudes are linear; at 10 deg the rate
    demand (63 deg/s) exceeds the 36 deg/s slew and the engine response loses gain and phase."""
    from taos.flight.describing import describing_function_map
    df = describing_function_map(ambient_ideal, np.array([0.5, 10.0]) * DEG, [1.0])
    small, big = df.engine[0, 0], df.engine[1, 0]
    assert abs(small) == pytest.approx(1.0, abs=0.1)
    assert abs(big) < 0.8 * abs(small)
    assert math.degrees(np.angle(big) - np.angle(small)) < -10.0


# -- 3-D TAOS model: the same limits ---------------------------------------------------------
@pytest.fixture(scope="module")
def taos_ambient():
    from taos.taos3d import load_taos_model
    tm = load_taos_model(MODELS / "rs25_ambient.toml", friction="none")
    return dataclasses.replace(tm, base=_ideal(tm.base))


def _ideal_valve_3d(tm):
    """The 3-D model with the supply-pressure limit off (:func:`_ideal_valve`)."""
    return dataclasses.replace(tm, base=_ideal_valve(tm.base))


def _step3d(tm, amp_rad, t_end=1.5, t0=0.05, pressure=False):
    from taos.taos3d import dynamics as _dy
    from taos.taos3d.simulate import run_samples
    n = int(t_end / DT)
    t = np.arange(n + 1) * DT
    cmd = np.zeros((n + 1, 2))
    cmd[:, 0] = np.where(t >= t0, amp_rad, 0.0)
    out = run_samples(tm, cmd, DT, 1)
    col = {k: i for i, k in enumerate(_dy.REC)}
    res = (t, out[:, col["xp_pitch"]], out[:, col["theta_pitch"]], out[:, col["fl_pitch"]])
    return res + (out[:, col["pl_pitch"]],) if pressure else res


def test_3d_5_deg_step_is_rate_limited_at_the_documented_rate(taos_ambient):
    """TAOS: the pitch piston slews at v_max through the middle of a 5 deg step with an ideal
    valve, and at the square-root law's load-flow rate with the supply-pressure limit on (the
    shipped default), the load pressure within 1.05 P_s."""
    act = taos_ambient.base.actuator
    vmax = act.max_rate_m_per_s
    R = act.moment_arm_m
    t, xp, th, _ = _step3d(_ideal_valve_3d(taos_ambient), 5 * DEG)
    x5 = R * 5 * DEG
    i0, i1 = np.argmax(xp > 0.2 * x5), np.argmax(xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(vmax, rel=0.03)
    assert np.gradient(th, DT).max() < 2 * vmax / R
    t, xp, th, _, p = _step3d(taos_ambient, 5 * DEG, pressure=True)
    i0, i1 = np.argmax(xp > 0.2 * x5), np.argmax(xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(_load_flow_slew(p[i0:i1], 1.0, act), rel=0.04)
    assert np.abs(p).max() <= 1.05 * act.supply_pressure_Pa


def test_3d_command_beyond_the_hard_stop_holds_the_engine_in_range(taos_ambient):
    """TAOS: a 12 deg pitch command settles the engine at the 10.5 deg stop plus the contact's
    elastic deflection (the actuator torque R F_L over k_s) and the gimbal chain's own
    compliance under that torque (the engine angle includes the FEM halves' rotation)."""
    e = taos_ambient.base.engine
    R = taos_ambient.base.actuator.moment_arm_m
    t, xp, th, fl = _step3d(taos_ambient, 12 * DEG, t_end=2.0)
    held = th[t > 1.5]
    torque = np.abs(R * fl[t > 1.5]).max()
    kchain = float(np.linalg.eigvalsh(taos_ambient.chain_stiffness[3:, 3:]).min())
    assert held.min() >= e.gimbal_range_rad - torque / kchain
    assert held.max() <= e.gimbal_range_rad + 1.05 * torque / e.hard_stop_stiffness_Nm_per_rad + torque / kchain


# -- both directions: the negative stop, the negative rate and pressure limits ---------------
# Every check above drives the positive direction. The limits are odd in the state (the valve
# clips u_v to +-v_max, the stops sit at +-theta_max, the stall pressure is +-P_s), so each
# analytic reference holds mirrored; a sign or factor wrong on one side only breaks them there.
def _contact_penetration_rad(w_hit, zeta, J, k_s):
    """Largest penetration [rad] of a free inertia J hitting a Kelvin-Voigt contact (stiffness
    k_s, damping ratio zeta < 1) at rate w_hit: the damped oscillator from rest position with
    initial rate w_hit, x = (w_hit / w_d) exp(-zeta w_n t) sin(w_d t), peaks where
    tan(w_d t) = w_d / (zeta w_n): x_max = (w_hit / w_n) exp(-zeta / sqrt(1 - zeta^2) atan(sqrt(1 - zeta^2) / zeta))."""
    wn = math.sqrt(k_s / J)
    s = math.sqrt(1.0 - zeta * zeta)
    return w_hit / wn * math.exp(-zeta / s * math.atan2(s, zeta))


def _run(m, r):
    plant = simplex_plant(m)
    y, _ = integrate_plant(plant, m, r.reshape(-1, 1), DT, 1)
    o = plant.ss.output_index
    return y[:, o("x_p_m")], y[:, o("theta_rad")], y[:, o("load_force_N")], y[:, o("p_load_Pa")]


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_step_slews_at_the_no_load_valve_rate_in_both_directions(ambient_ideal, sign):
    """The valve's flow saturation Q_max gives the piston the no-load rate v_max = Q_max / A
    whichever way it moves: a +-5 deg step crosses 20-80 % of its stroke at +-v_max, and the
    piston never moves faster than v_max (plus the oil column's decompression) either way."""
    m = _ideal_valve(ambient_ideal)
    vmax = m.actuator.max_rate_m_per_s
    R = m.actuator.moment_arm_m
    t, xp, th, _, _ = _step(m, sign * 5 * DEG)
    x5 = R * 5 * DEG
    i0, i1 = np.argmax(sign * xp > 0.2 * x5), np.argmax(sign * xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(sign * vmax, rel=0.03)
    vp = np.gradient(xp, DT)
    assert np.abs(vp).max() <= vmax * 1.10
    assert np.abs(np.gradient(th, DT)).max() < 2 * vmax / R
    # the supply-pressure limit on (the shipped default): the load-flow curve's slew either way
    t, xp, th, _, p = _step(ambient_ideal, sign * 5 * DEG)
    i0, i1 = np.argmax(sign * xp > 0.2 * x5), np.argmax(sign * xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(
        _load_flow_slew(p[i0:i1], sign, ambient_ideal.actuator), rel=0.04)
    assert np.abs(np.gradient(xp, DT)).max() <= vmax * 1.10
    assert np.abs(p).max() <= 1.05 * ambient_ideal.actuator.supply_pressure_Pa


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_impact_on_either_stop_penetrates_no_deeper_than_the_damped_contact(ambient_ideal, sign):
    """A +-12 deg command: the engine reaches the stop at +-theta_max at some rate w_hit and
    penetrates no deeper than the damped contact's analytic peak (a damping that pushed the
    engine in, not out, would let it through) plus the static deflection R F_L / k_s under the
    actuator force; it then holds at the stop, on the commanded side."""
    m = ambient_ideal
    e = m.engine
    R = m.actuator.moment_arm_m
    J, ks = e.inertia("pitch"), e.hard_stop_stiffness_Nm_per_rad
    t, xp, th, fl, _ = _step(m, sign * 12 * DEG, t_end=2.0)
    i = int(np.argmax(sign * th > e.gimbal_range_rad))
    assert i > 0
    w_hit = abs(np.gradient(th, DT)[i])
    static = np.abs(R * fl[t > 1.5]).max() / ks
    assert static < 0.05 * DEG  # a stiff contact: the engine holds at the stop
    deepest = (sign * th).max() - e.gimbal_range_rad
    assert deepest <= _contact_penetration_rad(w_hit, e.hard_stop_damping_ratio, J, ks) + static
    held = sign * th[t > 1.5]
    assert held.min() >= e.gimbal_range_rad
    assert held.max() <= e.gimbal_range_rad + 1.05 * static


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_slow_ramp_into_either_stop_holds_the_engine_at_the_gimbal_range(ambient_ideal, sign):
    """A 6 deg/s ramp to +-12 deg: the engine follows the ramp (lagging it by ~0.5 deg: the
    position loop's rate / K_v plus the feedline spring's and the pressure feedback's steady
    error) without touching the stop, reaches +-theta_max within 0.3 s after the ramp passes it
    and stays there, within the contact's static deflection, while the command goes beyond."""
    m = ambient_ideal
    e = m.engine
    R = m.actuator.moment_arm_m
    rate = 6 * DEG
    t = np.arange(int(2.6 / DT) + 1) * DT
    r = sign * np.minimum(rate * t, 12 * DEG)
    xp, th, fl, _ = _run(m, r)
    static = np.abs(R * fl).max() / e.hard_stop_stiffness_Nm_per_rad
    t_stop = e.gimbal_range_rad / rate
    before = t < t_stop
    assert np.abs(th[before] - r[before]).max() < 1.0 * DEG  # following the ramp
    assert (sign * th[before]).max() < e.gimbal_range_rad
    after = sign * th[t > t_stop + 0.3]
    assert after.min() >= e.gimbal_range_rad
    assert after.max() <= e.gimbal_range_rad + 1.05 * static
    assert (sign * th).max() <= e.gimbal_range_rad + 1.05 * static + _contact_penetration_rad(
        2 * rate, e.hard_stop_damping_ratio, e.inertia("pitch"), e.hard_stop_stiffness_Nm_per_rad)


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_supply_pressure_limits_the_load_pressure_to_plus_minus_p_s(ambient_ideal, sign):
    """Pushing against either stop with the supply-pressure limit on holds the load pressure at
    +-P_s (the stall force +-A P_s), on the side of the command."""
    act = dataclasses.replace(ambient_ideal.actuator, pressure_limited=True)
    m = ambient_ideal.replace(actuator=act)
    t, xp, th, fl, p = _step(m, sign * 14 * DEG, t_end=2.0)
    assert np.abs(p).max() <= act.supply_pressure_Pa * 1.3
    assert p[t > 1.5].mean() == pytest.approx(sign * act.supply_pressure_Pa, rel=0.05)
    assert fl[t > 1.5].mean() == pytest.approx(sign * act.stall_force_N, rel=0.05)


def test_all_limits_together_are_odd_in_the_command(ambient_ideal):
    """With all three limits on (no friction, unity avionics) the model is odd: the response to
    -r is minus the response to r, to rounding. One side's stop, rate or pressure law wrong
    breaks it."""
    act = dataclasses.replace(ambient_ideal.actuator, pressure_limited=True)
    m = ambient_ideal.replace(actuator=act)
    t = np.arange(int(1.5 / DT) + 1) * DT
    r = np.where(t >= 0.05, 14 * DEG, 0.0) * np.where(t < 0.9, 1.0, -0.5)  # into the stop and back
    up = _run(m, r)
    down = _run(m, -r)
    for a, b in zip(up, down):
        assert np.abs(a + b).max() <= 1e-9 * np.abs(a).max()


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_3d_limits_in_both_directions(taos_ambient, sign):
    """TAOS (the same limit laws, compiled into the 3-D step): a +-5 deg pitch step slews at
    +-v_max, and a +-12 deg command holds the engine at the stop on its side. The torque on the
    stop is bounded independently of the run: once the piston reaches x_c = R theta_c the load
    path pushes with at most K_L R^2 (theta_c - theta_max) (the stop and the gimbal chain take
    part of that deflection), doubled for the impact's ringing (measured 1.26 x). The engine
    penetrates no deeper than the damped contact's analytic peak at the measured impact rate
    plus that torque's deflection of the stop and of the gimbal chain."""
    base = taos_ambient.base
    e, R = base.engine, base.actuator.moment_arm_m
    vmax = base.actuator.max_rate_m_per_s
    t, xp, th, _ = _step3d(_ideal_valve_3d(taos_ambient), sign * 5 * DEG)
    x5 = R * 5 * DEG
    i0, i1 = np.argmax(sign * xp > 0.2 * x5), np.argmax(sign * xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(sign * vmax, rel=0.03)
    assert np.abs(np.gradient(th, DT)).max() < 2 * vmax / R
    t, xp, th, _, p = _step3d(taos_ambient, sign * 5 * DEG, pressure=True)  # the shipped limit on
    i0, i1 = np.argmax(sign * xp > 0.2 * x5), np.argmax(sign * xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(_load_flow_slew(p[i0:i1], sign, base.actuator),
                                                                rel=0.04)
    assert np.abs(p).max() <= 1.05 * base.actuator.supply_pressure_Pa
    t, xp, th, fl = _step3d(taos_ambient, sign * 12 * DEG, t_end=2.0)
    torque = 2.0 * base.structure.load_stiffness_N_per_m * R * R * (12 * DEG - e.gimbal_range_rad)
    assert np.abs(R * fl).max() <= torque
    kchain = float(np.linalg.eigvalsh(taos_ambient.chain_stiffness[3:, 3:]).min())
    ks = e.hard_stop_stiffness_Nm_per_rad
    held = sign * th[t > 1.5]
    assert held.min() >= e.gimbal_range_rad - torque / kchain
    assert held.max() <= e.gimbal_range_rad + torque / ks + torque / kchain
    i = int(np.argmax(sign * th > e.gimbal_range_rad))
    w_hit = abs(np.gradient(th, DT)[i])
    deepest = (sign * th).max() - e.gimbal_range_rad
    assert deepest <= _contact_penetration_rad(w_hit, e.hard_stop_damping_ratio, e.inertia("pitch"), ks) \
        + torque / ks + torque / kchain
