"""The co-simulation block (:mod:`taos.cosim`) against ``taos simulate`` and the flight loop.

References, each independent of the block's stepping: ``taos simulate``'s own runs (the
uncut kernel run over the whole profile), the closed flight loop of ``taos lco`` (one monolithic
Lur'e plant, vehicle and TVC in one RK4 state), finite differences of the engine angle, and
the rotation geometry of the gimbal frame."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from taos.cosim import BlockOutputs, TvcBlock
from taos.errors import InputError
from taos.model import load_model
from taos.planar.simulate import simulate
from taos.profiles import Step, TwoAxis, load_profile

from .conftest import MODELS

DEG = math.pi / 180
SIGNALS = ("engine_rad", "piston_m", "load_force_N", "load_pressure_Pa", "friction_torque_Nm", "command_avionics_rad")


@pytest.fixture(scope="module")
def hotfire():
    return load_model(MODELS / "rs25_hotfire.toml")


def run_block(block: TvcBlock, cmd: np.ndarray, dt: float) -> list[BlockOutputs]:
    """Step ``block`` through the command samples ``cmd`` (2, n) every ``dt`` with ramps to
    each next sample (``taos simulate``'s reading of its samples)."""
    outs = [block.reset(cmd[0, 0], cmd[1, 0])]
    for k in range(1, cmd.shape[1]):
        outs.append(block.step(dt, cmd[0, k], cmd[1, k]))
    return outs


def max_difference(outs: list[BlockOutputs], th) -> dict[str, float]:
    """Largest |block - taos simulate| per recorded signal and axis."""
    out = {}
    for name in SIGNALS:
        for i, ax in enumerate(th.axes):
            v = np.array([getattr(o, f"{ax}_{name}") for o in outs])
            out[f"{ax}_{name}"] = float(np.max(np.abs(v - getattr(th, name)[i])))
    return out


def two_axis_step() -> TwoAxis:
    return TwoAxis(Step(0.4 * DEG, 0.05, 0.5), Step(-0.3 * DEG, 0.1, 0.45), name="two-axis step")


@pytest.mark.parametrize("which", ["step", "greenrun"])
def test_simplex_block_is_taos_simulate_bit_for_bit(hotfire, which):
    """Ramped through the samples at the kernel's own step, the block is ``taos simulate``
    (simplex) bit for bit on every recorded signal, both axes (the acceptance asks 1e-6 deg):
    a step on each axis, and the first 2 s of the two-axis Green Run profile (the whole profile:
    the slow FMU test)."""
    prof = two_axis_step() if which == "step" else load_profile("greenrun_two_axis")
    dt = 2e-4
    th = simulate(hotfire, prof, dt_s=dt, record_every=1, duration_s=0.6 if which == "step" else 2.0)
    outs = run_block(TvcBlock(hotfire, hold="ramp"), np.atleast_2d(prof(th.t_s)), dt)
    assert np.allclose([o.time_s for o in outs], th.t_s, rtol=0, atol=1e-12)
    assert max(max_difference(outs, th).values()) == 0.0
    assert np.max(np.abs(th.engine_rad)) > 0.2 * DEG   # the runs did move the engine


def test_taos3d_block_is_taos_simulate_bit_for_bit(hotfire):
    """The same for the 3-D engine (``taos simulate --engine taos``): a two-axis step, 0.3 s."""
    from taos.taos3d import simulate_taos, taos_model

    tm = taos_model(hotfire)
    prof = two_axis_step()
    dt = 4e-4
    th = simulate_taos(tm, prof, dt_s=dt, record_every=1, duration_s=0.3)
    outs = run_block(TvcBlock(hotfire, engine="taos", taos=tm, hold="ramp"), np.atleast_2d(prof(th.t_s)), dt)
    assert max(max_difference(outs, th).values()) == 0.0
    assert np.max(np.abs(th.engine_rad)) > 0.1 * DEG


def test_hold_is_a_constant_command_and_chunks_do_not_matter(hotfire):
    """``hold`` with a command applied from t = 0 is ``taos simulate`` of a step at t = 0 (every
    sample equal: nothing to interpolate) bit for bit; a communication step of 25 internal steps
    gives the same state as 25 single steps."""
    dt = 2e-4
    th = simulate(hotfire, TwoAxis(Step(0.3 * DEG, 0.0, 0.3), Step(0.2 * DEG, 0.0, 0.3)), dt_s=dt,
                  record_every=25, duration_s=0.3)
    b = TvcBlock(hotfire)
    b.reset(0.3 * DEG, 0.2 * DEG)
    outs = [b.outputs] + [b.step(25 * dt, 0.3 * DEG, 0.2 * DEG) for _ in range(th.t_s.size - 1)]
    assert max(max_difference(outs, th).values()) == 0.0
    fine = TvcBlock(hotfire)
    fine.reset(0.3 * DEG, 0.2 * DEG)
    for _ in range(25 * (th.t_s.size - 1)):
        last = fine.step(dt, 0.3 * DEG, 0.2 * DEG)
    assert last == outs[-1]


def test_engine_rate_and_thrust_direction_geometry(hotfire):
    """The engine rates are the derivatives of the engine angles (central differences, O(dt^2));
    the thrust direction is a unit vector tilted by the engine angles: (sin theta_p, ~theta_y,
    ~1) to first order, x along pitch, y along yaw, for both engines."""
    from taos.taos3d import taos_model

    prof = two_axis_step()
    for engine, dt in (("simplex", 2e-4), ("taos", 4e-4)):
        b = TvcBlock(hotfire, engine=engine, hold="ramp", taos=taos_model(hotfire) if engine == "taos" else None)
        t = np.arange(0, 0.4, dt)
        outs = run_block(b, np.atleast_2d(prof(t)), dt)
        for ax in ("pitch", "yaw"):
            th = np.array([getattr(o, f"{ax}_engine_rad") for o in outs])
            rate = np.array([getattr(o, f"{ax}_engine_rate_rad_s") for o in outs])
            fd = (th[2:] - th[:-2]) / (2 * dt)
            assert np.max(np.abs(rate[1:-1] - fd)) < 2e-3 * np.max(np.abs(rate))
        d = np.array([[o.thrust_direction_x, o.thrust_direction_y, o.thrust_direction_z] for o in outs])
        assert np.allclose(np.linalg.norm(d, axis=1), 1.0, rtol=0, atol=1e-14)
        o = outs[-1]
        assert d[-1, 0] == pytest.approx(o.pitch_engine_rad, rel=2e-3)
        assert d[-1, 1] == pytest.approx(o.yaw_engine_rad, rel=2e-3)


@pytest.mark.parametrize("bad, message", [
    (dict(dt_s=3e-4), "whole multiple"), (dict(dt_s=float("nan")), "whole multiple"),
    (dict(dt_s=-2e-4), "whole multiple"), (dict(pitch=float("nan")), "pitch_command_rad"),
    (dict(yaw=11 * DEG), "gimbal range"), (dict(yaw="up"), "a number of radians"),
])
def test_bad_steps_and_commands_are_refused_in_one_line(hotfire, bad, message):
    b = TvcBlock(hotfire)
    kw = {"dt_s": 2e-4, "pitch": 0.0, "yaw": 0.0, **bad}
    with pytest.raises(InputError, match=message) as e:
        b.step(kw["dt_s"], kw["pitch"], kw["yaw"])
    assert "\n" not in str(e.value)
    assert b.time_s == 0.0   # nothing advanced


def test_refused_steps_between_good_ones_change_nothing(hotfire):
    """The block checks a step size once and reuses the count while the size repeats: a refused
    size or command between good steps changes nothing (the run equals one without them), and
    commands given as numpy floats or ints step exactly as the same values as floats."""
    dt = 2e-4
    cmds = [(0.3 * DEG, -0.2 * DEG), (0.1 * DEG, 0.25 * DEG)] * 15
    ref = TvcBlock(hotfire, hold="ramp")
    ref.reset()
    want = [ref.step(2 * dt, p, y) for p, y in cmds]
    b = TvcBlock(hotfire, hold="ramp")
    b.reset()
    got = []
    for k, (p, y) in enumerate(cmds):
        for bad in ((1.5 * dt, p, y), (float("nan"), p, y), (2 * dt, float("inf"), y), (2 * dt, p, 11 * DEG)):
            with pytest.raises(InputError):
                b.step(*bad)
        got.append(b.step(2 * dt, np.float64(p), y) if k % 2 else b.step(2 * dt, p, y))
    assert got == want
    assert b.step(2 * dt, 0, np.int64(0)) == ref.step(2 * dt, 0.0, 0.0)


@pytest.mark.parametrize("kw, message", [(dict(engine="mujoco"), "simplex or taos"),
                                         (dict(hold="cubic"), "hold or ramp"), (dict(dt_s=0.05), "at most")])
def test_bad_block_settings_are_refused_before_any_step(hotfire, kw, message):
    with pytest.raises(InputError, match=message):
        TvcBlock(hotfire, **kw)


def _cosim_flight_history(flight, model, duration_s: float, h: float, attitude0_rad: float):
    """The flight loop of :mod:`taos.flight.vehicle` closed through the block: vehicle + FCS
    (linear) advanced exactly over each communication step h with the block's engine angle and
    rate held (matrix exponential), the FCS command held over the block's step."""
    from taos.flight.lco import FlightHistory
    from taos.flight.vehicle import vehicle_fcs_state_space

    vf = vehicle_fcs_state_space(flight)
    n = vf.A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n], M[:n, n:] = vf.A, vf.B
    E = scipy.linalg.expm(M * h)
    Ad, Bd = E[:n, :n], E[:n, n:]
    o, a = vf.output_index("delta_cmd_rad"), vf.output_index("attitude_rad")
    block = TvcBlock(model)
    ax = flight.axis
    x = np.zeros(n)
    x[vf.state_index("xi_rad")] = attitude0_rad
    N = int(round(duration_s / h))
    rec = np.empty((N + 1, 4))
    out = block.outputs
    for k in range(N + 1):
        u = np.array([getattr(out, f"{ax}_engine_rad"), getattr(out, f"{ax}_engine_rate_rad_s")])
        c = float(vf.C[o] @ x + vf.D[o] @ u)
        rec[k] = (c, vf.C[a] @ x + vf.D[a] @ u, u[0], getattr(out, f"{ax}_friction_torque_Nm"))
        if k < N:
            x = Ad @ x + Bd @ u
            out = block.step(h, *((c, 0.0) if ax == "pitch" else (0.0, c)))
    t = np.arange(N + 1) * h
    return FlightHistory(t_s=t, attitude_rad=rec[:, 1], command_rad=rec[:, 0], engine_rad=rec[:, 2],
                         piston_m=np.zeros_like(t), friction_torque_Nm=rec[:, 3], pti_rad=np.zeros_like(t),
                         friction_model=model.friction.name, load_stiffness_N_per_m=model.structure.load_stiffness_N_per_m)


@pytest.mark.slow
def test_flight_loop_through_the_block_reproduces_the_lco_time_domain_cycle():
    """``taos lco``'s time domain (the flight file's loop with the TVC inside one RK4 state,
    :func:`taos.flight.lco.simulate_flight`, bounding avionics) and the same loop closed
    through the block by a host at a 5 ms communication step give the same limit cycle: command
    amplitude within 1.5 % (achieved +0.71 %), frequency within 0.5 % (+0.25 %); the residual is
    the host's O(h) coupling delay (halving h halves it: +1.4 % at 10 ms, +0.29 % at 2 ms)."""
    from taos.flight.lco import measure_oscillation, simulate_flight, with_bounding_avionics
    from taos.flight.vehicle import load_flight

    flight = load_flight(MODELS / "flight" / "core_stage.toml")
    model = with_bounding_avionics(load_model(MODELS / "rs25_flight.toml"))
    ref = measure_oscillation(simulate_flight(flight, model, 160.0, attitude0_rad=0.2 * DEG), 60.0)
    got = measure_oscillation(_cosim_flight_history(flight, model, 160.0, 5e-3, 0.2 * DEG), 60.0)
    print(f"lco: taos lco {math.degrees(ref.amplitude_rad):.5f} deg {ref.freq_hz:.5f} Hz; block "
          f"{math.degrees(got.amplitude_rad):.5f} deg {got.freq_hz:.5f} Hz")
    assert ref.lco and got.lco
    assert got.amplitude_rad == pytest.approx(ref.amplitude_rad, rel=0.015)
    assert got.engine_amplitude_rad == pytest.approx(ref.engine_amplitude_rad, rel=0.02)
    assert got.freq_hz == pytest.approx(ref.freq_hz, rel=0.005)
