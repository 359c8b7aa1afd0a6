"""The lockstep lanes of an ascent run (:mod:`taos.flight.ascent_sim`): the flight loop frozen
at a time, the ascent plant, the integration grid and segments, the external inputs (PTI, wind
disturbance) and one run of one axis packed for the compiled kernel
(:func:`taos.planar.dynamics.integrate_segments_lanes`). The physics and its sources are in
:mod:`taos.flight.ascent_sim`'s docstring (the booster TVC state, the disturbance
M_a(t) alpha_w(t), the zero-order hold of the vehicle over each update interval, the re-basing
of xi = theta - b delta across a change of b, the separation kick); SI units throughout.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from taos.flight.ascent import Ascent, aero_instability, control_acceleration, pti_command, wind_speed
from taos.flight.friction_env import friction_scale
from taos.flight.vehicle import FlightModel, PlantParts, flight_plant
from taos.linear import StateSpace
from taos.model import TvcModel
from taos.planar import saturation as sat
from taos.planar.simplex import LurePlant, extend_plant
from taos.planar.simulate import kernel_args

AXES = ("pitch", "yaw")
MAX_STEPS = 50_000_000


def flights_at(ascent: Ascent, t_s, axis: str) -> list[tuple[FlightModel, float]]:
    """The flight loop frozen at each of the times ``t_s`` [s]: vehicle properties from the
    trajectory, FCS gains scheduled by a_ref / a(t); and the booster control acceleration per
    radian [1/s^2]. The trajectory is interpolated at all the times at once (element by element
    the same numbers as one time at a time)."""
    fl = ascent.flight
    tr = ascent.trajectory
    t = np.asarray(t_s, float).reshape(-1)
    core, boost = control_acceleration(ascent, t)
    col = {k: tr.at(k, t) for k in ("inertia_kgm2", "mass_kg", "core_thrust_per_engine_N", "gimbal_arm_m")}
    aero = aero_instability(ascent, t)
    out = []
    for i in range(t.size):
        c, b = float(core[i]), float(boost[i])
        k = fl.vehicle.control_acceleration_per_s2(axis) / (c + b)
        inertia = float(col["inertia_kgm2"][i])
        veh = dataclasses.replace(fl.vehicle, mass_kg=float(col["mass_kg"][i]), pitch_inertia_kgm2=inertia,
                                  yaw_inertia_kgm2=inertia,
                                  thrust_per_engine_N=float(col["core_thrust_per_engine_N"][i]),
                                  gimbal_arm_m=float(col["gimbal_arm_m"][i]), aero_instability_per_s2=float(aero[i]))
        fcs = dataclasses.replace(fl.fcs, attitude_gain=fl.fcs.attitude_gain * k,
                                  integral_gain_per_s=fl.fcs.integral_gain_per_s * k,
                                  rate_gain_s=fl.fcs.rate_gain_s * k)
        out.append((dataclasses.replace(fl, vehicle=veh, fcs=fcs), b))
    return out


def flight_at(ascent: Ascent, t_s: float, axis: str) -> tuple[FlightModel, float]:
    """The flight loop frozen at ``t_s`` (:func:`flights_at`)."""
    return flights_at(ascent, t_s, axis)[0]


def ascent_plant(flight: FlightModel, model: TvcModel, axis: str, booster_accel_per_s2: float,
                 booster_time_constant_s: float, *, parts: PlantParts | None = None) -> LurePlant:
    """:func:`~taos.flight.vehicle.flight_plant` with the booster TVC state and the disturbance
    input added (module docstring). External inputs ``pti_rad`` [rad], ``disturbance_rad_s2``
    [rad/s^2]; the flight plant's limits carried (:func:`~taos.planar.simplex.extend_plant`).
    Outputs: the flight plant's, ``booster_deflection_rad``, then every state
    (``state:<name>``) so a run can be continued. ``parts``: as for ``flight_plant``."""
    base = flight_plant(flight, model, axis, parts=parts)
    ss = base.ss
    n = ss.A.shape[0]
    ixr = ss.state_index("xi_rate_rad_s")
    tau = booster_time_constant_s
    A = np.zeros((n + 1, n + 1))
    A[:n, :n] = ss.A
    A[ixr, n] = booster_accel_per_s2
    A[n, :n] = base.cmd_c / tau
    A[n, n] = -1.0 / tau
    B = np.zeros((n + 1, 4))
    B[:n, 0] = ss.B[:, 0]
    B[n, 0] = 1.0 / tau           # the booster sees the PTI too (it is on the FCS command)
    B[ixr, 1] = 1.0
    B[:n, 2:] = ss.B[:, 1:]
    states = ss.states + ("booster_deflection_rad",)
    C = np.zeros((ss.C.shape[0] + 1 + n + 1, n + 1))
    C[: ss.C.shape[0], :n] = ss.C
    C[ss.C.shape[0], n] = 1.0
    C[ss.C.shape[0] + 1:] = np.eye(n + 1)
    outputs = ss.outputs + ("booster_deflection_rad",) + tuple(f"state:{s}" for s in states)
    full = StateSpace(A, B, C, np.zeros((C.shape[0], 4)), states,
                      ("pti_rad", "disturbance_rad_s2", "command_rad", "friction_torque_Nm"), outputs)
    return extend_plant(base, full, n_ext=2, cmd_d=[1.0, 0.0])

def _grid(ascent: Ascent, start_s: float, end_s: float | None, dt_s: float, record_interval_s: float):
    """(end [s], record step in steps, t (n_steps + 1,) [s], segment bounds (step indices)): the
    segments are the file's update interval, split at the booster separation."""
    end = ascent.end_time_s if end_s is None else float(end_s)
    rec = max(1, int(round(record_interval_s / dt_s)))
    nsteps = int(math.ceil((end - start_s) / dt_s / rec)) * rec
    if nsteps <= 0 or nsteps > MAX_STEPS:
        from taos.errors import InputError
        raise InputError("command line", "duration / dt", f"1 to {MAX_STEPS} steps", got=str(nsteps))
    t = start_s + np.arange(nsteps + 1) * dt_s
    seg = max(rec, int(round(ascent.update_interval_s / dt_s / rec)) * rec)
    bounds = set(range(0, nsteps, seg)) | {nsteps}
    sep = ascent.boosters.separation_time_s
    if start_s < sep < end:
        bounds.add(int(round((sep - start_s) / dt_s / rec)) * rec)
    return end, rec, t, tuple(sorted(bounds))


def _external_inputs(ascent: Ascent, ax: str, t: np.ndarray, seed: int, dt_s: float) -> np.ndarray:
    """(n_steps + 1, 2): the PTI [rad] and the wind disturbance M_a alpha_w [rad/s^2]; the
    turbulence of axis k drawn from SeedSequence([seed, k])."""
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), AXES.index(ax)]))
    w = wind_speed(ascent, t, rng, dt_s)
    comp = math.cos(ascent.wind.azimuth_rad) if ax == "pitch" else math.sin(ascent.wind.azimuth_rad)
    dist = aero_instability(ascent, t) * comp * w / ascent.trajectory.at("velocity_m_s", t)
    return np.column_stack([pti_command(ascent, ax, t), dist])


@dataclass(frozen=True, eq=False)
class _Lane:
    """One run of one axis prepared for the lockstep kernel: its segment plants, their matrices
    (n_seg, n + 8, n + n_r + 5) in the layout of :func:`taos.planar.dynamics._rates_lanes`, the
    packed limits' heads (n_seg, N_HEAD), the xi re-basing coefficients (n_seg, 2) and kicks
    (n_seg, n) at the segment starts, the initial state, the external inputs."""

    plants: list
    mats: np.ndarray
    heads: np.ndarray
    jcoef: np.ndarray
    kick: np.ndarray
    x0: np.ndarray
    r: np.ndarray
    model: TvcModel
    #: (n_seg, NPARAM) the friction law packed per segment (its level following the thrust or not)
    fpack: np.ndarray

    @property
    def key(self) -> tuple:
        """Lanes with equal keys can share one kernel call."""
        return (self.mats.shape, self.model.friction.name, self.model.avionics.pack().shape,
                self.model.friction.pack().shape)


def _lane(ascent: Ascent, model: TvcModel, ax: str, t: np.ndarray, bounds: tuple, rec: int, dt_s: float,
          start_s: float, attitude0_rad: float, r: np.ndarray, follow: bool = False,
          step_s: float | None = None) -> _Lane:
    """Each segment's plant is :func:`ascent_plant` frozen at the segment's middle (the parts
    that do not change, built once); theta = xi + b delta and theta' are kept continuous across a
    change of b by re-basing xi; the separation kick lands on xi' at the separation. ``dt_s`` [s]
    the spacing of ``t``; ``step_s`` [s] the integrator's step the friction law's explicit-step
    rule is checked with (default ``dt_s``)."""
    sep = ascent.boosters.separation_time_s
    parts = PlantParts.of(ascent.flight, model, ax)
    plants, bs = [], []
    mids = [t[k0] + 0.5 * (t[k1] - t[k0]) for k0, k1 in zip(bounds[:-1], bounds[1:])]
    for flight, a_b in flights_at(ascent, mids, ax):
        plants.append(ascent_plant(flight, model, ax, a_b, ascent.boosters.actuator_time_constant_s, parts=parts))
        bs.append(flight.vehicle.twd_coefficient(ax))
    p0 = plants[0]
    si = p0.ss.state_index
    n, ne = p0.ss.A.shape[0], p0.n_ext
    scale = (friction_scale(model, ascent.trajectory.at("core_thrust_per_engine_N", np.array(mids)))
             if follow else np.ones(len(mids)))
    laws = [model.friction.scaled(float(f)) if follow else model.friction for f in scale]
    for law in {id(x): x for x in (laws[int(np.argmax(scale))], model.friction)}.values():
        law.check_step(p0.inertia_kgm2, dt_s if step_s is None else step_s, model.source)   # (check_friction_step on the stiffest level)
    mats = np.zeros((len(plants), n + 3 + 5, n + ne + 5))
    heads = np.zeros((len(plants), sat.N_HEAD))
    iu = n + ne
    for M, H, p in zip(mats, heads, plants):
        pk = kernel_args(p, model)
        A, Br, bc, bf, cc, dc, cw, ca, lim = pk.A, pk.Br, pk.bc, pk.bf, pk.cc, pk.dc, pk.cw, pk.ca, pk.lim
        M[:n, :n], M[:n, n:iu], M[:n, iu], M[:n, iu + 1] = A, Br, bc, bf
        M[n, :n], M[n, n:iu], M[n + 1, :n], M[n + 2, :n] = cc, dc, cw, ca
        if lim.size:  # the limit rows over x (u_v also over u) and their columns (taos.planar.saturation)
            row = lambda i: lim[sat.row_start(i, n):sat.row_start(i + 1, n)]  # noqa: E731
            for j, i in enumerate((sat.ROW_UV, sat.ROW_Q, sat.ROW_P, sat.ROW_THETA, sat.ROW_OMEGA)):
                M[n + 3 + j, :n] = row(i)
            M[n + 3, iu] = lim[sat.LIM_KVR]
            for j, i in enumerate((sat.ROW_UV_IN, sat.ROW_FLOW_IN, sat.ROW_STOP_IN)):
                M[:n, iu + 2 + j] = row(i)
            H[:] = lim[:sat.N_HEAD]
    jcoef = np.zeros((len(plants), 2))
    kick = np.zeros((len(plants), n))
    for s_, k0 in enumerate(bounds[:-1]):
        if s_:
            jcoef[s_] = bs[s_ - 1] - bs[s_]
        if start_s < sep and abs(t[k0] - sep) < 0.5 * dt_s * rec + 1e-12 and ascent.boosters.count:
            kick[s_, si("xi_rate_rad_s")] = ascent.boosters.separation_rate_kick_rad_s
    x0 = np.zeros(n)
    x0[si("xi_rad")] = attitude0_rad
    return _Lane(plants, mats, heads, jcoef, kick, x0, r, model, np.stack([law.pack() for law in laws]))
