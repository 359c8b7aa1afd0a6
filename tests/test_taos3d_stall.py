"""The 3-D step at stall (issue 44): the supply-pressure limit's stiff rate on the load pressure
integrated exactly (exponential time differencing, taos.taos3d.dynamics._etd_rk4) where it
exceeds 1 / dt (taos.taos3d._rhs.pressure_guard), so that the explicit step's rule of the 3-D
engine is the linear modes' alone (8.1e-4 s on the hot-fire model instead of 5.07e-4 s).

References are independent of the code under test: the limit's rate against a finite
difference of the right-hand side, the phi functions against their exact rational series,
the stalled runs against a 16x finer run (where the guard never acts: its rate 3,946 1/s
stays below 1 / dt)."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from taos.errors import InputError
from taos.planar.saturation import pressure_limit_rate_per_s
from taos.planar.simplex import check_rk4_step
from taos.taos3d import load_taos_model
from taos.taos3d import dynamics as dy
from taos.taos3d._rhs import GUARD_RATE_DT, _limit_rate, pressure_guard
from taos.taos3d.simulate import DEFAULT_DT_S, pack, rest_state, run_samples

MODEL = "models/rs25_hotfire.toml"


@pytest.fixture(scope="module")
def tm():
    return load_taos_model(MODEL, friction="modified-lugre")


def _stall_run(tm, dt, T=1.0, rec_s=4e-3):
    """Both axes commanded 1.3x the gimbal range (into the hard stops) from 0.05 s: the valves
    open at their rate limit against a stalled piston, the load pressure at the supply pressure
    (the limit's stiffest point: square-root law within eps of stall, relief open)."""
    rng = tm.base.engine.gimbal_range_rad
    n = int(round(T / dt))
    t = np.arange(n + 1) * dt
    cmd = np.zeros((n + 1, 2))
    cmd[:, 0] = np.where(t > 0.05, 1.3 * rng, 0.0)
    cmd[:, 1] = np.where(t > 0.05, -1.3 * rng, 0.0)
    return run_samples(tm, cmd, dt, int(round(rec_s / dt)))


def test_limit_rate_is_the_slope_of_the_right_hand_side(tm):
    """The limit's rate (_limit_rate) equals -d(P_L')/d(P_L) of the right-hand side's limit
    term, by central differences of dy.rhs with the pressure limit on and off (the linear part
    cancels), in the square-root regime, within eps of stall and with the relief open; its
    largest value is the rule's pressure_limit_rate_per_s, and pressure_guard returns the part of
    it above GUARD_RATE_DT / dt."""
    import dataclasses

    pk = pack(tm)
    off = tm.replace(base=tm.base.replace(actuator=dataclasses.replace(tm.base.actuator, pressure_limited=False)))
    P, Poff = pk.P, pack(off).P
    na = pk.n_act
    ip = dy.N_BODY + P.act_pl_index
    iq = dy.N_BODY + P.act_q_index
    act = tm.base.actuator
    ps, vmax = act.supply_pressure_Pa, act.max_rate_m_per_s
    aux = np.empty(dy.N_AUX)
    for q, p in ((0.5 * vmax, 0.3 * ps), (vmax, 0.99 * ps), (vmax, 1.02 * ps), (-0.8 * vmax, -0.97 * ps)):
        x = rest_state(pk)
        x[iq] = q
        x[ip] = p
        r = _limit_rate(P.limits, x, int(dy.N_BODY), int(na), int(P.act_pl_index))
        slope = []
        for Pk in (P, Poff):
            d = []
            for s in (+1.0, -1.0):
                xs = x.copy()
                xs[ip] += s * 1e-4 * ps
                dx = np.empty_like(x)
                dy.rhs(xs, float(0.0), float(0.0), float(0.0), float(0.0), Pk, dx, aux)
                d.append(dx[ip])
            slope.append((d[0] - d[1]) / (2e-4 * ps))
        assert r == pytest.approx(-(slope[0] - slope[1]), rel=1e-5), (q, p)
    x = rest_state(pk)
    x[iq], x[ip], x[iq + na], x[ip + na] = vmax, 1.02 * ps, 0.5 * vmax, 0.3 * ps
    dt = 1e-3
    lam0, lam1 = pressure_guard(x, dt, P)
    assert lam0 + GUARD_RATE_DT / dt == pytest.approx(pressure_limit_rate_per_s(act), rel=1e-12)
    assert lam1 == 0.0


def test_phi_functions_against_their_exact_series():
    """dy._phi123 (series below |z| = 1, closed forms above) against the exact rational series
    to 200 terms (to z = -10; at -30 the closed forms in exact arithmetic from e^-30, whose
    rounding is below 1e-28 of them): within 4e-16 relative over z in [-30, 0)."""
    for z in (-1e-9, -0.02, -0.5, -0.999999, -1.0, -1.000001, -2.5, -10.0, -30.0):
        got = dy._phi123.py_func(z)
        zf = Fraction(z)
        if z >= -10.0:
            refs = [sum(zf ** j / math.factorial(j + k) for j in range(200)) for k in (1, 2, 3)]
        else:
            r1 = (Fraction(math.exp(z)) - 1) / zf
            r2 = (r1 - 1) / zf
            refs = [r1, r2, (r2 - Fraction(1, 2)) / zf]
        for k in (1, 2, 3):
            assert abs(Fraction(got[k - 1]) - refs[k - 1]) <= 4e-16 * abs(refs[k - 1]), (z, k)


def test_the_3d_rule_is_the_linear_modes_alone(tm):
    """The explicit step's rule: the planar engine's includes the supply-pressure limit's rate
    (5.07e-4 s on the hot-fire model), the 3-D engine's the linear modes alone (8.13e-4 s:
    the time run's default 8e-4 s passes, 8.2e-4 s is refused)."""
    check_rk4_step(5e-4, tm.base, "dt_s")
    with pytest.raises(InputError):
        check_rk4_step(5.1e-4, tm.base, "dt_s")
    check_rk4_step(DEFAULT_DT_S, tm.base, "dt_s", pressure_limit=False)
    with pytest.raises(InputError):
        check_rk4_step(8.2e-4, tm.base, "dt_s", pressure_limit=False)


@pytest.mark.slow
def test_stalled_actuators_at_the_default_step(tm):
    """Stalled into the hard stops (:func:`_stall_run`, the limit's rate up to 3,946 1/s, 3.2
    times its RK4 bound at 8e-4 s): the default step (guard active) stays within 0.035 P_s of
    the load pressure and 0.02 deg of the engine angle of a 5e-5 s run (the guard inactive:
    1 / dt above the rate) over the whole second, and within 0.003 P_s over the stalled half
    second (rms; measured 0.027 P_s, 0.014 deg, 0.0023 P_s; at 4e-4 s 0.0083 P_s, 0.0066 deg)."""
    ps = tm.base.actuator.supply_pressure_Pa
    ref = _stall_run(tm, 5e-5)
    run = _stall_run(tm, DEFAULT_DT_S)
    assert np.abs(ref[:, dy.REC_PL:dy.REC_PL + 2]).max() > 0.99 * ps   # it did stall
    e_p = (run[:, dy.REC_PL:dy.REC_PL + 2] - ref[:, dy.REC_PL:dy.REC_PL + 2]) / ps
    e_th = np.degrees(np.abs(run[:, dy.REC_THETA:dy.REC_THETA + 2] - ref[:, dy.REC_THETA:dy.REC_THETA + 2]))
    late = np.arange(ref.shape[0]) * 4e-3 > 0.4
    print("max |d P_L| / P_s", np.abs(e_p).max(), "max |d theta| deg", e_th.max(),
          "rms stalled", np.sqrt((e_p[late] ** 2).mean()))
    assert np.abs(e_p).max() < 0.035
    assert e_th.max() < 0.02
    assert np.sqrt((e_p[late] ** 2).mean()) < 0.003
