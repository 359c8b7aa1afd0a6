"""TAOS 3-D time step: the kernel (allocation-free right-hand side without reference counting,
the quantised command's mean over each step in every RK4 stage, second-order bearing coupling:
trapezoidal bearing torque in the RK4 step, BDF2 bearing with its own substeps, the bearing
solve continued from the previous slip speed) against references 16x finer than its default
step (the former 4e-4 s default, now the dwells' step DWELL_DT_S, and the time run's default 8e-4 s
since issue 44): the smooth laws must show the second-order convergence that allows the default step;
modified LuGre (rational bristle-damping decay: a well-posed massless bearing) also against
an independent uniform-step reference on 4 s and over the whole 60 s run; the mean of the command path is checked against
brute-force quadrature."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from taos.profiles import Sequence, TwoAxis, load_profile
from taos.taos3d import load_taos_model
from taos.taos3d.simulate import DEFAULT_DT_S, DWELL_DT_S, run_samples

T_RUN = 4.0
REF_DT = 2.5e-5  # 16x below the dwells' step, 32x below the time run's default
REC_S = 0.008  # the records' interval [s]: a whole multiple of every step here
UNIFORM_REC_S = 0.01  # the stored uniform reference's records' interval [s]


def _greenrun():
    """The two-axis Green Run of benchmarks/bench_taos3d.py (pitch twice, yaw three times)."""
    p = load_profile("models/profiles/greenrun_two_axis.toml")
    return TwoAxis(Sequence((p.pitch,) * 2), Sequence((p.yaw,) * 3), "Green Run x2, 60 s")


def _run(tm, dt, rec_s=REC_S):
    n = int(round(T_RUN / dt))
    cmd = np.ascontiguousarray(np.asarray(_greenrun()(np.arange(n + 1) * dt)).T)
    return run_samples(tm, cmd, dt, int(round(rec_s / dt)))[:, :8]


def _err(a, ref):
    """max |d theta| [rad], max |d x_p| [m], rms |d theta| [rad], rms |d x_p| [m]."""
    d = a - ref
    return np.array([np.abs(d[:, 0:2]).max(), np.abs(d[:, 2:4]).max(),
                     np.sqrt((d[:, 0:2] ** 2).mean()), np.sqrt((d[:, 2:4] ** 2).mean())])


@pytest.mark.slow
@pytest.mark.parametrize("law", ["modified-lugre", "coulomb-smooth", "coulomb-switching", "dahl"])
def test_default_step_against_a_16x_finer_reference(law):
    """Error of the dwells' step (4e-4 s, the former default) and of the time run's default
    (8e-4 s) against a 2.5e-5 s reference, first 4 s of the Green Run (+-0.45 deg): within 2
    and 10 microdegrees for every law (measured at 4e-4 s: modified LuGre 0.6, Coulomb smooth
    and switching, Dahl 0.7-1.2, the same with the bearing substep tolerance scaled with the
    step, issue 28; at 8e-4 s 2.8 / 4.1 / 4.8 / 2.9, issue 44). The former kernel's stored records
    (2e-4 s, removed; in git history before this file's rational-decay change) predate the servo recalibration and the
    pressure limit (issue 24.1, 24.2): against this model they are 1.1-1.3e-3 rad off, a
    different model, so the former-kernel ratios (0.010-0.031 for the smooth laws,
    benchmarks/RESULTS.md) are history, not re-measured here."""
    tm = load_taos_model("models/rs25_hotfire.toml", friction=law)
    ref = _run(tm, REF_DT)
    e4, e8 = _err(_run(tm, DWELL_DT_S), ref), _err(_run(tm, DEFAULT_DT_S), ref)
    print(law, "4e-4 s and the default step: max |d theta|, |d x_p|, rms", e4, e8)
    assert e4[0] < np.radians(2e-6)
    assert e8[0] < np.radians(1e-5)


@pytest.mark.slow
@pytest.mark.parametrize("law", ["coulomb-smooth", "dahl"])
def test_bearing_coupling_converges_at_second_order(law):
    """Halving the step from 4e-4 to 2e-4 s cuts the error against the 2.5e-5 s reference at
    least 3x (first order would halve it; measured 3.8x Dahl, 5.3x Coulomb smooth with the
    substep tolerance scaled with the step, issue 28; the former kernel's 2.2x)."""
    tm = load_taos_model("models/rs25_hotfire.toml", friction=law)
    ref = _run(tm, REF_DT)
    e2, e4 = _err(_run(tm, 2e-4), ref), _err(_run(tm, 4e-4), ref)
    print(law, "error ratio 4e-4 / 2e-4", e4 / e2)
    assert np.all(e4 >= 3.0 * e2)


UNIFORM = Path(__file__).parent / "data" / "taos3d_mlugre_uniform_1.5625e-6.npz"


@pytest.mark.slow
def test_modified_lugre_converges_with_the_step_against_an_independent_fine_reference():
    """Modified LuGre on the first 4 s of the Green Run against an independent solver: the
    former constant-step kernel (commit abb8363, no bearing substeps) at a uniform
    1.5625e-6 s with the shipped rational decay, made by
    tests/data/make_taos3d_uniform_reference.py from that commit's own tree and model files
    (ideal valve, line load stiffness as that tree gave it: the same here). The 4e-4 s step
    (the former default, the dwells' step) is within 3e-6 deg (measured 6.2e-7; 7.0e-4 with the former exponential decay against its
    own reference of this kind) and the error falls with the step (1e-4 s: measured 4.5e-8)."""
    import dataclasses

    data = np.load(UNIFORM)
    ref = data["records"]
    tm = load_taos_model("models/rs25_hotfire.toml", friction="modified-lugre")
    act = dataclasses.replace(tm.base.actuator, pressure_limited=False)
    gim = dataclasses.replace(tm.gimbal, line_load_stiffness_N_per_m=float(data["line_load_stiffness_N_per_m"]))
    tm = tm.replace(base=tm.base.replace(actuator=act), gimbal=gim)
    e4 = _err(_run(tm, DWELL_DT_S, UNIFORM_REC_S), ref)
    e1 = _err(_run(tm, 1e-4, UNIFORM_REC_S), ref)
    print("max |d theta| deg at 4e-4, 1e-4 s:", np.degrees(e4[0]), np.degrees(e1[0]))
    assert e4[0] < np.radians(3e-6)
    assert e1[0] < 0.2 * e4[0]


@pytest.mark.slow
def test_shipped_modified_lugre_converges_over_the_60s_green_run():
    """Issue 24 point 6: the shipped model (hot fire, modified LuGre with the rational
    bristle-damping decay, square-root valve) over the whole 60 s two-axis Green Run,
    engine angles against the same kernel at 2.5e-5 s (32x finer; itself within 5.1e-8 deg of a
    1.25e-5 s run, 2.3e-7 before issue 28, benchmarks/bench_taos3d.py part 4): the default step
    (8e-4 s since issue 44) within 1e-4 deg (the acceptance is 1e-3; measured 7.57e-5), and the
    error falls at second order, at least 3x per halving (measured 7.57e-5 / 1.83e-5 / 4.98e-6 /
    1.09e-6 deg at 8e-4 / 4e-4 / 2e-4 / 1e-4 s; 1.82e-5 / 5.0e-6 / 1.08e-6 deg at 4e-4 / 2e-4 / 1e-4 s with the
    bearing substep tolerance scaled with the step cubed, issue 28; 1.97e-5 / 5.0e-6 / 1.1e-6
    with the former fixed 1e-8 rad; the reference run in the test: about 15 s at machine load 5). With the former exponential decay the same runs gave 6.0e-3 / 7.7e-3 /
    7.7e-3 deg: no step-converged solution (docs/theory/taos3d.md)."""
    tm = load_taos_model("models/rs25_hotfire.toml", friction="modified-lugre")
    assert tm.base.actuator.pressure_limited

    def run(dt):
        n = int(round(60.0 / dt))
        cmd = np.ascontiguousarray(np.asarray(_greenrun()(np.arange(n + 1) * dt)).T)
        return run_samples(tm, cmd, dt, int(round(REC_S / dt)))[:, 0:2]

    ref = run(REF_DT)
    e8, e4, e2, e1 = (np.degrees(np.abs(run(dt) - ref).max()) for dt in (DEFAULT_DT_S, 4e-4, 2e-4, 1e-4))
    print("60 s, shipped modified LuGre: max |d theta| deg at 8e-4, 4e-4, 2e-4, 1e-4 s:", e8, e4, e2, e1)
    assert e8 < 1e-4
    assert e4 < e8 / 3 and e2 < e4 / 3 and e1 < e2 / 3


@pytest.mark.parametrize("rounding", [False, True])
def test_command_mean_is_the_mean_of_the_command_path_over_a_ramp(rounding):
    """dynamics.command_mean (the mean of taos.planar.avionics.apply over a ramp) against brute-force
    quadrature of the command path over the ramp (2e5 points), for ramps inside one bin,
    across a few bins, through zero, and reversed."""
    from taos.planar.avionics import Avionics
    from taos.taos3d.dynamics import command_mean as apply_mean
    av = Avionics(12, np.radians(21.0), rounding, tuple(np.radians([0.0, 0.02, 0.1, 1.0])), (0.95, 0.95, 0.98, 1.0))
    p = av.pack()
    lsb = av.lsb_rad
    rng = np.random.default_rng(3)
    ramps = [(0.2 * lsb, 0.7 * lsb), (1.3 * lsb, 4.6 * lsb), (-2.5 * lsb, 3.2 * lsb), (5.1 * lsb, -0.4 * lsb)]
    ramps += [tuple(rng.uniform(-8, 8, 2) * lsb) for _ in range(4)]
    for c0, c1 in ramps:
        c = np.linspace(c0, c1, 200_001)
        brute = av(0.5 * (c[1:] + c[:-1])).mean()
        assert apply_mean(c0, c1, p) == pytest.approx(brute, rel=0, abs=2e-5 * lsb)
    assert apply_mean(3.3 * lsb, 3.3 * lsb, p) == av(3.3 * lsb)
