"""The public flight API's arguments (:func:`taos.predict_lco`, :func:`taos.analyse_lco`,
:func:`taos.simulate_ascent`, :func:`taos.fly_ascent`), checked as the command line checks
them (issue 40): every bad value raises :class:`~taos.errors.InputError` naming the argument,
before any work, so the API never answers an absurd input with NaN, another exception or
unbounded work. Limits: :mod:`taos.bounds` and the ``taos lco`` / ``taos montecarlo ascent``
flags (an RK4 step from 1e-5 to 2e-3 s, 0 <= start < end <= the trajectory's end)."""

from __future__ import annotations

import math

from taos.bounds import (MAX_CYCLES, MAX_DURATION_S, check_axis, check_choice, check_count, check_flag, check_grid,
                         check_instance, check_number)
from taos.errors import InputError

#: the harmonic-balance search grid of :func:`taos.predict_lco`: n_grid x n_grid describing-function
#: evaluations (the default 160 resolves every crossing of the shipped maps; 2000 is 4e6 evaluations)
N_GRID = (4, 2000)
#: rows an LCO map may be extended by per edge (``extend``; each row is a row of dwells)
MAX_EXTEND = 16
#: the ascent's RK4 step [s], as ``taos montecarlo ascent --dt`` (taos.bounds.CAMPAIGN_BOUNDS "dt")
ASCENT_DT_S = (1e-5, 2e-3)
AVIONICS = ("bounding", "model")
STEADY = ("settle", "shoot")


def _flight(flight) -> None:
    from .vehicle import FlightModel

    check_instance(flight, "flight", FlightModel, "a FlightModel (taos.load_flight)")


def _model(model, field: str = "model") -> None:
    from taos.model import TvcModel

    check_instance(model, field, TvcModel, "a TvcModel (taos.load_model)")


def _df(df, optional: bool = False) -> None:
    from .describing import DescribingFunctionMap

    if not (optional and df is None):
        check_instance(df, "df", DescribingFunctionMap, ("None or " if optional else "")
                       + "a DescribingFunctionMap (taos.describing_function_map)")


def check_predict_args(flight, df, axis, n_grid) -> None:
    """:func:`taos.predict_lco`: a flight, a map, None or an axis, a grid of :data:`N_GRID` points."""
    _flight(flight)
    _df(df)
    if axis is not None:
        check_axis(axis)
    check_count(n_grid, "n_grid", *N_GRID)


def check_lco_args(flight, model, *, axis, amplitudes_rad, freq_hz, duration_s, window_s, attitude0_rad,
                   settle_cycles, measure_cycles, avionics, time_domain, steady, df, extend) -> None:
    """:func:`taos.analyse_lco`: every argument, before the map, the prediction or the run."""
    _flight(flight)
    _model(model)
    if axis is not None:
        check_axis(axis)
    if amplitudes_rad is not None:
        check_grid(amplitudes_rad, "amplitudes_rad", "rad", 0.0, math.pi / 2)
    if freq_hz is not None:
        check_grid(freq_hz, "freq_hz", "Hz", 0.0, 1e4)
    check_number(duration_s, "duration_s", 0.0, MAX_DURATION_S, "s", lo_open=True)
    check_number(window_s, "window_s", 0.0, MAX_DURATION_S, "s (beyond duration_s: the whole run)", lo_open=True)
    check_number(attitude0_rad, "attitude0_rad", -math.pi / 2, math.pi / 2, "rad")
    check_count(settle_cycles, "settle_cycles", 0, MAX_CYCLES)
    check_count(measure_cycles, "measure_cycles", 1, MAX_CYCLES)
    check_choice(avionics, "avionics", AVIONICS)
    check_flag(time_domain, "time_domain")
    check_choice(steady, "steady", STEADY)
    _df(df, optional=True)
    check_count(extend, "extend", 0, MAX_EXTEND)


def _ascent_window(ascent, start_s, end_s, dt_s) -> float:
    """The flown segment's end [s], checked: 0 <= start < end <= the trajectory's end, a step
    of :data:`ASCENT_DT_S`."""
    from .ascent import Ascent

    check_instance(ascent, "ascent", Ascent, "an Ascent (taos.load_ascent)")
    T = float(ascent.end_time_s)
    start = check_number(start_s, "start_s", 0.0, T, "s (within the trajectory)")
    end = T if end_s is None else check_number(end_s, "end_s", start, T, "s (after start_s, within the trajectory)",
                                               lo_open=True)
    if start >= end:
        raise InputError("argument", "start_s", f"a start before the trajectory's end ({T:g} s)", got=f"{start:g} s")
    check_number(dt_s, "dt_s", *ASCENT_DT_S, "s")
    return end


def _axes(axes) -> None:
    if not isinstance(axes, (tuple, list)) or not axes or len(set(map(repr, axes))) != len(axes):
        raise InputError("argument", "axes", "a non-empty tuple of distinct axes ('pitch', 'yaw')", got=repr(axes)[:40])
    for a in axes:
        check_axis(a, "axes")


def check_ascent_args(ascent, model, *, axes, start_s, end_s, dt_s, record_interval_s, seed, attitude0_rad,
                      progress, friction_follows_thrust) -> None:
    """:func:`taos.simulate_ascent`: every argument, before the trajectory is sampled."""
    _ascent_window(ascent, start_s, end_s, dt_s)
    _model(model)
    _axes(axes)
    check_number(record_interval_s, "record_interval_s", 0.0, MAX_DURATION_S, "s", lo_open=True)
    check_count(seed, "seed", 0, 2 ** 63 - 1)
    check_number(attitude0_rad, "attitude0_rad", -math.pi / 2, math.pi / 2, "rad")
    check_flag(progress, "progress")
    check_flag(friction_follows_thrust, "friction_follows_thrust")


def check_fly_args(ascent, models, *, reference, avionics, axes, start_s, end_s, dt_s, seed, progress,
                   friction_follows_thrust) -> None:
    """:func:`taos.fly_ascent`: every argument, before the first run."""
    _ascent_window(ascent, start_s, end_s, dt_s)
    if not isinstance(models, (list, tuple)) or not models:
        raise InputError("argument", "models", "a non-empty list of TvcModel (taos.load_model)", got=repr(models)[:40])
    for m in models:
        _model(m, "models")
    _model(reference, "reference")
    check_choice(avionics, "avionics", AVIONICS)
    _axes(axes)
    check_count(seed, "seed", 0, 2 ** 63 - 1)
    check_flag(progress, "progress")
    check_flag(friction_follows_thrust, "friction_follows_thrust")
