"""The planar kernels compile one specialisation each (issue 44 point 1: the cold start).

numba types a constant argument of a call between compiled functions as a literal
(``Literal[int](0)``, ``Literal[bool](True)``) and compiles the callee once per literal value: a
settle call with ``False`` and a measure call with ``True`` made two full copies of
``sine_steps`` (8 s of compile each on a quiet machine). The callers pass run-time values
(``int(0)``, ``bool(True)``), so every planar kernel has one signature for the model's types,
shared by the simulation, the dwells, the shooting and the verdict map's confirmation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba.core import types
from numba.core.dispatcher import Dispatcher

from taos.model import load_model

PLANAR_KERNEL_MODULES = ("dynamics", "_expstep", "_exptime", "_expplan", "saturation", "steady",
                         "_avionics_kernels")


def _run_all(model) -> None:
    from taos.flight.lco_confirm import compile_kernel
    from taos.planar.freqresp import sine_dwell_grid
    from taos.planar.simulate import simulate
    from taos.profiles import SineDwell

    for integ in ("rk4", "exp"):
        simulate(model, SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01, integrator=integ)
    import os

    before = os.environ.get("TAOS_KERNELS")
    os.environ["TAOS_KERNELS"] = "numba"   # numba's dwell kernels, not their C translation (taos.planar._cdwell)
    try:
        for kw in ({}, {"integrator": "rk4"}, {"method": "shoot", "max_cycles": 1}):
            sine_dwell_grid(model, [math.radians(0.4)], [10.0], settle_s=0.0, settle_cycles=1, measure_cycles=1, **kw)
    finally:
        if before is None:
            os.environ.pop("TAOS_KERNELS")
        else:
            os.environ["TAOS_KERNELS"] = before
    compile_kernel(model)


def _signatures(d) -> list:
    """The signatures of kernel ``d`` compiled in this process or saved in its on-disk cache for
    its current source (a kernel called only from other cached kernels is not loaded itself
    when they come from the cache: its cache index still lists what was compiled; the index
    keys are (signature, machine, code hashes), ``numba.core.caching``)."""
    sigs = list(d.signatures)
    cache = getattr(d, "_cache", None)
    try:
        index = cache._cache_file._load_index() if cache is not None else {}
    except (AttributeError, OSError):
        index = {}
    return sigs + [k[0] for k in index if k[0] not in sigs]


def _kernels():
    import importlib

    for name in PLANAR_KERNEL_MODULES:
        mod = importlib.import_module(f"taos.planar.{name}")
        for attr, obj in vars(mod).items():
            if isinstance(obj, Dispatcher) and obj.py_func.__module__ == mod.__name__:
                yield f"{name}.{attr}", obj


@pytest.fixture(scope="module")
def ran():
    _run_all(load_model("rs25_hotfire"))


def test_no_literal_specialisation(ran):
    """No planar kernel was compiled for a literal argument value."""
    bad = [(name, sig) for name, d in _kernels() for sig in _signatures(d)
           if any(isinstance(a, types.Literal) for a in sig)]
    assert not bad, f"kernels specialised on a literal argument: {bad}"


@pytest.mark.parametrize("name", ["dynamics.integrate_samples", "dynamics._rk4_step", "dynamics.sine_steps",
                                  "_expstep.sine_steps_exp", "_expstep.etdrk4_step", "saturation.apply",
                                  "_avionics_kernels.apply"])
def test_one_signature_for_every_caller(ran, name):
    """The simulation, the dwells (RK4 and ETDRK4), the shooting and the confirmation share one
    compiled specialisation of each step kernel."""
    d = dict(_kernels())[name]
    sigs = [s for s in _signatures(d) if all(not isinstance(a, types.Array) or a.dtype == types.float64 for a in s
                                           if isinstance(a, types.Array))]
    assert len(sigs) == 1, f"{name}: {len(sigs)} specialisations {sigs}"
    assert np.all([a.layout == "C" for a in sigs[0] if isinstance(a, types.Array)])


def test_shooting_extrapolation_solve_is_lapack_gelsd():
    """The shooting's reduced-rank-extrapolation solve (``steady._lstsq_ones``, numba's LAPACK
    ``dgelsd`` driver called directly instead of through ``np.linalg.lstsq`` and its checks) gives
    the bits of scipy's ``gelsd`` least squares (the same LAPACK routine, the same rcond) on
    ill-conditioned Gram matrices like the extrapolation's."""
    import scipy.linalg as sl

    from taos.planar.steady import _lstsq_ones

    rng = np.random.default_rng(1)
    for q in range(1, 7):
        for _ in range(10):
            V = rng.standard_normal((q, 9)) * 10.0 ** rng.uniform(-12, 0, (q, 1))
            M = V @ V.T
            M += 1e-15 * np.trace(M) * np.eye(q)
            ref = sl.lstsq(M, np.ones(q), cond=-1, lapack_driver="gelsd", check_finite=False)[0]
            assert np.array_equal(_lstsq_ones(M), ref)
