"""Run checks that need the model's dynamics: the engines' default steps
(:func:`default_dt_s`), the step against the fastest mode, dwell and run sizes, linear stability
before a run, and the physical envelope after it.

The documented limits themselves (gimbal range, frequencies, durations, sizes) and the scalar
checks are in :mod:`taos.bounds`; this module sits one layer up, beside the simplex model and
the profiles it inspects.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import EnvelopeExceeded, InputError, UnstableModel
from ..bounds import (GIMBAL_RANGE_RAD, HARD_STOP_RAD, LOAD_FORCE_FACTOR, MAX_JOB_BYTES, MAX_STEPS,
                     MIN_STEPS_PER_CYCLE, RK4_STEP_LIMIT, check_duration)


from .runfile import ENGINES  # noqa: E402,F401  (the engine models a run can use)


def default_dt_s(engine: str = "simplex", *, source: str = "command line", field: str = "--engine",
                 time_run: bool = False) -> float:
    """The integration step [s] engine model ``engine`` runs at unless told otherwise:
    :data:`taos.planar.simulate.DEFAULT_DT_S` (2e-4 s) for ``"simplex"``; for ``"taos"`` (imported
    only then: the 3-D model loads its compiled kernels) a time run's (``time_run``, ``taos
    simulate``) :data:`taos.taos3d.simulate.DEFAULT_DT_S` (8e-4 s), else the step of its dwells, the
    verdict and the co-simulation block :data:`taos.taos3d.simulate.DWELL_DT_S` (4e-4 s). Another name
    is bad input (one line naming ``field``)."""
    if engine == "taos":
        from ..taos3d.simulate import DEFAULT_DT_S, DWELL_DT_S
        if not time_run:
            return DWELL_DT_S
    elif engine == "simplex":
        from .simulate import DEFAULT_DT_S
    else:
        raise InputError(source, field, " or ".join(ENGINES), got=repr(engine))
    return DEFAULT_DT_S


def fastest_mode_rad_s(model, axes=("pitch", "yaw"), *, pressure_limit: bool = True) -> float:
    """|lambda|_max of the linear block over ``axes`` [rad/s], or the supply-pressure limit's
    fastest rate at stall when larger (:func:`taos.planar.saturation.pressure_limit_rate_per_s`)
    and ``pressure_limit`` (False for an engine whose step integrates that rate exactly, the 3-D
    engine's: :func:`taos.taos3d.dynamics._etd_rk4`)."""
    from ._limits_pack import pressure_limit_rate_per_s
    from .simplex import simplex_state_space

    lin = max(float(np.max(np.abs(simplex_state_space(model, ax).poles()))) for ax in axes)
    return max(lin, pressure_limit_rate_per_s(model.actuator)) if pressure_limit else lin


def check_run_step(dt_s: float, model=None, *, max_freq_hz: float | None = None, duration_s: float | None = None,
                   n_axes: int = 1, source: str = "command line", field: str = "--dt",
                   pressure_limit: bool = True) -> None:
    """The integration step against the fastest linear mode (and the supply-pressure limit's
    rate unless ``pressure_limit`` is False: :func:`fastest_mode_rad_s`), the command
    frequencies and the job size (steps and memory, estimated before any array is made)."""
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise InputError(source, field, "a positive step in seconds", got=repr(dt_s))
    if model is not None:
        lam = fastest_mode_rad_s(model, pressure_limit=pressure_limit)
        if dt_s * lam > RK4_STEP_LIMIT:
            raise InputError(source, field, f"a step at most {RK4_STEP_LIMIT / lam:.3g} s (dt |lambda|max <= "
                             f"{RK4_STEP_LIMIT:g}, fastest mode {lam / (2 * math.pi):.4g} Hz of {model.source})",
                             got=f"{dt_s:g} s")
    if max_freq_hz is not None and max_freq_hz * dt_s > 1.0 / MIN_STEPS_PER_CYCLE:
        raise InputError(source, field, f"a step at most {1.0 / (MIN_STEPS_PER_CYCLE * max_freq_hz):.3g} s "
                         f"({MIN_STEPS_PER_CYCLE} steps per cycle of the highest command frequency "
                         f"{max_freq_hz:g} Hz)", got=f"{dt_s:g} s")
    if duration_s is not None:
        n = duration_s / dt_s
        if n > MAX_STEPS:
            raise InputError(source, field, f"at most {MAX_STEPS:.0e} steps for the {duration_s:g} s run "
                             f"(a step of at least {duration_s / MAX_STEPS:.3g} s)", got=f"{dt_s:g} s")
        need = n * 8 * (4 + 4 * n_axes)  # time, commands and their copies, float64
        if need > MAX_JOB_BYTES:
            raise InputError(source, field, f"a job within {MAX_JOB_BYTES / 2 ** 30:g} GiB of memory",
                             got=f"{dt_s:g} s, which needs about {need / 2 ** 30:.3g} GiB")


def _profile_parts(profile):
    """Single-axis leaves of a profile (for frequency and amplitude checks)."""
    from ..profiles import Circular, Sequence, TwoAxis

    if isinstance(profile, TwoAxis):
        return _profile_parts(profile.pitch) + _profile_parts(profile.yaw)
    if isinstance(profile, Sequence):
        return [q for p in profile.parts for q in _profile_parts(p)]
    if isinstance(profile, Circular):
        return [profile]
    return [profile]


def profile_max_frequency_hz(profile) -> float:
    """Highest commanded frequency of a profile [Hz] (0 for steps and ramps)."""
    f = 0.0
    for p in _profile_parts(profile):
        for name in ("frequency_hz", "f0_hz", "f1_hz"):
            f = max(f, float(getattr(p, name, 0.0)))
        f = max([f] + [float(x) for x in getattr(p, "freqs_hz", ())])
    return f


MAX_DWELL_STEPS = 5e7


def check_dwell(model, freqs_hz, dt_s: float = 2e-4, axis: str = "pitch", source: str = "command line",
                field: str = "--freq-hz", min_steps_per_cycle: int = 64, n_amplitudes: int = 1) -> None:
    """The integration steps a sine-dwell grid of ``n_amplitudes`` x ``freqs_hz`` will take at
    most (settling over the slowest linear mode, then two measured cycles;
    :func:`taos.planar.freqresp.sine_dwell_points`; shooting's fallback has the same budget) within
    MAX_DWELL_STEPS."""
    from .freqresp import settle_time_s

    ts = settle_time_s(model, axis)
    total = 0.0
    for f in np.atleast_1d(freqs_hz):
        npc = max(math.ceil(1.0 / (f * dt_s)), min_steps_per_cycle)
        total += (max(2.0, math.ceil(ts * f)) + 2.0) * npc * n_amplitudes
    if total > MAX_DWELL_STEPS:
        raise InputError(source, field, f"sine-dwell frequencies needing at most {MAX_DWELL_STEPS:.0e} integration "
                         f"steps (settling {ts:.3g} s, then two cycles, per amplitude)", got=f"{total:.3g} steps")


def check_run(model, profile, dt_s: float, *, source: str = "command line", field: str = "--dt",
              pressure_limit: bool = True) -> None:
    """Everything about a time run that can be refused before it starts (see the table);
    ``pressure_limit`` as :func:`check_run_step`."""
    check_duration(profile.duration_s, getattr(profile, "source", "profile"), "(duration)")
    check_run_step(dt_s, model, max_freq_hz=profile_max_frequency_hz(profile) or None,
               duration_s=profile.duration_s + 1.0, n_axes=2, source=source, field=field,
               pressure_limit=pressure_limit)


def unstable_modes(model, axes=("pitch", "yaw")) -> list[tuple[str, float, float]]:
    """(axis, freq_hz, damping_ratio) of every right-half-plane pole of the linear block."""
    from .simplex import simplex_state_space

    out = []
    for ax in axes:
        p = simplex_state_space(model, ax).poles()
        for x in p[(p.imag >= 0) & (p.real > 1e-9 * np.maximum(np.abs(p), 1.0))]:
            w = abs(x)
            out.append((ax, float(w / (2 * math.pi)), float(-x.real / w) if w > 0 else -1.0))
    return out


def _unstable_hint(model) -> str:
    a = model.actuator
    if a.pressure_feedback_gain_m_per_s_Pa == 0.0:
        return ("likely cause: no dynamic pressure feedback (actuator.pressure_feedback_gain = 0) with "
                "K_c + C_l below A^2 K_v / K_h")
    return "likely cause: actuator.loop_gain, flow_pressure_coefficient or pressure_feedback_gain"


def check_linear_stability(model, axes=("pitch", "yaw"), allow: bool = False) -> None:
    """Refuse (exit 3) a model whose linear block is unstable, naming the least-damped unstable
    mode (frequency and damping ratio), unless ``allow``."""
    if allow:
        return
    modes = unstable_modes(model, axes)
    if modes:
        ax, f, z = min(modes, key=lambda m: m[2])
        raise UnstableModel(model.source, ax, f, z, _unstable_hint(model))


def check_envelope(th, model) -> None:
    """Stop (exit 3) a run whose engine went beyond the hard stops or whose load force went
    beyond what the supply pressure holds; names the first such time, the state and the cause."""
    stall = model.actuator.stall_force_N
    first = None
    for i, ax in enumerate(th.axes):
        eng = np.abs(np.asarray(th.engine_rad[i]))
        fl = np.abs(np.asarray(th.load_force_N[i]))
        for arr, lim, what in ((eng, HARD_STOP_RAD, "engine"), (fl, LOAD_FORCE_FACTOR * stall, "load")):
            bad = np.flatnonzero(~(arr <= lim))
            if bad.size and (first is None or bad[0] < first[0]):
                first = (int(bad[0]), ax, what, float(arr[bad[0]]), lim)
    if first is None:
        return
    k, ax, what, val, lim = first
    t = float(th.t_s[k])
    if what == "engine":
        state = (f"{ax} engine angle {math.degrees(val):.4g} deg beyond the hard stops "
                 f"+-{math.degrees(lim):.3g} deg")
    else:
        state = (f"{ax} load force {val:.4g} N beyond {LOAD_FORCE_FACTOR:g} x the stall force A P_s = "
                 f"{stall:.4g} N (pressure beyond supply)")
    modes = unstable_modes(model)
    if modes:
        m = min(modes, key=lambda m: m[2])
        cause = (f"the unstable {m[0]} mode at {m[1]:.4g} Hz (damping ratio {m[2]:.3g}); "
                 + _unstable_hint(model).removeprefix("likely cause: "))
    elif np.max(np.abs(th.command_rad)) > GIMBAL_RANGE_RAD:
        cause = "a command beyond the gimbal range"
    elif what == "load":
        cause = ("a stall force A P_s too small for the load (actuator.supply_pressure, piston_area), "
                 "or a command too fast or too large for the actuator")
    else:
        cause = "a command too fast or too large for the actuator's flow and force (check the profile)"
    raise EnvelopeExceeded(t, state, cause)
