"""Identities between two models or two computations: MASV with one engine on a rigid
structure = simplex; a test record written and read back; the sine-dwell estimator on a
simulated friction-free run = the exact linear response; a log sweep's instantaneous frequency;
quantisation error bounds."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from taos.model import load_model
from taos.planar.simplex import simplex_state_space

from ..test_masv import one_engine

DEG = math.pi / 180


@pytest.mark.parametrize("axis", ["pitch", "yaw"])
def test_masv_one_engine_rigid_structure_equals_simplex(axis, verify):
    hot = load_model("rs25_hotfire")
    model = hot.replace(engine=dataclasses.replace(hot.engine, inertia_yaw_kgm2=9000.0),   # MASV's damping is modal
                        structure=dataclasses.replace(hot.structure, load_damping_ratio=0.0))
    s = one_engine(model, axis)
    f = np.logspace(-2, 2.5, 100)
    xp, th = s.frf(f)
    h = simplex_state_space(model, axis).freqresp(f, "command_rad", ["x_p_m", "theta_rad"])
    err = max(np.max(np.abs(xp[:, 0, 0] / h[:, 0] - 1)), np.max(np.abs(th[:, 0, 0] / h[:, 1] - 1)))
    verify("identity: simplex model", 1e-6, err, case=f"MASV one engine, rigid structure = simplex, {axis}")


def test_dwell_estimator_recovers_the_exact_linear_response(verify):
    """Friction off, ideal avionics: a simulated dwell record, estimated as the test data were
    (taos.identify), gives the exact linear response."""
    from taos.planar.freqresp import linear_freqresp
    from taos.identify.data import from_time_history
    from taos.identify.estimation import estimate
    from taos.profiles import Sequence, SineDwell
    from taos.planar.simulate import simulate

    a = load_model("rs25_ambient")
    m = a.with_friction("none").replace(avionics=a.avionics.ideal())
    m = m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False))  # the ideal valve: linear
    freqs = [1.0, 3.0]
    prof = Sequence(tuple(SineDwell(0.4 * DEG, f, 12) for f in freqs))
    th = simulate(m, prof, record_every=5)
    (r,) = estimate(from_time_history(th), method="dwell")
    lin = linear_freqresp(m, r.freq_hz)
    err = np.max(np.abs(r.piston_m_per_rad / (lin.piston * m.actuator.moment_arm_m) - 1))
    verify("identity: exact linear response", 5e-3, err, case="sine-dwell estimator on a linear run")


def test_csv_round_trip(tmp_path, verify):
    from taos.identify.data import from_time_history, load_test_data
    from taos.profiles import SineDwell
    from taos.planar.simulate import simulate

    th = simulate(load_model("rs25_ambient"), SineDwell(0.4 * DEG, 2.0, 4))
    d = from_time_history(th)
    d.to_csv(tmp_path / "r.csv", digits=12)
    back = load_test_data(tmp_path / "r.csv")
    err = np.max(np.abs(back.piston_m - d.piston_m)) / np.max(np.abs(d.piston_m))
    verify("identity: the written record", 1e-9, err, case="CSV write and read back")


def test_log_sweep_instantaneous_frequency(verify):
    """f(t) = f0 exp(ln(f1/f0) t / T) for a logarithmic sweep (zero-crossing spacing)."""
    from taos.profiles import SineSweep

    sw = SineSweep(1.0, 0.1, 10.0, 20.0)
    t = np.linspace(0, 20, 400001)
    y = sw(t)
    zc = t[1:][np.diff(np.signbit(y)) != 0]
    f_inst = 0.5 / np.diff(zc)
    t_mid = 0.5 * (zc[1:] + zc[:-1])
    expect = 0.1 * np.exp(np.log(100) * t_mid / 20)
    verify("analytic log-sweep frequency", 0.02, np.max(np.abs(f_inst / expect - 1)[t_mid > 2]))


def test_rounding_quantiser_error_is_at_most_half_an_lsb(verify):
    """A rounding quantiser errs by at most LSB/2, truncation by less than one LSB (Widrow)."""
    from taos.planar.avionics import apply_array

    av = load_model("rs25_ambient").avionics.ideal()
    av = dataclasses.replace(av, quantization_bits=12, command_range_rad=21 * DEG, rounding=True)
    c = np.linspace(-2 * DEG, 2 * DEG, 100001)
    e = np.max(np.abs(apply_array(c, av.pack()) - c)) / av.lsb_rad
    verify("Widrow: rounding error <= LSB/2", 0.5 + 1e-9, e, unit="LSB")


def test_schroeder_multisine_crest_factor(verify):
    """Schroeder phases give a flat 20-tone multisine a crest factor near sqrt(2) (Schroeder
    1970); zero phases would give sqrt(2 N) = 6.3."""
    from taos.profiles import Multisine

    ms = Multisine(0.4 * DEG, tuple(0.1 * k for k in range(1, 21)), 10.0)
    y = ms(np.linspace(0, 10, 200001))
    crest = np.max(np.abs(y)) / np.sqrt(np.mean(y ** 2))
    verify("Schroeder 1970: crest factor near sqrt(2)", 0.5, crest / math.sqrt(2) - 1)
