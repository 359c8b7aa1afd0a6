"""The Green Run analysis (:func:`greenrun`), the project's main product as a library call.

Runs a two-axis profile (default ``models/profiles/greenrun_two_axis.toml``: pitch and yaw
commanded at the same time at different frequencies, 0.4 deg up to 7 Hz and 0.8 deg up to 14 Hz,
paper sec. 3.2) through an engine model (the planar simplex model,
:func:`taos.planar.simulate.simulate`, or the 3-D model, :func:`taos.taos3d.simulate_taos`) and
computes per axis:

* the exact linear response on a log grid 0.1-30 Hz (:func:`taos.planar.freqresp.linear_freqresp`;
  3-D: :func:`taos.taos3d.taos_freqresp`), its piston notch
  (:func:`taos.planar.simplex.load_resonance_from_notch`; 3-D: the minimum of the 3-D piston gain)
  and the load resonance w_L = sqrt((K_L R^2 + K_n) / J_n) (paper eq. 1);
* sine-dwell responses at the profile's amplitudes and frequencies
  (:func:`taos.planar.freqresp.sine_dwell_grid`);
* the response read off the two-axis run itself, as the test was analysed: for each dwell
  segment of the profile a least-squares fit y = a sin(w t') + b cos(w t') + c over its last
  two whole cycles (:func:`taos.harmonics.fit_sines`), H = (a + j b) / A (piston as
  x_p / (R theta_c));
* the figures of merit and the model's derived figures (:func:`taos.report.summary.model_summary`),
  the spec-mask check of the linear response (:mod:`taos.report.spec`) and, given a measured
  record, its estimated responses (:func:`taos.identify.estimation.estimate`);
* the mask on every basis (linear, nonlinear dwell, measured, step) with the cause of each
  failing point, and the verdict in words (:mod:`taos.report.verdict`), on the engine that ran
  (3-D: its own dwells with the profile's cross-axis dither, its causes by 3-D re-runs).

The result, :class:`GreenRunResult`, holds all of it; ``.summary()`` is the ``summary.json``
dict and ``.write(DIR)`` writes the report folder: ``DIR/index.html`` (self-contained, drawn by
:mod:`taos.report.html`), ``DIR/summary.json`` and ``DIR/greenrun.h5`` (the run plus the
responses under ``/freqresp``). The folder is built in a temporary folder beside DIR and renamed
into place, so a failure leaves nothing half-written. This module computes and writes numbers;
it never draws (matplotlib is imported by :mod:`taos.report.html` only, when a page is made).
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Mapping

import numpy as np

from taos.errors import InputError
from taos.harmonics import fit_sines
from taos.profiles import Sequence, SineDwell, TwoAxis, dwell_segments  # noqa: F401 (re-exported)
from taos.shipped import models_dir

from .summary import greenrun_summary, model_summary

if TYPE_CHECKING:
    from taos.identify.estimation import MeasuredResponse
    from taos.model import TvcModel
    from taos.planar.freqresp import FrequencyResponse
    from taos.planar.simulate import TimeHistory
    from taos.identify.data import TestData
    from taos.profiles import Profile
    from taos.report.spec import SpecMask, SpecResult
    from taos.report.verdict import Verdict

DEFAULT_PROFILE = models_dir() / "profiles" / "greenrun_two_axis.toml"
DEFAULT_SPEC = models_dir() / "specs" / "tvc_actuator_notional.toml"
#: the report's own files (the folder receives only these, plus its mark ``.taos-output.json``)
OUTPUTS = ("index.html", "summary.json", "greenrun.h5")
AXES = ("pitch", "yaw")
#: a measured record given as the profile replays its commands (:func:`taos.profiles.profile_from_record`)
# the linear response's grid [Hz], 0.1-30 Hz
LINEAR_GRID_HZ = np.logspace(-1, math.log10(30.0), 240)


# -- the run's own responses -------------------------------------------------------------------

def run_dwell_response(t_s, command_amp_rad: float, freq_hz: float, t0_s: float, cycles: int, y,
                       fit_cycles: int = 2) -> complex:
    """Fundamental of ``y`` relative to A sin(w (t - t0)) over the segment's last whole cycles."""
    m = min(fit_cycles, max(1, cycles - 1))
    lo, hi = t0_s + (cycles - m) / freq_hz, t0_s + cycles / freq_hz
    sel = (t_s >= lo) & (t_s < hi)
    return complex(fit_sines(t_s[sel] - t0_s, y[sel], freq_hz).phasor[0, 0]) / command_amp_rad


def run_responses(th, profile, moment_arm_m: float) -> dict:
    """{axis: [FrequencyResponse per amplitude]} read off the two-axis run's dwell segments."""
    from taos.planar.freqresp import FrequencyResponse

    out = {}
    for k, ax in enumerate(th.axes):
        segs = dwell_segments(getattr(profile, ax)) if isinstance(profile, TwoAxis) else dwell_segments(profile)
        if not segs:
            continue
        rows = []
        for t0, s in segs:
            hp = run_dwell_response(th.t_s, s.amplitude_rad, s.frequency_hz, t0, s.cycles, th.piston_m[k]) / moment_arm_m
            he = run_dwell_response(th.t_s, s.amplitude_rad, s.frequency_hz, t0, s.cycles, th.engine_rad[k])
            rows.append((s.amplitude_rad, s.frequency_hz, hp, he))
        out[ax] = [FrequencyResponse(np.array([r[1] for r in rows if r[0] == a]),
                                     np.array([r[2] for r in rows if r[0] == a]),
                                     np.array([r[3] for r in rows if r[0] == a]), a, ax,
                                     friction_model=th.provenance.get("friction_model", "?"),
                                     provenance={"method": "two-axis run, dwell segments"})
                   for a in sorted({r[0] for r in rows})]
    return out


# -- the result --------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class GreenRunResult:
    """Everything the Green Run report shows (:func:`greenrun`). Responses are
    :class:`taos.planar.freqresp.FrequencyResponse` (piston x_p / (R theta_c), engine
    theta / theta_c, complex), per axis ``"pitch"`` / ``"yaw"``."""

    model: TvcModel
    #: the two-axis profile run, and the file it came from ("" for a profile object)
    profile: TwoAxis
    profile_file: str
    #: ``"simplex"`` or ``"taos"``, and its integration step [s]
    engine: str
    dt_s: float
    #: the two-axis run (``taos.planar.simulate.TimeHistory``; 3-D: ``TaosTimeHistory``), with its provenance
    time_history: TimeHistory
    #: exact linear response on a log grid 0.1-30 Hz (240 points)
    linear: Mapping[str, FrequencyResponse]
    #: sine-dwell responses, one per profile amplitude, at the profile's frequencies
    dwell: Mapping[str, tuple[FrequencyResponse, ...]]
    #: responses read off the run's dwell segments, one per amplitude (axes with dwells only)
    run: Mapping[str, tuple[FrequencyResponse, ...]]
    #: command -> piston notch [Hz] and load resonance w_L [Hz]
    notch_hz: Mapping[str, float]
    load_resonance_hz: Mapping[str, float]
    #: :func:`taos.report.summary.model_summary` of the model (``taos info --steps``), figures of merit included
    model_info: dict
    #: spec-mask verdict per axis (empty when no mask was checked)
    spec: Mapping[str, SpecResult] = field(default_factory=dict)
    #: a measured record's estimated responses per axis (None when none was given)
    measured: Mapping[str, MeasuredResponse] | None = None
    #: the mask on every basis (linear, dwell, measured, step) with each shortfall's cause
    #: (:func:`taos.report.verdict.spec_verdict`; None when no mask was checked)
    verdict: Verdict | None = None
    #: when the analysis finished (UTC, ISO 8601)
    created_utc: str = ""

    @property
    def figures_of_merit(self) -> dict:
        """Per axis: frequency, step, threshold and hysteresis figures (:mod:`taos.report.merit`)."""
        return self.model_info["figures_of_merit"]

    @property
    def spec_verdict_text(self) -> str | None:
        """In words, why the model fails (or passes) its mask (:meth:`taos.report.verdict.Verdict.text`)."""
        return None if self.verdict is None else self.verdict.text()

    @property
    def spec_pass(self) -> bool | None:
        """All axes' LINEAR responses within the spec mask (None when no mask was checked); the
        verdict on every basis is ``verdict.passed``."""
        return all(r.passed for r in self.spec.values()) if self.spec else None

    def dwell_grid(self, axis: str) -> dict:
        """The sine-dwell responses of ``axis`` as arrays: ``freq_hz`` (n_f), ``amplitude_rad``
        (n_a), ``piston`` and ``engine`` (n_a x n_f, complex)."""
        frs = self.dwell[axis]
        if not frs:
            return {"freq_hz": np.zeros(0), "amplitude_rad": np.zeros(0),
                    "piston": np.zeros((0, 0), complex), "engine": np.zeros((0, 0), complex)}
        return {"freq_hz": np.asarray(frs[0].freq_hz), "amplitude_rad": np.array([f.amplitude_rad for f in frs]),
                "piston": np.array([f.piston for f in frs]), "engine": np.array([f.engine for f in frs])}

    def summary(self) -> dict:
        """The ``summary.json`` dict (:func:`taos.report.summary.greenrun_summary`)."""
        return greenrun_summary(self)

    def write(self, out_dir, *, view_angle_scale: float = 5.0, view_fps: float = 100.0, progress=None) -> Path:
        """Write the report folder ``out_dir`` (``index.html``, ``summary.json``, ``greenrun.h5``),
        replacing it as a whole once the new one is complete; returns its path.

        ``view_angle_scale``: engine-angle exaggeration of the embedded 3-D view [-];
        ``view_fps``: its keyframe rate [1/s], lowered so that the view holds at most
        :data:`taos.report.html.MAX_VIEW_FRAMES` keyframes. ``progress``: a tqdm bar advanced
        once per step (plots, 3-D view, write), or None. An output place that cannot be written
        is bad input (:class:`~taos.errors.InputError`); the previous folder is then untouched."""
        from taos.results import check_output_folder, write_output_folder

        from .html import render_html

        out = Path(out_dir)
        check_output_folder(out, OUTPUTS)
        summary = self.summary()
        page = render_html(self, summary, view_angle_scale=view_angle_scale, view_fps=view_fps, progress=progress)
        text = json.dumps(summary, indent=2, allow_nan=False) + "\n"
        write_output_folder(out, {
            "index.html": lambda p: p.write_text(page, encoding="utf-8"),
            "summary.json": lambda p: p.write_text(text),
            "greenrun.h5": lambda p: _write_h5(p, self),
        })
        if progress is not None:
            progress.update()
        return out


def _write_h5(path: Path, r: GreenRunResult) -> None:
    """The run (:meth:`TimeHistory.to_hdf5`) plus ``/freqresp/{axis}/linear``, ``sine_dwell`` and
    ``run_dwell/{amplitude}deg`` (complex responses)."""
    import h5py

    r.time_history.to_hdf5(path)
    with h5py.File(path, "a") as h5:
        g = h5.create_group("freqresp")
        g.attrs["piston_definition"] = "x_p / (R theta_c), complex"
        g.attrs["engine_definition"] = "theta / theta_c, complex"
        for ax, lin in r.linear.items():
            a = g.create_group(ax)
            a.create_dataset("linear/freq_hz", data=lin.freq_hz)
            a.create_dataset("linear/piston", data=lin.piston)
            a.create_dataset("linear/engine", data=lin.engine)
            d = r.dwell_grid(ax)
            a.create_dataset("sine_dwell/freq_hz", data=d["freq_hz"])
            a.create_dataset("sine_dwell/amplitude_rad", data=d["amplitude_rad"])
            a.create_dataset("sine_dwell/piston", data=d["piston"])
            a.create_dataset("sine_dwell/engine", data=d["engine"])
            for fr in r.run.get(ax, []):
                g2 = a.create_group(f"run_dwell/{math.degrees(fr.amplitude_rad):.3g}deg")
                g2.attrs["amplitude_rad"] = fr.amplitude_rad
                g2.create_dataset("freq_hz", data=fr.freq_hz)
                g2.create_dataset("piston", data=fr.piston)
                g2.create_dataset("engine", data=fr.engine)


# -- inputs ------------------------------------------------------------------------------------

def _profile_of(profile) -> tuple[TwoAxis, str, Path | None]:
    """(profile, its file as shown, its path for provenance) of a profile object, a profile
    file / shipped name, or a measured record whose commands are replayed."""
    from taos.identify.replay import load_command_source

    if profile is None:
        profile = DEFAULT_PROFILE
    if isinstance(profile, (str, Path)):
        path = Path(profile)
        prof = load_command_source(path)
        src = str(path)
    else:
        prof, src, path = profile, "", None
    if not isinstance(prof, TwoAxis):
        raise InputError(src or "(profile)", "(profile)", "a two-axis profile with [pitch] and [yaw] tables",
                         got=type(prof).__name__)
    return prof, src, path


def _spec_mask(spec) -> SpecMask | None:
    """The mask (a file or a :class:`taos.report.spec.SpecMask`; None if None)."""
    if spec is None:
        return None
    from .spec import SpecMask, load_spec

    return spec if isinstance(spec, SpecMask) else load_spec(spec)


def _spec_results(model, mask) -> dict:
    """{axis: SpecResult} of the model's linear response against ``mask`` (empty if None)."""
    if mask is None:
        return {}
    from .spec import check_spec

    return {ax: check_spec(model, mask, ax) for ax in AXES}


def _verdict(model, mask, prof, measured, info, dt_s, threads=None, engine="simplex", tm=None) -> Verdict | None:
    """The mask on every basis with causes (:func:`taos.report.verdict.spec_verdict`) on the
    engine that ran: dwells at the profile's amplitudes (3-D: with the other axis' dwell the
    profile commands meanwhile, :func:`taos.report.engines.concurrent_dwells`), the measured
    record, the planar step figures ``info`` already holds (simplex; the 3-D engine runs its own)."""
    if mask is None:
        return None
    from .engines import concurrent_dwells
    from .verdict import spec_verdict

    if engine == "taos":
        segs = concurrent_dwells(prof)
    else:
        segs = {ax: [(s.frequency_hz, s.amplitude_rad) for _, s in dwell_segments(getattr(prof, ax))] for ax in AXES}
    steps = {ax: m["step"] for ax, m in info["figures_of_merit"].items() if "step" in m}
    return spec_verdict(model, mask, segments=segs, measured=measured, step_figures=steps, dt_s=dt_s, threads=threads,
                        engine=engine, taos_model=tm)


def _measured_responses(data) -> dict:
    """{axis: MeasuredResponse} estimated from a measured record (a file or a
    :class:`taos.identify.data.TestData`; estimator chosen and explained by
    :func:`taos.identify.estimation.estimate`)."""
    from taos.identify.data import load_test_data
    from taos.identify.estimation import estimate

    if isinstance(data, (str, Path)):
        data = load_test_data(data)
    return {r.axis: r for r in estimate(data)}


# -- the analysis ------------------------------------------------------------------------------

def _check_args(model, out, allow_unstable, progress, view_angle_scale, view_fps, threads) -> None:
    """:func:`greenrun`'s arguments, each refused naming it as the command line refuses its flag:
    a model (or a model file's name), an output folder place (checked before any work), flags
    True or False, the 3-D view's scales (:func:`taos.viewer.check_view_args`), a thread count."""
    from taos.bounds import check_flag, check_number
    from taos.errors import as_argument, check_path_arg
    from taos.model import TvcModel
    from taos.planar._parallel import thread_count
    from taos.results import check_output_folder
    from taos.bounds import MAX_VIEW_FPS, MAX_VIEW_SCALE

    if not isinstance(model, TvcModel):
        check_path_arg(model, "model", "a TvcModel, a model file or a shipped model's name")
    if out is not None:
        try:
            check_output_folder(Path(check_path_arg(out, "out", "a report folder")), OUTPUTS)
        except InputError as e:
            raise as_argument(e, "out", "--out") from None
    check_flag(allow_unstable, "allow_unstable")
    check_flag(progress, "progress")
    check_number(view_angle_scale, "view_angle_scale", 0.0, MAX_VIEW_SCALE, lo_open=True)
    check_number(view_fps, "view_fps", 0.0, MAX_VIEW_FPS, "1/s", lo_open=True)
    if threads is not None:
        thread_count(threads)


def greenrun(model: TvcModel | str | Path, profile: Profile | str | Path | None = None, *,
             engine: str = "simplex", friction: str | None = None, out: str | Path | None = None,
             dt_s: float | None = None, spec: SpecMask | str | Path | None = DEFAULT_SPEC,
             data: TestData | str | Path | None = None, allow_unstable: bool = False,
             progress: bool = False, view_angle_scale: float = 5.0, view_fps: float = 100.0,
             threads: int | None = None) -> GreenRunResult:
    """The Green Run analysis of ``model`` (see the module docstring); with ``out``, also the
    report folder (:meth:`GreenRunResult.write`).

    Raises :class:`~taos.errors.InputError` on bad input (before any work starts; nothing
    written), and :class:`~taos.errors.SimulationUnstable` when the model is unstable or the run
    leaves its physical envelope.

    Parameters
    ----------
    model : TvcModel, str or Path
        A model, a model file (TOML) or a shipped model's name (``"rs25_hotfire"``).
    profile : TwoAxis, str or Path, optional
        A two-axis profile object, a profile file or shipped name, or a measured record
        (``.csv``/``.h5``) whose commands are replayed; default the notional Green Run profile
        (:data:`DEFAULT_PROFILE`).
    engine : str
        ``"simplex"`` (planar, one model per axis) or ``"taos"`` (3-D: both axes on one engine,
        FEM two-half gimbal, spherical-bearing friction; :mod:`taos.taos3d`).
    friction : str, optional
        Swap the model's friction law (keeping its torque levels).
    out : str or Path, optional
        Report folder to write (replaced as a whole when the new one is complete); checked
        before any work starts.
    dt_s : float, optional
        Integration step [s]; default the engine's own (:func:`taos.planar.envelope.default_dt_s`).
    spec : str, Path or SpecMask, optional
        Spec mask (:mod:`taos.report.spec`), checked on the linear response, the nonlinear sine
        dwells at the profile's amplitudes, the measured record (with ``data``) and the step
        figures, each failing point with its cause (:mod:`taos.report.verdict`); default
        ``models/specs/tvc_actuator_notional.toml``; None: no check.
    data : str, Path or TestData, optional
        A measured record (e.g. ``models/data/greenrun_hotfire_synthetic.csv``): its estimated
        responses are set beside the model's.
    allow_unstable : bool
        Run a model whose linear block is unstable (else refused, :class:`~taos.errors.UnstableModel`)
        and skip the envelope check.
    progress : bool
        tqdm progress bar on standard error.
    view_angle_scale, view_fps : float
        The embedded 3-D view's angle exaggeration [-] and keyframe rate [1/s] (with ``out``).
    threads : int, optional
        Threads for the independent runs (the model's step figures beside the two-axis run, the
        run's axes, the step figures' runs; :mod:`taos.planar._parallel`); default numba's
        thread count (``NUMBA_NUM_THREADS``, default the number of cores); 1: one after the
        other. The results are the same bits on any count.
    """
    from tqdm import tqdm

    from taos.linear import notch_hz
    from taos.model import TvcModel, load_model
    from taos.planar import envelope as run_checks
    from taos.planar._parallel import run_tasks, thread_count
    from taos.results import check_output_folder, input_provenance

    # bad input fails here, before any progress output: one line, nothing written
    _check_args(model, out, allow_unstable, progress, view_angle_scale, view_fps, threads)
    if out is not None:
        check_output_folder(Path(out), OUTPUTS)
    if isinstance(model, TvcModel):
        model = model.with_friction(friction) if friction is not None else model
    else:
        model = load_model(model, friction=friction)
    if engine not in run_checks.ENGINES:
        raise InputError("command line", "--engine", " or ".join(run_checks.ENGINES), got=repr(engine))
    tm = None
    if engine == "taos":   # every 3-D input check before any work; one model object, one friction
        from taos.taos3d import taos_model
        tm = taos_model(model)
    prof, profile_file, ppath = _profile_of(profile)
    if dt_s is None:
        dt_s = run_checks.default_dt_s(engine)
    run_checks.check_run(model, prof, dt_s, pressure_limit=engine != "taos")
    run_checks.check_linear_stability(model, allow=allow_unstable)
    mask = _spec_mask(spec)
    specs = _spec_results(model, mask)
    measured = _measured_responses(data) if data is not None else None
    threads = thread_count(threads)   # when None numba's count: numba imported once the inputs are good
    if engine == "taos":
        from taos.taos3d import simulate_taos, taos_freqresp
        from taos.taos3d.simulate import taos_freqresp_axes
        run_sim = lambda: simulate_taos(tm, prof, dt_s=dt_s)  # noqa: E731
        lin_fr = lambda f, ax: taos_freqresp(tm, f, None, ax)  # noqa: E731

        def dwell_fr_all(grids):   # every axis' dwells in one parallel call
            frs = taos_freqresp_axes(tm, {ax: (freqs, amps) for ax, (amps, freqs) in grids.items()})
            return {ax: (np.array([fr.piston for fr in f]), np.array([fr.engine for fr in f])) for ax, f in frs.items()}
    else:
        from taos.planar.freqresp import linear_freqresp, sine_dwell_grid
        from taos.planar.simulate import simulate
        run_sim = lambda: simulate(model, prof, dt_s=dt_s, threads=threads)  # noqa: E731
        lin_fr = lambda f, ax: linear_freqresp(model, f, ax)  # noqa: E731

        def dwell_fr_all(grids):   # one parallel call per axis
            return {ax: sine_dwell_grid(model, amps, freqs, ax, dt_max_s=dt_s) for ax, (amps, freqs) in grids.items()}
    from taos.planar.freqresp import FrequencyResponse
    from taos.planar.simplex import load_resonance_from_notch

    steps = ["simulate", "linear response", "sine dwell"] + (["plots", "3-D view", "write"] if out is not None else [])
    bar = tqdm(total=len(steps), desc="greenrun", unit="step", file=sys.stderr, disable=not progress)
    try:
        bar.set_postfix_str("simulate")
        # the model's figures (their step runs) beside the run: independent, on the threads
        info, th = run_tasks([lambda: model_summary(model, threads=threads), run_sim], threads)
        if not allow_unstable:
            run_checks.check_envelope(th, model)
        if ppath is not None:
            th.provenance.update(input_provenance(ppath, "profile", th.provenance))
        bar.update()

        bar.set_postfix_str("linear response")
        f_lin = LINEAR_GRID_HZ
        linear = {ax: lin_fr(f_lin, ax) for ax in AXES}
        if engine == "taos":  # the notch of the 3-D response, refined between the coarse grid's neighbours
            notch = {}
            for ax in AXES:
                k = int(np.argmin(np.abs(linear[ax].piston)))
                notch[ax] = notch_hz(lambda f, ax=ax: np.abs(lin_fr(f, ax).piston), f_lin[max(k - 1, 0)],
                                     f_lin[min(k + 1, f_lin.size - 1)], n_grid=21, xatol=1e-6)
        else:
            notch = {ax: load_resonance_from_notch(model, ax) for ax in AXES}
        wl = {ax: model.load_resonance_hz(ax) for ax in AXES}
        bar.update()

        bar.set_postfix_str("sine dwell")
        grids = {}
        for ax in AXES:
            segs = dwell_segments(getattr(prof, ax))
            if segs:
                grids[ax] = (sorted({s.amplitude_rad for _, s in segs}), sorted({s.frequency_hz for _, s in segs}))
        got = dwell_fr_all(grids) if grids else {}
        dwell = {}
        for ax in AXES:
            if ax not in grids:
                dwell[ax] = ()
                continue
            (amps, freqs), (p, e) = grids[ax], got[ax]
            dwell[ax] = tuple(FrequencyResponse(np.array(freqs), p[i], e[i], a, ax, friction_model=model.friction.name)
                              for i, a in enumerate(amps))
        run = {ax: tuple(frs) for ax, frs in run_responses(th, prof, model.actuator.moment_arm_m).items()}
        verdict = None
        if mask is not None:   # part of the dwell step: the mask's dwells and the causes' re-runs
            bar.set_postfix_str("spec verdict")
            verdict = _verdict(model, mask, prof, measured, info, dt_s, threads, engine, tm)
        bar.update()

        result = GreenRunResult(
            model=model, profile=prof, profile_file=profile_file, engine=engine, dt_s=dt_s, time_history=th,
            linear=linear, dwell=dwell, run=run, notch_hz=notch, load_resonance_hz=wl, model_info=info,
            spec=specs, measured=measured, verdict=verdict,
            created_utc=_dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"))
        if out is not None:
            result.write(out, view_angle_scale=view_angle_scale, view_fps=view_fps, progress=bar)
    finally:
        bar.close()
    return result
