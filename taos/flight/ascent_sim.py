"""Flying an ascent (:mod:`taos.flight.ascent`): the closed flight loop with the nonlinear TVC,
time-varying vehicle, boosters until separation, PTIs and winds; and the LCO read off its windows.

Each axis (pitch, yaw) is the planar flight loop of :func:`taos.flight.vehicle.flight_plant`
(vehicle + FCS + the simplex TVC with its friction, avionics and actuator/gimbal limits,
integrated by the compiled RK4 kernel of :mod:`taos.planar.dynamics`) augmented with

* the booster TVC, a first-order servo on the FCS command (state ``booster_deflection_rad``),
  adding n_b T_b l_b / I_v delta_b to the attitude acceleration until separation;
* a disturbance input ``disturbance_rad_s2`` = M_a(t) alpha_w(t) (wind angle of attack);
* the PTI added to the FCS command (input ``pti_rad``).

The vehicle properties and the scheduled FCS gains are held constant over each update interval
(zero-order hold; the file's ``update_interval``, 1 s) and the state is carried from interval to
interval: the attitude and rate are kept continuous across a change of the tail-wags-dog
coefficient b (xi = theta - b delta is re-based), the friction state is carried as it is. At
separation the attitude rate receives the file's ``separation_rate_kick``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from taos.flight.ascent import Ascent, aero_instability, control_acceleration, pti_command, wind_speed
from taos.flight.lco import FlightHistory, measure_oscillation
from taos.flight.vehicle import FlightModel, flight_plant
from taos.harmonics import fit_sines
from taos.linear import StateSpace
from taos.model import TvcModel
from taos.results import atomic_write, package_version, write_provenance
from taos.planar.simplex import LurePlant, extend_plant
from taos.planar.simulate import check_friction_step, integrate_plant

AXES = ("pitch", "yaw")
DEFAULT_DT_S = 5e-4
#: recorded signals of an ascent run, per axis (SI)
SIGNALS = ("attitude_rad", "rate_rad_s", "command_rad", "engine_rad", "engine_rate_rad_s", "piston_m",
           "friction_torque_Nm", "booster_deflection_rad", "pti_rad", "disturbance_rad_s2")
MAX_STEPS = 50_000_000


def flight_at(ascent: Ascent, t_s: float, axis: str) -> tuple[FlightModel, float]:
    """The flight loop frozen at ``t_s``: vehicle properties from the trajectory, FCS gains
    scheduled by a_ref / a(t); and the booster control acceleration per radian [1/s^2]."""
    fl = ascent.flight
    tr = ascent.trajectory
    core, boost = (float(v) for v in control_acceleration(ascent, t_s))
    k = fl.vehicle.control_acceleration_per_s2(axis) / (core + boost)
    inertia = float(tr.at("inertia_kgm2", t_s))
    veh = dataclasses.replace(fl.vehicle, mass_kg=float(tr.at("mass_kg", t_s)), pitch_inertia_kgm2=inertia,
                              yaw_inertia_kgm2=inertia,
                              thrust_per_engine_N=float(tr.at("core_thrust_per_engine_N", t_s)),
                              gimbal_arm_m=float(tr.at("gimbal_arm_m", t_s)),
                              aero_instability_per_s2=float(aero_instability(ascent, t_s)))
    fcs = dataclasses.replace(fl.fcs, attitude_gain=fl.fcs.attitude_gain * k,
                              integral_gain_per_s=fl.fcs.integral_gain_per_s * k, rate_gain_s=fl.fcs.rate_gain_s * k)
    return dataclasses.replace(fl, vehicle=veh, fcs=fcs), boost


def ascent_plant(flight: FlightModel, model: TvcModel, axis: str, booster_accel_per_s2: float,
                 booster_time_constant_s: float) -> LurePlant:
    """:func:`~taos.flight.vehicle.flight_plant` with the booster TVC state and the disturbance
    input added (module docstring). External inputs ``pti_rad`` [rad], ``disturbance_rad_s2``
    [rad/s^2]; the flight plant's limits carried (:func:`~taos.planar.simplex.extend_plant`).
    Outputs: the flight plant's, ``booster_deflection_rad``, then every state
    (``state:<name>``) so a run can be continued."""
    base = flight_plant(flight, model, axis)
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


@dataclass(frozen=True, eq=False)
class AscentHistory:
    """An ascent run: ``t_s`` and, per axis, the :data:`SIGNALS` as (n_axes, n_samples) arrays
    (SI); separation time [s]; PTI windows per axis; provenance."""

    t_s: np.ndarray
    axes: tuple[str, ...]
    signals: dict
    separation_time_s: float
    pti_windows: dict
    friction_model: str
    load_stiffness_N_per_m: float
    provenance: dict = field(default_factory=dict)

    def signal(self, name: str, axis: str) -> np.ndarray:
        return self.signals[name][self.axes.index(axis)]

    def flight_history(self, axis: str, t0_s: float, t1_s: float) -> FlightHistory:
        """The part of one axis between t0 and t1 as a :class:`~taos.flight.lco.FlightHistory`."""
        sel = (self.t_s >= t0_s) & (self.t_s <= t1_s)
        g = lambda k: self.signal(k, axis)[sel]  # noqa: E731
        return FlightHistory(t_s=self.t_s[sel], attitude_rad=g("attitude_rad"), command_rad=g("command_rad"),
                             engine_rad=g("engine_rad"), piston_m=g("piston_m"),
                             friction_torque_Nm=g("friction_torque_Nm"), pti_rad=g("pti_rad"),
                             friction_model=self.friction_model, load_stiffness_N_per_m=self.load_stiffness_N_per_m)

    def to_hdf5(self, path) -> None:
        """Write atomically: /t_s, /<axis>/<signal>, PTI windows and provenance as attributes."""
        def write(tmp):
            import h5py
            with h5py.File(tmp, "w") as h5:
                h5.create_dataset("t_s", data=self.t_s)
                h5.attrs["axes"] = ",".join(self.axes)
                h5.attrs["separation_time_s"] = self.separation_time_s
                h5.attrs["friction_model"] = self.friction_model
                h5.attrs["load_stiffness_N_per_m"] = self.load_stiffness_N_per_m
                write_provenance(h5, self.provenance)
                for i, ax in enumerate(self.axes):
                    g = h5.create_group(ax)
                    g.attrs["pti_windows_s"] = np.asarray(self.pti_windows[ax], float).reshape(-1, 2)
                    for k in SIGNALS:
                        g.create_dataset(k, data=self.signals[k][i], compression="gzip")
        atomic_write(path, write)


def simulate_ascent(ascent: Ascent, model: TvcModel, *, axes: tuple[str, ...] = AXES, start_s: float = 0.0,
                    end_s: float | None = None, dt_s: float = DEFAULT_DT_S, record_interval_s: float = 0.01,
                    seed: int = 0, attitude0_rad: float = 0.0, progress: bool = False) -> AscentHistory:
    """Fly ``ascent`` from ``start_s`` to ``end_s`` [s] (default the trajectory's end) with the
    TVC ``model`` on each of ``axes``.

    ``dt_s`` RK4 step [s]; ``record_interval_s`` output spacing [s] (a whole number of steps);
    ``seed`` draws the turbulence (axis k uses the stream SeedSequence([seed, k])), so a run is a
    pure function of its inputs; ``attitude0_rad`` initial attitude error [rad]. Raises
    :class:`~taos.errors.SimulationUnstable` on a non-finite state."""
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
    bounds = sorted(bounds)
    out = {k: [] for k in SIGNALS}
    pw = {ax: ascent.pti_windows(ax) for ax in axes}
    it = list(enumerate(axes))
    if progress:
        from tqdm import tqdm
        it = tqdm(it, desc="ascent", unit="axis")
    for ai, ax in it:
        rng = np.random.default_rng(np.random.SeedSequence([int(seed), AXES.index(ax)]))
        w = wind_speed(ascent, t, rng, dt_s)
        comp = math.cos(ascent.wind.azimuth_rad) if ax == "pitch" else math.sin(ascent.wind.azimuth_rad)
        dist = aero_instability(ascent, t) * comp * w / ascent.trajectory.at("velocity_m_s", t)
        r = np.column_stack([pti_command(ascent, ax, t), dist])
        ys, auxs = [], []
        x = z = None
        b_prev = None
        for k0, k1 in zip(bounds[:-1], bounds[1:]):
            tm = t[k0] + 0.5 * (t[k1] - t[k0])
            flight, a_b = flight_at(ascent, tm, ax)
            plant = ascent_plant(flight, model, ax, a_b, ascent.boosters.actuator_time_constant_s)
            si = plant.ss.state_index
            b = flight.vehicle.twd_coefficient(ax)
            if x is None:
                check_friction_step(model, plant.inertia_kgm2, dt_s)
                x = np.zeros(plant.ss.A.shape[0])
                x[si("xi_rad")] = attitude0_rad
                z = 0.0
            else:  # keep theta = xi + b delta and theta' continuous across a change of b
                d, dd = x[si("theta_rad")], x[si("omega_rad_s")]
                x[si("xi_rad")] += (b_prev - b) * d
                x[si("xi_rate_rad_s")] += (b_prev - b) * dd
            if start_s < sep and abs(t[k0] - sep) < 0.5 * dt_s * rec + 1e-12 and ascent.boosters.count:
                x[si("xi_rate_rad_s")] += ascent.boosters.separation_rate_kick_rad_s
            y, aux = integrate_plant(plant, model, r[k0:k1 + 1], dt_s, rec, x0=x, z0=z)
            o = plant.ss.output_index
            nst = plant.ss.A.shape[0]
            x = y[-1, o(f"state:{plant.ss.states[0]}"):o(f"state:{plant.ss.states[0]}") + nst].copy()
            z = float(aux[-1, 1])
            b_prev = b
            last = k1 == nsteps
            keep = slice(None) if last else slice(0, -1)
            ys.append(np.column_stack([y[keep, o("attitude_rad")], y[keep, o("rate_rad_s")],
                                       y[keep, o("delta_cmd_rad")] + r[k0:k1 + 1:rec, 0][keep],
                                       y[keep, o("theta_rad")], y[keep, o("omega_rad_s")], y[keep, o("x_p_m")],
                                       aux[keep, 0], y[keep, o("booster_deflection_rad")]]))
            auxs.append(r[k0:k1 + 1:rec][keep])
        Y = np.vstack(ys)
        Rr = np.vstack(auxs)
        for j, k in enumerate(SIGNALS[:8]):
            out[k].append(Y[:, j])
        out["pti_rad"].append(Rr[:, 0])
        out["disturbance_rad_s2"].append(Rr[:, 1])
    prov = {"model_file": model.source, "model_sha256": model.sha256, "ascent_file": ascent.source,
            "ascent_sha256": ascent.sha256, "flight_file": ascent.flight.source,
            "flight_sha256": ascent.flight.sha256, "package_version": package_version(),
            "solver": {"method": "rk4-fixed-step", "dt_s": dt_s, "record_every": rec},
            "seed": int(seed), "start_s": start_s, "end_s": end, "attitude0_rad": attitude0_rad,
            "friction_model": model.friction.name}
    return AscentHistory(t_s=t[::rec], axes=tuple(axes), signals={k: np.vstack(v) for k, v in out.items()},
                         separation_time_s=sep, pti_windows=pw, friction_model=model.friction.name,
                         load_stiffness_N_per_m=model.structure.load_stiffness_N_per_m, provenance=prov)


# -- windows --------------------------------------------------------------------------------
@dataclass(frozen=True)
class WindowResult:
    """One analysis window of an ascent run: ``kind`` 'pti' or 'quiescent', [start, end] [s];
    the oscillation of the FCS command measured as ``taos lco`` does
    (:func:`~taos.flight.lco.measure_oscillation`): LCO flag, command and engine amplitudes
    [rad], frequency [Hz]; for PTI windows the command fundamental at ``lco_band_freq_hz``
    that the friction adds beyond the linear run (``friction_band_amplitude_rad``)."""

    axis: str
    kind: str
    start_s: float
    end_s: float
    lco: bool
    amplitude_rad: float
    engine_amplitude_rad: float
    freq_hz: float
    friction_band_amplitude_rad: float | None = None

    def to_dict(self) -> dict:
        """JSON form (degrees; None where a figure does not apply)."""
        num = lambda v, f=math.degrees: None if v is None or not math.isfinite(v) else f(v)  # noqa: E731
        return {"axis": self.axis, "kind": self.kind, "start_s": self.start_s, "end_s": self.end_s, "lco": self.lco,
                "amplitude_deg": num(self.amplitude_rad), "engine_amplitude_deg": num(self.engine_amplitude_rad),
                "frequency_hz": num(self.freq_hz, float),
                "friction_band_amplitude_deg": num(self.friction_band_amplitude_rad)}


def analysis_windows(h: AscentHistory, axis: str, settle_s: float = 15.0, min_quiet_s: float = 20.0
                     ) -> list[tuple[str, float, float]]:
    """(kind, start, end) of the post-separation windows: each PTI window, and each quiescent
    stretch of at least ``min_quiet_s`` between them (starting ``settle_s`` after separation or
    after a PTI ends)."""
    t0 = max(h.separation_time_s, float(h.t_s[0]))
    t_end = float(h.t_s[-1])
    out = []
    cursor = t0 + settle_s
    for a, b in sorted(h.pti_windows[axis]):
        if b <= t0 or a >= t_end:
            continue
        if a - cursor >= min_quiet_s:
            out.append(("quiescent", cursor, a))
        out.append(("pti", max(a, t0), min(b, t_end)))
        cursor = b + settle_s
    if t_end - cursor >= min_quiet_s:
        out.append(("quiescent", cursor, t_end))
    return out


def analyse_ascent(h: AscentHistory, linear: AscentHistory | None = None, axes=None,
                   threshold_rad: float = 0.004 * math.pi / 180) -> list[WindowResult]:
    """Measure each post-separation window of ``h`` (:func:`analysis_windows`). Quiescent
    windows: the command oscillation (LCO if above ``threshold_rad`` and not decaying). PTI
    windows, when the same run without friction (``linear``) is given: the friction-induced part
    of the command (h - linear) at the frequency of the preceding quiescent window's oscillation
    (the nearest one if none precedes), over the second half of the window (the first half still
    carries the decay of the cycle the PTI broke up): what a limit cycle riding on the PTI would
    show."""
    res = []
    for ax in axes or h.axes:
        wins = analysis_windows(h, ax)
        quiet = []
        for kind, a, b in wins:
            if kind != "quiescent":
                continue
            m = measure_oscillation(h.flight_history(ax, a, b), window_s=b - a, threshold_rad=threshold_rad)
            quiet.append(WindowResult(ax, kind, a, b, m.lco, m.amplitude_rad, m.engine_amplitude_rad, m.freq_hz))
        res += quiet
        for kind, a, b in wins:
            if kind != "pti":
                continue
            band = None
            f = None
            if quiet:
                before = [q for q in quiet if q.end_s <= a + 1e-9]
                near = before[-1] if before else min(quiet, key=lambda q: abs(q.start_s - b))
                f = near.freq_hz
            if linear is not None and f:
                sel = (h.t_s >= 0.5 * (a + b)) & (h.t_s <= b)
                d = h.signal("command_rad", ax)[sel] - linear.signal("command_rad", ax)[sel]
                band = float(fit_sines(h.t_s[sel], d, f, trend=True).amplitude()[0, 0])
            res.append(WindowResult(ax, kind, a, b, False, float("nan"), float("nan"), f or float("nan"), band))
    return sorted(res, key=lambda r: (r.axis, r.start_s))
