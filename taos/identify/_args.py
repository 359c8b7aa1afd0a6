"""The public identification API's arguments (:func:`taos.fit_frequency_response`,
:func:`taos.reduce_to_planar`), checked as the command line checks ``taos fit`` and
``taos reduce`` (issue 40): every bad value raises :class:`~taos.errors.InputError` naming the
argument, before any problem is built or any dwell run."""

from __future__ import annotations

from taos.bounds import MAX_STARTS, check_count, check_flag, check_instance, check_number
from taos.errors import InputError, as_argument, check_path_arg


def check_fit_args(model, data, free, *, start, starts, seed, use_engine, min_coherence, sigma_floor, correct,
                   max_corrections, correction_tol, absolute_sigma, bounds, global_stage) -> None:
    """:func:`taos.fit_frequency_response`: a model, a non-empty list of measured responses, a
    list of free parameter names the model's law has (``--free``), start and bound tables or
    None, whole numbers of starts (1 to :data:`taos.bounds.MAX_STARTS`) and corrections, a
    seed, a coherence threshold from 0 to 1 (``--min-coherence``), positive tolerances, flags."""
    from taos.identify.estimation import MeasuredResponse
    from taos.identify.surrogate import check_free
    from taos.model import TvcModel

    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    if not isinstance(data, (list, tuple)) or not data or not all(isinstance(r, MeasuredResponse) for r in data):
        raise InputError("argument", "data", "a non-empty list of MeasuredResponse (taos.estimate)", got=repr(data)[:40])
    if not isinstance(free, (list, tuple)) or not all(isinstance(n, str) for n in free):
        raise InputError("argument", "free", "a list of parameter names (text)", got=repr(free)[:40])
    try:
        check_free(model, free)
    except InputError as e:
        raise as_argument(e, "free", "--free") from None
    for name, v in (("start", start), ("bounds", bounds)):
        if v is not None and not isinstance(v, dict):
            raise InputError("argument", name, "None or a table name -> SI value(s)", got=repr(v)[:40])
    check_count(starts, "starts", 1, MAX_STARTS)
    check_count(seed, "seed", 0, 2 ** 63 - 1)
    check_number(min_coherence, "min_coherence", 0.0, 1.0)
    check_number(sigma_floor, "sigma_floor", 0.0, 1.0, lo_open=True)
    check_count(max_corrections, "max_corrections", 0, 100)
    check_number(correction_tol, "correction_tol", 0.0, 1.0, lo_open=True)
    for name, v in (("use_engine", use_engine), ("absolute_sigma", absolute_sigma), ("global_stage", global_stage)):
        check_flag(v, name)
    if correct is not None:
        check_flag(correct, "correct")


def check_reduce_source(source) -> None:
    """:func:`taos.reduce_to_planar`'s ``source``: a TaosModel, a TvcModel or a model file's name."""
    from taos.model import TvcModel
    from taos.taos3d.model import TaosModel

    if not isinstance(source, (TaosModel, TvcModel)):
        check_path_arg(source, "source", "a TaosModel, a TvcModel or a model file (with [gimbal] and [geometry])")
