"""Figures of merit of a TVC axis, as an actuator specification states them.

Frequency domain (:func:`frequency_merit`, from the exact linear response on a dense log
grid, :func:`taos.planar.freqresp.linear_freqresp`; phase continuous from low frequency):

* ``bandwidth_3db_hz``: the lowest frequency at which the gain falls 3 dB below its
  low-frequency value (linear interpolation of dB in log f between grid points);
* ``phase_90_hz``: the lowest frequency at which the phase reaches -90 deg;
* ``peak_gain_db`` and ``peak_freq_hz``: the largest gain relative to the low-frequency
  value and where it occurs (refined by a parabola in log f through the three grid points
  around the maximum);
* ``load_resonance_hz`` w_L = sqrt((K_L R^2 + K_n) / J_n) and ``notch_hz``, the minimum of
  the command -> piston gain (:func:`taos.planar.simplex.load_resonance_from_notch`, the one notch
  finder every command uses).

Reported for command -> engine (theta / theta_c) and command -> piston (x_p / (R theta_c)).

Time domain (:func:`step_merit`, by simulating the full nonlinear simplex model,
:func:`taos.planar.simulate.simulate`, with its friction and avionics):

* ``rise_time_s``: 10 % to 90 % of the final engine angle after a step of
  ``step_amplitude_rad``; ``overshoot_pct``: (peak - final) / final;
* ``threshold_deg``: the smallest command step after which the engine settles at least half
  way to the command (bisection between 0 and the step amplitude; with Coulomb friction it
  sits near the breakaway deflection T_c / (K_L R^2), DESIGN.md "Why stiffness decides the
  limit cycle", plus the avionics quantisation);
* ``hysteresis_deg``: a slow triangle +-A (``hysteresis_amplitude_rad``, ramp rate
  ``ramp_rate_rad_s``, slow enough that the servo's velocity lag is small): the engine angle on
  the way down minus on the way up at zero command
  (the friction dead band the engine lags by: about 2 T_c / (K_L R^2 + K_n) for Coulomb
  friction);
* ``null_shift_deg``: the engine angle left at zero command after the triangle
  (0 -> +A -> -A -> +A -> 0, each level held 0.2 s) returns.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..model import TvcModel


def _none(x):
    return None if x is None or not math.isfinite(x) else float(x)


@dataclass(frozen=True)
class ResponseMerit:
    """Frequency figures of one response (SI, Hz, dB relative to the low-frequency gain)."""

    response: str
    low_frequency_gain_db: float
    bandwidth_3db_hz: float | None
    phase_90_hz: float | None
    peak_gain_db: float
    peak_freq_hz: float

    def to_dict(self) -> dict:
        return {k: (_none(v) if isinstance(v, float) else v) for k, v in asdict(self).items()}


@dataclass(frozen=True)
class FrequencyMerit:
    """Frequency-domain figures of merit of one axis (module docstring)."""

    axis: str
    engine: ResponseMerit
    piston: ResponseMerit
    load_resonance_hz: float
    notch_hz: float
    f_range_hz: tuple[float, float]
    engine_model: str = "simplex"

    def to_dict(self) -> dict:
        return {"axis": self.axis, "engine": self.engine.to_dict(), "piston": self.piston.to_dict(),
                "load_resonance_hz": self.load_resonance_hz, "notch_hz": self.notch_hz,
                "f_range_hz": list(self.f_range_hz), "engine_model": self.engine_model,
                "definition": "linear response; gains relative to the low-frequency gain; -3 dB and -90 deg: "
                              "lowest crossing; piston x_p/(R theta_c); phase continuous from low frequency"}


def _first_crossing(x, y, level) -> float | None:
    """Lowest x where y first falls to ``level`` (linear in log x between samples), or None."""
    below = np.flatnonzero(y <= level)
    if below.size == 0:
        return None
    k = int(below[0])
    if k == 0:
        return float(x[0])
    lx0, lx1 = math.log10(x[k - 1]), math.log10(x[k])
    t = (y[k - 1] - level) / (y[k - 1] - y[k])
    return float(10 ** (lx0 + t * (lx1 - lx0)))


def response_merit(name: str, freq_hz, h, phase_deg) -> ResponseMerit:
    """Figures of a response sampled on a dense, increasing log grid (module docstring)."""
    f = np.asarray(freq_hz, float)
    g = 20 * np.log10(np.abs(h))
    g0 = float(g[0])
    rel = g - g0
    k = int(np.argmax(rel))
    pk_f, pk_g = float(f[k]), float(rel[k])
    if 0 < k < f.size - 1:
        x = np.log10(f[k - 1:k + 2])
        a, b, c = np.polyfit(x, rel[k - 1:k + 2], 2)
        if a < 0:
            xv = float(np.clip(-b / (2 * a), x[0], x[2]))
            pk_f, pk_g = 10 ** xv, float(np.polyval([a, b, c], xv))
    return ResponseMerit(name, g0, _first_crossing(f, rel, -3.0), _first_crossing(f, np.asarray(phase_deg), -90.0),
                         pk_g, pk_f)


def frequency_merit(model: TvcModel, axis: str = "pitch", f_min_hz: float = 0.01, f_max_hz: float = 50.0,
                    n: int = 1500, *, taos=None) -> FrequencyMerit:
    """Frequency figures of merit of ``axis`` from the exact linear response (module docstring).

    ``taos``: a :class:`taos.taos3d.TaosModel` of ``model``: the figures are then the 3-D model's
    own, from its linearisation (:func:`taos.taos3d.linear_state_space`, via
    :func:`taos.taos3d.taos_freqresp`), and ``notch_hz`` the minimum of its command -> piston gain
    between 0.5 and 30 Hz (:func:`taos.linear.notch_hz`, as the planar notch);
    ``load_resonance_hz`` stays the planar w_L, the target the 3-D line stiffness is derived for."""
    f = np.logspace(math.log10(f_min_hz), math.log10(f_max_hz), n)
    if taos is None:
        from ..planar.freqresp import linear_freqresp
        from ..planar.simplex import load_resonance_from_notch

        fr = linear_freqresp(model, f, axis)
        notch = load_resonance_from_notch(model, axis)
    else:
        from ..linear import notch_hz
        from ..taos3d import taos_freqresp

        fr = taos_freqresp(taos, f, None, axis)
        # the same search band as the planar notch (load_resonance_from_notch)
        notch = notch_hz(lambda x: np.abs(taos_freqresp(taos, x, None, axis).piston), 0.5, 30.0)
    return FrequencyMerit(axis, response_merit("engine", f, fr.engine, fr.engine_phase_deg()),
                          response_merit("piston", f, fr.piston, fr.piston_phase_deg()),
                          model.load_resonance_hz(axis), notch, (f_min_hz, f_max_hz),
                          "taos" if taos is not None else "simplex")


@dataclass(frozen=True)
class StepMerit:
    """Time-domain figures of merit of one axis (module docstring); angles in deg."""

    axis: str
    step_amplitude_deg: float
    rise_time_s: float | None
    overshoot_pct: float | None
    threshold_deg: float
    hysteresis_deg: float
    null_shift_deg: float
    hysteresis_amplitude_deg: float
    friction_model: str

    def to_dict(self) -> dict:
        return {k: (_none(v) if isinstance(v, float) else v) for k, v in asdict(self).items()}


#: the step figures' command: a step at t0 [s], held [s]
STEP_T0_S = 0.2
STEP_HOLD_S = 1.5


def _engine_step(model, axis, amp_rad, t_step=STEP_T0_S, hold=STEP_HOLD_S, dt_s=2e-4):
    from ..profiles import Step
    from ..planar.simulate import simulate
    th = simulate(_axis_model(model, axis), Step(amp_rad, t_step, hold), dt_s=dt_s, record_every=1, duration_s=t_step + hold)
    return th.t_s, th.engine_rad[0]


def _axis_model(model: TvcModel, axis: str) -> TvcModel:
    """A model whose pitch axis is ``axis`` (single-axis profiles drive pitch)."""
    if axis == "pitch":
        return model
    import dataclasses   # an analysis device made in code: recorded in the copy's overrides and hash
    return model.replace(engine=dataclasses.replace(model.engine, inertia_pitch_kgm2=model.engine.inertia_yaw_kgm2))


def rise_and_overshoot(t_s, engine_rad, t0_s: float = STEP_T0_S) -> tuple[float | None, float | None]:
    """(rise time 10-90 % [s], overshoot [%]) of an engine angle ``engine_rad`` [rad] at times
    ``t_s`` [s] after a command step at ``t0_s``, relative to the final value (the mean of the
    last tenth of the record); None when undefined. Any engine's step run (planar or 3-D)."""
    t, th = np.asarray(t_s), np.asarray(engine_rad)
    m = t >= t0_s
    tt, yy = t[m] - t0_s, th[m]
    final = float(np.mean(yy[-max(10, yy.size // 10):]))
    rise = over = None
    if abs(final) > 0:
        s = yy / final
        i10 = np.flatnonzero(s >= 0.1)
        i90 = np.flatnonzero(s >= 0.9)
        if i10.size and i90.size:
            rise = float(tt[i90[0]] - tt[i10[0]])
        over = float(100.0 * max(0.0, (np.max(s) - 1.0)))
    return rise, over


def step_response_figures(model: TvcModel, axis: str = "pitch", step_amplitude_rad: float = math.radians(0.5),
                          dt_s: float = 2e-4) -> tuple[float | None, float | None]:
    """(rise time 10-90 % [s], overshoot [%]) of the engine angle after a command step of
    ``step_amplitude_rad`` [rad] on the nonlinear simplex model (module docstring), relative to
    the final value (the mean of the last tenth of the 1.5 s hold); None when undefined."""
    t, th = _engine_step(model, axis, step_amplitude_rad, dt_s=dt_s)
    return rise_and_overshoot(t, th)


def _threshold_rad(model: TvcModel, axis: str, step_amplitude_rad: float, threshold_tol_rad: float,
                   dt_s: float) -> float:
    """The threshold [rad] (module docstring) by bisection: a chain of step runs, each after the
    one before (nan when even ``step_amplitude_rad`` does not move the engine half way)."""
    def moves(a):
        _, e = _engine_step(model, axis, a, hold=1.0, dt_s=dt_s)
        return float(np.mean(e[-200:])) >= 0.5 * a

    lo, hi = 0.0, step_amplitude_rad
    if not moves(hi):
        return math.nan
    while hi - lo > threshold_tol_rad:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if moves(mid) else (mid, hi)
    return hi


def _hysteresis_run(model: TvcModel, axis: str, amplitude_rad: float, ramp_rate_rad_s: float,
                    dt_s: float) -> tuple[float, float, float]:
    """The slow triangle (module docstring): the engine angle [rad] at zero command on the way
    down and on the way up, and the one left at its end."""
    from ..profiles import MultiRamp
    from ..planar.simulate import simulate

    A = amplitude_rad
    prof = MultiRamp((A, -A, A, 0.0), ramp_rate_rad_s, hold_s=0.2)
    h = simulate(_axis_model(model, axis), prof, dt_s=dt_s, record_every=5, duration_s=prof.duration_s)
    e, tk = h.engine_rad[0], h.t_s
    t_down0 = A / ramp_rate_rad_s + 0.2 + A / ramp_rate_rad_s        # command passes 0 going down
    t_up0 = t_down0 + A / ramp_rate_rad_s + 0.2 + A / ramp_rate_rad_s  # and going up again
    return float(np.interp(t_down0, tk, e)), float(np.interp(t_up0, tk, e)), float(e[-1])


def step_merits(model: TvcModel, axes=("pitch", "yaw"), *, step_amplitude_rad: float = math.radians(0.5),
                hysteresis_amplitude_rad: float = math.radians(0.2), ramp_rate_rad_s: float = math.radians(0.05),
                threshold_tol_rad: float = math.radians(0.002), dt_s: float = 2e-4,
                threads: int | None = None) -> dict[str, StepMerit]:
    """{axis: :func:`step_merit`} of every axis in ``axes``, their independent runs (per axis the
    step, the threshold's bisection chain and the hysteresis triangle) spread over ``threads``
    threads (:func:`taos.planar._parallel.run_tasks`; default numba's thread count, 1: one after
    the other) with the numbers of a serial run."""
    from ..planar._parallel import run_tasks

    tasks, cost = [], []
    for ax in axes:   # task order = the serial order (its first failure is the one raised)
        tasks += [lambda ax=ax: step_response_figures(model, ax, step_amplitude_rad, dt_s=dt_s),
                  lambda ax=ax: _threshold_rad(model, ax, step_amplitude_rad, threshold_tol_rad, dt_s),
                  lambda ax=ax: _hysteresis_run(model, ax, hysteresis_amplitude_rad, ramp_rate_rad_s, dt_s)]
        # their costs in simulated seconds (the longest start first): one 1.7 s step; ~9 bisection
        # steps of 1.2 s; the triangle's ramps over 6 A and its 4 holds of 0.2 s
        cost += [1.7, 1.2 * (1 + math.log2(max(step_amplitude_rad / threshold_tol_rad, 1.0))),
                 6 * hysteresis_amplitude_rad / ramp_rate_rad_s + 0.8]
    res = run_tasks(tasks, threads, start_order=sorted(range(len(tasks)), key=lambda i: -cost[i]))
    out = {}
    for k, ax in enumerate(axes):
        (rise, over), hi, (e_down, e_up, null) = res[3 * k: 3 * k + 3]
        out[ax] = StepMerit(ax, math.degrees(step_amplitude_rad), rise, over, math.degrees(hi),
                            math.degrees(e_down - e_up), math.degrees(null), math.degrees(hysteresis_amplitude_rad),
                            model.friction.name)
    return out


def step_merit(model: TvcModel, axis: str = "pitch", *, step_amplitude_rad: float = math.radians(0.5),
               hysteresis_amplitude_rad: float = math.radians(0.2), ramp_rate_rad_s: float = math.radians(0.05),
               threshold_tol_rad: float = math.radians(0.002), dt_s: float = 2e-4,
               threads: int | None = None) -> StepMerit:
    """Step, threshold and hysteresis figures of ``axis`` by simulation (module docstring); its
    independent runs on ``threads`` threads (:func:`step_merits`)."""
    return step_merits(model, (axis,), step_amplitude_rad=step_amplitude_rad,
                       hysteresis_amplitude_rad=hysteresis_amplitude_rad, ramp_rate_rad_s=ramp_rate_rad_s,
                       threshold_tol_rad=threshold_tol_rad, dt_s=dt_s, threads=threads)[axis]
