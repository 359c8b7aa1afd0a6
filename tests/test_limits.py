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
    resonance (peak rate below twice the slew), where the unlimited servo reaches > 100 deg/s.
    The piston exceeds v_max only by the oil column's decompression as the load force falls."""
    m = ambient_ideal
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
    free = m.replace(actuator=dataclasses.replace(m.actuator, max_rate_m_per_s=0.0))
    _, _, th_free, _, _ = _step(free, 5 * DEG, t_end=0.5)
    assert np.gradient(th_free, DT).max() > 100 * DEG


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
    # transient: at the stop's impact the load spring drives the piston back into the oil column
    # faster than the valve relieves it (measured 1.23 P_s; a relief valve's job)
    assert np.abs(p).max() <= act.supply_pressure_Pa * 1.3
    assert p[t > 1.5].mean() == pytest.approx(act.supply_pressure_Pa, rel=0.05)
    _, _, _, _, p_free = _step(ambient_ideal, 14 * DEG, t_end=2.0)
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
    from taos.taos3d.model import load_taos_model
    tm = load_taos_model(MODELS / "rs25_ambient.toml", friction="none")
    return dataclasses.replace(tm, base=_ideal(tm.base))


def _step3d(tm, amp_rad, t_end=1.5, t0=0.05):
    from taos.taos3d import dynamics as _dy
    from taos.taos3d.simulate import run_samples
    n = int(t_end / DT)
    t = np.arange(n + 1) * DT
    cmd = np.zeros((n + 1, 2))
    cmd[:, 0] = np.where(t >= t0, amp_rad, 0.0)
    out = run_samples(tm, cmd, DT, 1)
    col = {k: i for i, k in enumerate(_dy.REC)}
    return t, out[:, col["xp_pitch"]], out[:, col["theta_pitch"]], out[:, col["fl_pitch"]]


def test_3d_5_deg_step_is_rate_limited_at_the_documented_rate(taos_ambient):
    """TAOS: the pitch piston slews at v_max through the middle of a 5 deg step."""
    vmax = taos_ambient.base.actuator.max_rate_m_per_s
    R = taos_ambient.base.actuator.moment_arm_m
    t, xp, th, _ = _step3d(taos_ambient, 5 * DEG)
    x5 = R * 5 * DEG
    i0, i1 = np.argmax(xp > 0.2 * x5), np.argmax(xp > 0.8 * x5)
    assert (xp[i1] - xp[i0]) / (t[i1] - t[i0]) == pytest.approx(vmax, rel=0.03)
    assert np.gradient(th, DT).max() < 2 * vmax / R


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
