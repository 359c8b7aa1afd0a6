"""The public 3-D API's arguments, checked as the command line checks them (issue 25): every
bad value raises :class:`~taos.errors.InputError` naming the argument, before any work, so the
API never answers an absurd input with NaN or a silent result. Limits: :mod:`taos.bounds`."""

from __future__ import annotations

import math

import numpy as np

from ..bounds import MAX_DURATION_S, RESPONSE_FREQ_HZ, check_axis, check_count, check_grid, check_number, check_step
from ..planar.simplex import check_rk4_step
from ..errors import InputError

SRC = "argument"
#: largest dwell amplitude of the API [rad], as :func:`taos.bounds.check_response_args`
MAX_AMPLITUDE_RAD = math.pi / 2
#: integration steps of one dwell grid, the command line's budget (taos.planar.envelope.check_dwell)
MAX_DWELL_STEPS = 5e7


def check_tm(tm) -> None:
    """A TAOS model (:func:`taos.taos_model`)."""
    from .model import TaosModel
    from ..bounds import check_instance

    check_instance(tm, "tm", TaosModel, "a TaosModel (taos.taos_model)")


def check_dwell_steps(total: int) -> None:
    """The integration steps of a whole dwell grid within :data:`MAX_DWELL_STEPS`."""
    if total > MAX_DWELL_STEPS:
        raise InputError(SRC, "freq_hz", f"sine-dwell frequencies needing at most {MAX_DWELL_STEPS:.0e} integration "
                         "steps (settling, then the measured cycles, per amplitude)", got=f"{total:.3g} steps")


def check_dwell_args(tm, freq_hz, amplitudes_rad, axis: str, amp_field: str, dt_max_s, settle_cycles,
                     measure_cycles, settle_s, min_steps_per_cycle) -> tuple[np.ndarray, np.ndarray | None]:
    """(frequencies, amplitudes or None) of a frequency-response call, checked: a known axis, a
    non-empty grid of frequencies in (0, 1e4] Hz and of amplitudes in (0, 90] deg, a positive
    step, whole cycle counts, a job within the dwell step budget."""
    check_tm(tm)
    check_axis(axis)
    f = check_grid(freq_hz, "freq_hz", "Hz", 0.0, RESPONSE_FREQ_HZ[1], source=SRC)
    if amplitudes_rad is None:
        return f, None
    a = check_grid(amplitudes_rad, amp_field, "rad", 0.0, MAX_AMPLITUDE_RAD, source=SRC)
    dt = check_step(dt_max_s, "dt_max_s")
    check_rk4_step(dt, tm.base, "dt_max_s", pressure_limit=False)   # the explicit step's rule, as --dt
    check_count(settle_cycles, "settle_cycles", 0)
    check_count(measure_cycles, "measure_cycles", 1)
    check_count(min_steps_per_cycle, "min_steps_per_cycle", 8)
    check_number(settle_s, "settle_s", 0.0, MAX_DURATION_S, "s", optional=True)
    return f, a


def check_two_axis(amplitude_rad, freq_hz, measure_axis: str) -> tuple[np.ndarray, np.ndarray]:
    """Rows (n, 2) of pitch and yaw amplitudes [rad] and frequencies [Hz] of a two-axis dwell:
    the same shape, every value finite, amplitudes from 0 to 90 deg and frequencies from 0 to
    1e4 Hz, the measured axis' amplitude and frequency above zero."""
    i = AXES_INDEX[check_axis(measure_axis, "measure_axis")]
    out = []
    for name, v, hi in (("amplitude_rad", amplitude_rad, MAX_AMPLITUDE_RAD), ("freq_hz", freq_hz, RESPONSE_FREQ_HZ[1])):
        try:
            arr = np.atleast_2d(np.asarray(v, float))
        except (TypeError, ValueError):
            raise InputError(SRC, name, "rows of (pitch, yaw) numbers", got=repr(v)[:60]) from None
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
            raise InputError(SRC, name, "rows of (pitch, yaw) values, shape (n, 2)", got=f"shape {arr.shape}")
        bad = ~(np.isfinite(arr) & (arr >= 0) & (arr <= hi))
        if bad.any():
            raise InputError(SRC, name, f"finite values from 0 to {hi:g}", got=f"{arr[bad][0]:g}")
        check_grid(arr[:, i], name, "rad" if name == "amplitude_rad" else "Hz", 0.0, hi, source=SRC)
        out.append(arr)
    if out[0].shape != out[1].shape:
        raise InputError(SRC, "freq_hz", f"as many rows as amplitude_rad ({out[0].shape[0]})",
                         got=str(out[1].shape[0]))
    return out[0], out[1]


AXES_INDEX = {"pitch": 0, "yaw": 1}


def check_samples(cmd, dt_s, record_every) -> np.ndarray:
    """Command samples (n + 1, 2) [rad], at least two rows, finite and within 90 deg; a
    positive step within the job limits; a whole record interval of at least 1."""
    try:
        c = np.asarray(cmd, float)
    except (TypeError, ValueError):
        raise InputError(SRC, "cmd", "samples (n + 1, 2) of (pitch, yaw) commands in rad", got=repr(cmd)[:60]) from None
    if c.ndim != 2 or c.shape[1] != 2 or c.shape[0] < 2:
        raise InputError(SRC, "cmd", "samples (n + 1, 2) of (pitch, yaw) commands, at least two rows",
                         got=f"shape {c.shape}")
    bad = ~(np.isfinite(c) & (np.abs(c) <= MAX_AMPLITUDE_RAD))
    if bad.any():
        raise InputError(SRC, "cmd", "finite commands within 90 deg", got=f"{c[bad][0]:g} rad")
    check_step(dt_s, "dt_s", duration_s=(c.shape[0] - 1) * float(dt_s) if _positive(dt_s) else None)
    check_count(record_every, "record_every", 1)
    return c


def _positive(x) -> bool:
    try:
        return math.isfinite(float(x)) and float(x) > 0
    except (TypeError, ValueError):
        return False


def check_simulate_args(profile, dt_s, record_every, duration_s) -> None:
    """:func:`taos.taos3d.simulate_taos`: a positive step, a whole record interval, a run of at
    most 1e4 s (the profile's, or ``duration_s``) within the job limits."""
    from ..bounds import check_profile

    check_profile(profile)
    T = getattr(profile, "duration_s", None)
    if duration_s is not None:
        if isinstance(duration_s, bool) or not isinstance(duration_s, (int, float)) or not 0 < duration_s <= MAX_DURATION_S:
            raise InputError(SRC, "duration_s", f"None or a duration above 0 and at most {MAX_DURATION_S:g} s",
                             got=repr(duration_s)[:40])
        T = duration_s
    elif not (isinstance(T, (int, float)) and math.isfinite(T) and 0 <= T <= MAX_DURATION_S):
        raise InputError(SRC, "profile", f"a profile of at most {MAX_DURATION_S:g} s", got=repr(T)[:40])
    else:
        T = T + 1.0
    check_step(dt_s, "dt_s", duration_s=T if _positive(dt_s) else None)
    check_count(record_every, "record_every", 1)
