"""taos: thrust-vector-control gimbal and actuator simulation.

The public API, by task (each name is importable from ``taos``)::

    model = taos.load_model("rs25_hotfire")               # a model file, or a shipped name
    taos.linear_freqresp(model, [0.5, 5.0])                # exact linear response
    taos.sine_dwell_freqresp(model, [0.5, 5.0], 0.4 * pi / 180)   # with friction and avionics
    taos.simulate(model, taos.load_profile("greenrun_two_axis"))  # a time history
    taos.describing_function_map(model, amplitudes_rad, freq_hz)  # N(A, w)
    taos.analyse_lco(taos.load_flight("core_stage"), model)       # limit-cycle prediction
    study = taos.fly_ascent(taos.load_ascent("ascent"), [tvc], reference=tvc_no_friction)
    study.runs, study.summary()                            # one flown ascent per TVC, their windows
    taos.fit_frequency_response(model, responses, ["load_stiffness"])
    taos.compare_models(model_a, model_b)
    planar = taos.reduce_to_planar("rs25_hotfire").model   # the 3-D model's planar-equivalent friction
    taos.write_html(run, "run.html")                       # offline 3-D view
    res = taos.greenrun(model, out="out/greenrun")         # the Green Run report (GreenRunResult)
    res.summary()["figures_of_merit"]                      # its numbers (summary.json)
    taos.model_summary(model, steps=False)                 # what `taos info --json` prints

Layers, bottom to top (none imports a layer above it; ``tests/test_architecture.py`` checks):

1. ``units``, ``errors``, ``results``, ``shipped``, ``bounds``, ``harmonics``, ``descfcn`` - units, one-line
   input errors, output files, the documented bounds of every input, sine fits, describing functions;
   and ``cosim._ccode`` (with ``_ccode_func``, ``_ccode_stmt``), the kernels' Python-to-C
   translator, which imports nothing of taos (the FMUs and the C dwells of ``planar._cdwell``
   use it);
2. ``friction``, ``linear``, ``stability``, ``model`` and the component models
   ``planar.actuator``, ``planar.avionics``, ``planar.saturation`` (its packing ``planar._limits_pack``);
3. the engines: ``planar`` (the simplex model, its kernels, simulation, frequency response,
   steady state, run envelope) and ``taos3d`` (3-D), with ``fem``, ``profiles``,
   ``engine_geometry``;
4. ``flight``, ``identify``, ``report`` (figures of merit, spec masks, summaries), ``montecarlo``,
   ``interop``, ``cosim`` - analyses built on them, and the models leaving for other tools (linear
   models and responses; the nonlinear TVC as a co-simulation block and FMU);
5. ``plotting``, ``viewer`` - drawing only; ``report.analysis`` and ``report.html`` - the Green Run
   report, whose folder holds its drawn page;
6. ``cli`` - the ``taos`` command: argument parsing over the layers below; ``masv`` sits on all
   of these, and ``cli.warmup`` (the kernel warm-up of ``make``, imported by nothing) on masv too,
   since it compiles both packages' kernels.

Names are resolved on first use (PEP 562), so ``import taos`` stays cheap and a command imports
only what it needs.
"""

from __future__ import annotations

import sys as _sys


def _startup_signals() -> None:
    """Ctrl-C / SIGTERM while a ``taos`` or ``masv`` command starts (imports, before
    :func:`taos.errors.run_cli` takes over): one line and exit 130 / 143, nothing written yet.
    Installed here, the first code of the package to run, and only for a command line (``taos``,
    ``masv``, ``python -m taos``), never for a program importing the library."""
    import os
    import signal

    prog = os.path.basename(_sys.argv[0]) if _sys.argv and _sys.argv[0] not in ("-m", "") else "taos"

    def stop(signum, frame):  # pragma: no cover - exercised in subprocesses (tests/test_hostile_fuzz.py)
        what = "interrupted (Ctrl-C)" if signum == signal.SIGINT else f"terminated (signal {signum})"
        os.write(2, f"{prog}: {what} during start-up; nothing written\n".encode())
        os._exit(128 + signum)

    for s in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(s) in (signal.default_int_handler, signal.SIG_DFL):
            signal.signal(s, stop)


if _sys.argv[:1] == ["-m"] or (_sys.argv[:1] and _sys.argv[0].rsplit("/", 1)[-1] in ("taos", "masv")):
    _startup_signals()

import importlib  # noqa: E402

__version__ = "0.1.0"

#: public name -> module that defines it
_API = {
    "load_model": "taos.model", "TvcModel": "taos.model",
    "InputError": "taos.errors", "SimulationUnstable": "taos.errors",
    "linear_freqresp": "taos.planar.freqresp", "sine_dwell_freqresp": "taos.planar.freqresp",
    "sine_dwell_grid": "taos.planar.freqresp", "FrequencyResponse": "taos.planar.freqresp",
    "simplex_state_space": "taos.planar.simplex", "load_resonance_from_notch": "taos.planar.simplex",
    "simulate": "taos.planar.simulate", "TimeHistory": "taos.planar.simulate",
    "load_profile": "taos.profiles",
    "FrictionLaw": "taos.friction", "LAWS": "taos.friction",
    "taos_model": "taos.taos3d", "simulate_taos": "taos.taos3d", "taos_freqresp": "taos.taos3d", "taos_freqresp_family": "taos.taos3d",
    "describing_function_map": "taos.flight.describing", "DescribingFunctionMap": "taos.flight.describing",
    "load_flight": "taos.flight.vehicle", "margins": "taos.flight.vehicle",
    "analyse_lco": "taos.flight.lco", "predict_lco": "taos.flight.lco",
    "load_test_data": "taos.identify.data", "estimate": "taos.identify.estimation",
    "fit_frequency_response": "taos.identify.fit", "compare_models": "taos.identify.compare",
    "reduce_to_planar": "taos.identify.reduce",
    "load_ascent": "taos.flight.ascent", "simulate_ascent": "taos.flight.ascent_sim",
    "fly_ascent": "taos.flight.ascent_sim", "AscentStudy": "taos.flight.ascent_sim",
    "load_campaign": "taos.montecarlo", "run_campaign": "taos.montecarlo",
    "load_run": "taos.viewer", "write_html": "taos.viewer", "serve": "taos.viewer",
    "loop_margins": "taos.stability", "LoopMargins": "taos.stability",
    "to_control": "taos.interop", "from_control_ss": "taos.interop",
    "greenrun": "taos.report.analysis", "GreenRunResult": "taos.report.analysis",
    "model_summary": "taos.report.summary",
}

__all__ = sorted(_API) + ["__version__"]


def lazy_api(package: str, table: dict[str, str], namespace: dict):
    """The PEP 562 ``__getattr__`` and ``__dir__`` of a package whose public names live in its
    submodules: ``table`` maps each name to its module (absolute, or relative to ``package``); a
    name is imported on first use and cached in the package's ``namespace``; ``dir()`` lists the
    package's ``__all__``. Used by ``taos`` and its subpackages alike."""

    def __getattr__(name: str):
        try:
            module = table[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(module, package), name)
        namespace[name] = value
        return value

    def __dir__():
        return sorted(namespace.get("__all__", table))

    return __getattr__, __dir__


__getattr__, __dir__ = lazy_api(__name__, _API, globals())
