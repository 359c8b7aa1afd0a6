"""The supply-pressure limit as physics (issue 24 point 2): the critical-centre valve's
square-root pressure-drop law and the cross-port relief valve of :mod:`taos.planar.saturation`,
against independent analytic references (Merritt, Hydraulic Control Systems, 1967, ch. 3):

* the static load-flow curve: a piston against a constant load force F with the valve open at
  its no-load rate v_nl moves at v = v_nl sqrt(1 - F / (A P_s)) (resisting and aiding loads,
  both directions);
* the relief valve's static curve: a load forcing flow Q into a chamber with the valve closed
  holds P_L = P_r + Q / K_r;
* the stall force: a step into a locked load holds F = A P_s within the relief's margin
  (planar and 3-D);
* the null linearisation is the linear model (linear responses unchanged), and the limit off is
  the ideal valve bit for bit;
* the 3-D record carries load pressure, spool and supply pressure as the planar one does.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from taos.model import load_model
from taos.planar.actuator import actuator_state_space
from taos.planar.avionics import Avionics
from taos.planar.saturation import limit_rows_for_actuator, pack_limits

from .conftest import MODELS

DEG = math.pi / 180


@pytest.fixture(scope="module")
def act():
    """The shipped actuator (pressure limit on, as shipped) with the valve's null pressure
    coefficient, leakage and pressure feedback off, so the analytic curves hold exactly."""
    a = load_model(MODELS / "rs25_ambient.toml").actuator
    assert a.pressure_limited and a.relief_pressure_Pa == pytest.approx(a.supply_pressure_Pa)
    return dataclasses.replace(a, flow_pressure_coefficient_m3_per_s_Pa=0.0, leakage_coefficient_m3_per_s_Pa=0.0,
                               pressure_feedback_gain_m_per_s_Pa=0.0, pressure_feedback_time_constant_s=0.0)


def _actuator_steady(act, force_N, xc_gain, xc_offset=0.0, t_end=0.3, dt=1e-5):
    """Integrate the actuator alone (linear state space + the packed limits) against a constant
    load force ``force_N`` [N], the command ``x_c = xc_gain x_p + xc_offset`` [m] held over each
    step (classical RK4, compiled: tests/_actuator_rk4.py); return the final piston rate [m/s]
    and load pressure [Pa]."""
    from ._actuator_rk4 import rk4_actuator

    ss = actuator_state_space(act)
    rows, _ = limit_rows_for_actuator(act)
    R = act.moment_arm_m
    lim = pack_limits(act.max_rate_m_per_s, act.loop_gain_per_s * R, act.supply_pressure_Pa, 0.0, 0.0, 0.0, rows,
                      p_relief=act.relief_pressure_Pa,
                      k_relief_per_area=act.relief_flow_coefficient_m3_per_s_Pa / act.piston_area_m2)
    A, bx, bf = (np.ascontiguousarray(a, dtype=float) for a in (ss.A, ss.B[:, 0], ss.B[:, 1]))
    ixp, ivp, ip = ss.state_index("x_p_m"), ss.state_index("v_p_m_s"), ss.state_index("p_load_Pa")
    x = rk4_actuator(A, bx, bf, lim, R, float(force_N), ixp, float(xc_gain), float(xc_offset), dt, int(t_end / dt))
    return x[ivp], x[ip]


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["extend", "retract"])
@pytest.mark.parametrize("load", [0.0, 0.25, 0.5, 0.8, -0.5], ids=["no-load", "0.25", "0.5", "0.8", "aiding-0.5"])
def test_static_load_flow_curve_is_the_square_root_law(act, sign, load):
    """Valve wide open (command far away: the valve at its no-load rate v_nl = v_max), constant
    load force F = load A P_s resisting the motion (negative: aiding it): the piston moves at
    v = v_nl sqrt(1 - F_p / (A P_s)), F_p = F + B_p v the force the pressure carries (piston
    damping B_p; the piston's mass and the oil column settle). Zero load gives exactly the
    no-load rate (the linear model's flow gain is the no-load gain); an aiding load speeds the
    piston (the overrunning quadrant of the four-quadrant law)."""
    aps = act.piston_area_m2 * act.supply_pressure_Pa
    vnl, bp = act.max_rate_m_per_s, act.piston_damping_Ns_per_m
    F = sign * load * aps
    v, p = _actuator_steady(act, F, xc_gain=0.0, xc_offset=sign * 10.0)
    ref = sign * brentq(lambda w: w - vnl * math.sqrt(1.0 - (load * aps + bp * w) / aps), 0.0, 2.0 * vnl)
    assert v == pytest.approx(ref, rel=2e-3)
    assert p * act.piston_area_m2 == pytest.approx(F + bp * v, rel=1e-3, abs=1e-6 * aps)
    if load == 0.0:
        assert v == pytest.approx(sign * vnl, rel=0.02)  # B_p v_nl / (A P_s) = 2.5 %: sqrt -> 1.3 % slower


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
@pytest.mark.parametrize("over", [1.02, 1.1, 1.3])
def test_relief_valve_static_curve(act, sign, over):
    """Valve closed (the command follows the piston), a load force beyond stall F = over A P_s
    drives the piston back: all the displaced oil goes through the cross-port relief, Q =
    K_r (|P_L| - P_r) sgn(P_L), so A |v| = K_r (|P_L| - P_r) with A P_L = F + B_p v."""
    A, kr, pr, bp = (act.piston_area_m2, act.relief_flow_coefficient_m3_per_s_Pa, act.relief_pressure_Pa,
                     act.piston_damping_Ns_per_m)
    F = sign * over * A * act.supply_pressure_Pa
    v, p = _actuator_steady(act, F, xc_gain=1.0)
    # analytic: |P| = P_r + A |v| / K_r and A |P| = |F| - B_p |v|
    w = brentq(lambda w: A * (pr + A * w / kr) - (abs(F) - bp * w), 0.0, 10.0)
    assert v == pytest.approx(-sign * w, rel=2e-3)
    assert p == pytest.approx(sign * (pr + A * w / kr), rel=1e-4)


def _ideal(m, **act_changes):
    m = m.with_friction("none").replace(avionics=Avionics(gain_table_rad=(0.0,), gain_table=(1.0,)))
    return m.replace(actuator=dataclasses.replace(m.actuator, **act_changes)) if act_changes else m


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_step_into_a_locked_load_holds_the_stall_force(sign):
    """Planar: the engine locked (inertia x 1e4), a 2 deg step asks the load spring for
    K_L R 2 deg = 2.8 x the stall force: the piston force settles at A P_s (the valve's
    square-root law delivers no flow at P_L = P_s; K_c P_L leaks 0.7 % below it) and never
    exceeds it by more than the relief's margin."""
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import integrate_plant
    m = _ideal(load_model(MODELS / "rs25_ambient.toml"))
    eng = dataclasses.replace(m.engine, inertia_pitch_kgm2=1e4 * m.engine.inertia_pitch_kgm2)
    m = m.replace(engine=eng)
    plant = simplex_plant(m)
    dt = 2e-4
    t = np.arange(int(2.0 / dt) + 1) * dt
    y, _ = integrate_plant(plant, m, np.where(t >= 0.05, sign * 2 * DEG, 0.0)[:, None], dt, 1)
    o = plant.ss.output_index
    a = m.actuator
    aps = a.piston_area_m2 * a.supply_pressure_Pa
    fp = a.piston_area_m2 * y[:, o("p_load_Pa")]
    assert fp[t > 1.5].mean() == pytest.approx(sign * aps, rel=0.01)
    assert y[t > 1.5, o("load_force_N")].mean() == pytest.approx(sign * aps, rel=0.01)
    assert np.abs(fp).max() <= 1.05 * aps
    # the ideal valve (limit off) pushes the spring on towards x_c
    free = m.replace(actuator=dataclasses.replace(a, pressure_limited=False))
    yf, _ = integrate_plant(simplex_plant(free), free, np.where(t >= 0.05, sign * 2 * DEG, 0.0)[:, None], dt, 1)
    assert np.abs(yf[:, o("load_force_N")]).max() > 2.0 * aps


def test_null_linearisation_is_the_linear_model_and_off_is_bit_for_bit():
    """At the null (q = 0, P_L = 0) the limit adds nothing to the derivative and nothing to its
    Jacobian (the square-root law's flow gain there is the linear K_q); the limit off packs
    no pressure slots and reproduces the ideal valve exactly."""
    from taos.planar.simplex import simplex_limits, simplex_plant
    from taos.planar.simulate import integrate_plant
    from taos.planar import saturation as sat
    m = _ideal(load_model(MODELS / "rs25_hotfire.toml"))
    lim = simplex_limits(m)
    n = sat.n_limit_states(lim)
    x0 = np.zeros(n)
    h = {"q_m_s": 1e-6, "p_load_Pa": 1.0}
    ss = simplex_plant(m).ss
    for name, step in h.items():
        for s in (step, -step):
            x = x0.copy()
            x[ss.state_index(name)] = s
            dx = np.zeros(n)
            sat.apply(lim, x, 0.0, dx)
            assert np.all(dx == 0.0), name
    # off: only the rate limit and the stops packed; the run equals a run with the slots cleared
    off = m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False))
    lo = simplex_limits(off)
    assert lo[sat.LIM_PS] == 0.0 and lo[sat.LIM_KRA] == 0.0 and lo[sat.LIM_PR] == math.inf
    t = np.arange(5001) * 2e-4
    r = (0.4 * DEG * np.sin(2 * math.pi * 5.0 * t))[:, None]
    y_off, _ = integrate_plant(simplex_plant(off), off, r, 2e-4, 10)
    y_on, _ = integrate_plant(simplex_plant(m), m, r, 2e-4, 10)
    assert not np.array_equal(y_on, y_off)  # the valve's load sensitivity shows in the time domain


@pytest.fixture(scope="module")
def taos_ambient():
    from taos.taos3d import load_taos_model
    tm = load_taos_model(MODELS / "rs25_ambient.toml", friction="none")
    return dataclasses.replace(tm, base=_ideal(tm.base))


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["positive", "negative"])
def test_3d_step_into_the_stop_holds_the_stall_force(taos_ambient, sign):
    """TAOS: a 14 deg pitch command into the 10.5 deg stop: the pitch piston force settles at
    the stall force A P_s. At the impact the stop back-drives the piston into the oil column
    (harder than in the planar model: the engine arrives through the gimbal chain); the valve's
    square-root backflow and the relief hold the load pressure to 1.13 P_s (measured 1.127 /
    1.080 P_s), within the relief curve's P_r + A v_max / K_r = 1.47 P_s."""
    from taos.taos3d import dynamics as dy
    from taos.taos3d.simulate import run_samples
    dt = 2e-4
    t = np.arange(int(2.0 / dt) + 1) * dt
    cmd = np.zeros((t.size, 2))
    cmd[:, 0] = np.where(t >= 0.05, sign * 14 * DEG, 0.0)
    out = run_samples(taos_ambient, cmd, dt, 1)
    a = taos_ambient.base.actuator
    p = out[:, dy.REC_PL]
    assert np.abs(p).max() <= 1.15 * a.supply_pressure_Pa
    assert p[t > 1.5].mean() == pytest.approx(sign * a.supply_pressure_Pa, rel=0.02)
    assert out[t > 1.5, dy.REC_FL].mean() == pytest.approx(sign * a.stall_force_N, rel=0.02)


def test_3d_record_carries_load_pressure_spool_and_supply(tmp_path):
    """The 3-D time history records P_L, the spool signal q and P_s per axis as the planar one
    does (tests/test_signals_export.py), and writes them to the .h5 the same way."""
    from taos.planar.simulate import TimeHistory
    from taos.profiles import SineDwell
    from taos.taos3d import load_taos_model
    from taos.taos3d.simulate import TaosTimeHistory, simulate_taos
    tm = load_taos_model(MODELS / "rs25_hotfire.toml", friction="none")
    run = simulate_taos(tm, SineDwell(math.radians(0.4), 0.5, 3), record_every=5)
    a = tm.base.actuator
    # piston force balance: A P_L = F_L + B_p v_p + M_p a_p (the 3-D load force is small at
    # 0.5 Hz, so the piston's damping shows: B_p v_p is 8 % of F_L here)
    fl, fp = run.load_force_N[0], a.piston_area_m2 * run.load_pressure_Pa[0]
    vp = np.gradient(run.piston_m[0], run.t_s)
    bal = fl + a.piston_damping_Ns_per_m * vp + a.piston_mass_kg * np.gradient(vp, run.t_s)
    assert np.sqrt(np.mean((fp - bal)[10:-10] ** 2)) < 0.03 * np.sqrt(np.mean(fl ** 2))
    assert run.supply_pressure_Pa.shape == run.load_pressure_Pa.shape == run.spool_flow_m_s.shape
    assert np.all(run.supply_pressure_Pa == a.supply_pressure_Pa)
    v = np.gradient(run.piston_m[0], run.t_s)
    assert np.corrcoef(run.spool_flow_m_s[0], v)[0, 1] > 0.98
    run.to_hdf5(tmp_path / "r.h5")
    for cls in (TimeHistory, TaosTimeHistory):
        back = cls.from_hdf5(tmp_path / "r.h5")
        np.testing.assert_array_equal(back.load_pressure_Pa, run.load_pressure_Pa)
        np.testing.assert_array_equal(back.spool_flow_m_s, run.spool_flow_m_s)
        np.testing.assert_array_equal(back.supply_pressure_Pa, run.supply_pressure_Pa)


def test_relief_keys_are_checked(tmp_path):
    """The relief valve's keys come together, and it cracks between P_s and 1.5 P_s."""
    from taos.errors import InputError
    from taos.model import parse_actuator
    base = {"moment_arm": "0.8 m", "piston_area": "15 in**2", "supply_pressure": "3000 psi",
            "oil_bulk_modulus": "150000 psi", "trapped_volume": "100 in**3", "piston_mass": "45 kg",
            "piston_damping": "1e4 N*s/m", "loop_gain": "20 1/s", "valve_natural_frequency": "100 Hz",
            "valve_damping_ratio": 0.7, "flow_pressure_coefficient": "5e-12 m**3/s/Pa",
            "leakage_coefficient": "0 m**3/s/Pa"}
    ok = parse_actuator({"actuator": {**base, "relief_pressure": "3150 psi",
                                      "relief_flow_coefficient": "5e-10 m**3/s/Pa"}}, "x.toml")
    assert ok.relief_pressure_Pa == pytest.approx(3150 * 6894.757, rel=1e-6)
    with pytest.raises(InputError, match="relief_flow_coefficient"):
        parse_actuator({"actuator": {**base, "relief_pressure": "3150 psi"}}, "x.toml")
    with pytest.raises(InputError, match="relief_pressure"):
        parse_actuator({"actuator": {**base, "relief_pressure": "2000 psi",
                                     "relief_flow_coefficient": "5e-10 m**3/s/Pa"}}, "x.toml")
