"""Simplex linear block against analytic references: the seed paper's eq. 1, static equilibrium,
Merritt's high-passed pressure feedback, the exact solution of the linear ODE (RK4 order), and the
time-domain sine dwell against the exact frequency response."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.linalg import expm

from taos.planar.freqresp import linear_freqresp, sine_dwell_grid
from taos.linear import gain_db
from taos.model import load_model
from taos.planar.simplex import simplex_plant, simplex_state_space
from taos.planar.simulate import integrate_plant

DEG = math.pi / 180


@pytest.mark.parametrize("name", ["rs25_ambient", "rs25_hotfire", "rs25_flight"])
def test_piston_notch_at_load_resonance_eq1_of_the_seed_paper(name, verify):
    """The command -> piston notch of the exact linear response sits at
    w_L = sqrt((K_L R^2 + K_n)/J_n) (seed paper eq. 1, fig. 2)."""
    m = load_model(name)
    wl = m.load_resonance_hz()
    f = np.linspace(0.5 * wl, 2 * wl, 8001)
    notch = f[np.argmin(np.abs(linear_freqresp(m, f).piston))]
    verify("seed paper eq. 1 (load resonance)", 0.01, abs(notch / wl - 1), case=f"piston notch = w_L, {name}")


def test_static_equilibrium_three_springs_in_series(verify):
    """At DC the servo is a spring k_s = A^2 K_v / (K_c + C_l) (flow-pressure coefficient and
    leakage, Merritt 1967) in series with the load path K_L and the engine stiffness K_n / R^2:
    theta / theta_c = 1 / (1 + (K_n / R^2) (1/k_s + 1/K_L))."""
    m = load_model("rs25_ambient")
    a = m.actuator
    KL, R, Kn = m.structure.load_stiffness_N_per_m, a.moment_arm_m, m.engine.rotational_stiffness_Nm_per_rad
    ks = a.piston_area_m2 ** 2 * a.loop_gain_per_s / (a.flow_pressure_coefficient_m3_per_s_Pa
                                                      + a.leakage_coefficient_m3_per_s_Pa)
    want = 1.0 / (1.0 + Kn / R ** 2 * (1 / ks + 1 / KL))
    h = linear_freqresp(m, [1e-9])
    verify("static equilibrium: servo, load path and engine springs in series", 1e-9, abs(h.engine[0] / want - 1))


def test_pressure_feedback_is_high_passed_merritt(verify):
    """Dynamic pressure feedback (Merritt 1967, sec. 9) leaves the DC stiffness unchanged."""
    m = load_model("rs25_ambient")
    off = m.replace(actuator=dataclasses.replace(m.actuator, pressure_feedback_gain_m_per_s_Pa=0.0))
    d = abs(linear_freqresp(m, [1e-5]).piston[0] - linear_freqresp(off, [1e-5]).piston[0])
    verify("Merritt: high-passed pressure feedback, DC gain unchanged", 1e-4, d, unit="absolute (in/in)")


def _step_error(m, dt, T=0.2):
    plant = simplex_plant(m, "pitch")
    ss = plant.ss
    n = int(round(T / dt))
    r = np.full((n + 1, plant.n_ext), 0.0)
    r[:, 0] = 0.1 * DEG
    y, _ = integrate_plant(plant, m, r, dt, record_every=n)
    ic = ss.input_index("command_rad")
    A, b = ss.A, ss.B[:, : plant.n_ext] @ r[0] + ss.B[:, ic] * 0.1 * DEG
    x = np.linalg.solve(A, (expm(A * T) - np.eye(A.shape[0])) @ b)
    o = ss.output_index("theta_rad")
    return abs(y[-1, o] - ss.C[o] @ x) / (0.1 * DEG)


def test_rk4_step_response_against_matrix_exponential(verify):
    """Friction off, ideal avionics: the compiled RK4 step response equals the exact solution
    x(T) = A^-1 (e^{AT} - I) b of the linear ODE; halving a large step divides the error by ~16."""
    m0 = load_model("rs25_ambient")
    m = m0.with_friction("none").replace(avionics=m0.avionics.ideal())
    m = m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False))  # the ideal valve: linear
    e0 = _step_error(m, 2e-4)
    verify("exact solution of the linear ODE (matrix exponential)", 1e-9, e0, unit="relative to the step",
           case="RK4 step response, dt = 2e-4 s")
    # the order is read where the error is above round-off (which it reaches near dt = 1e-4 s)
    e1, e2 = _step_error(m, 8e-4), _step_error(m, 4e-4)
    order = math.log2(e1 / e2)
    verify("RK4 global order 4 (Butcher)", 0.5, abs(order - 4.0), unit="absolute (order)",
           case="RK4 convergence order, dt 8e-4 -> 4e-4 s")


def test_sine_dwell_equals_exact_linear_response(verify):
    """Friction off, ideal avionics: time-domain sine dwell = exact linear response (identity
    between two computations), 0.1 to 20 Hz."""
    a = load_model("rs25_ambient")
    m = a.with_friction("none").replace(avionics=a.avionics.ideal())
    m = m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False))  # the ideal valve: linear
    f = np.array([0.1, 0.5, 2.0, 5.3, 10.0, 20.0])
    piston, engine = sine_dwell_grid(m, [0.4 * DEG], f)
    lin = linear_freqresp(m, f)
    err = max(np.max(np.abs(gain_db(piston[0]) - gain_db(lin.piston))),
              np.max(np.abs(gain_db(engine[0]) - gain_db(lin.engine))))
    verify("exact linear frequency response", 0.1, err, unit="dB")
    ph = max(np.max(np.abs(np.degrees(np.angle(piston[0] / lin.piston)))),
             np.max(np.abs(np.degrees(np.angle(engine[0] / lin.engine)))))
    verify("exact linear frequency response", 1.0, ph, unit="deg", case="sine dwell phase = exact linear phase")


def test_linear_poles_match_the_state_matrix_eigenvalues_of_scipy_signal(verify):
    """The model's frequency response equals scipy.signal's evaluation of the same (A, B, C, D)
    (an independent implementation of C (jwI - A)^-1 B + D)."""
    from scipy import signal

    m = load_model("rs25_hotfire")
    ss = simplex_state_space(m, "pitch")
    ic = ss.input_index("command_rad")
    o = ss.output_index("x_p_m")
    f = np.logspace(-1, 2, 50)
    w, h = signal.freqresp(signal.StateSpace(ss.A, ss.B[:, [ic]], ss.C[[o]], ss.D[[o]][:, [ic]]), w=2 * np.pi * f)
    mine = linear_freqresp(m, f).piston * m.actuator.moment_arm_m
    verify("scipy.signal.freqresp of the same state space", 1e-9, np.max(np.abs(mine / h - 1)))
