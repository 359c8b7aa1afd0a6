"""The Green Run report (``taos greenrun MODEL --out DIR``).

Runs the two-axis Green Run profile (default ``models/profiles/greenrun_two_axis.toml``: pitch
and yaw commanded at the same time at different frequencies, 0.4 deg up to 7 Hz and 0.8 deg up
to 14 Hz, paper sec. 3.2) through the simplex model (:func:`taos.planar.simulate.simulate`), and
computes per axis:

* the exact linear response (:func:`taos.planar.freqresp.linear_freqresp`) on a log grid, its piston
  notch (:func:`taos.planar.simplex.load_resonance_from_notch`) and the load resonance
  w_L = sqrt((K_L R^2 + K_n) / J_n) (paper eq. 1);
* sine-dwell responses at the profile's amplitudes and frequencies
  (:func:`taos.planar.freqresp.sine_dwell_grid`);
* the response read off the two-axis run itself, as the test was analysed: for each dwell
  segment of the profile a least-squares fit y = a sin(w t') + b cos(w t') + c over its last
  two whole cycles, H = (a + j b) / A (piston as x_p / (R theta_c)).

Writes ``DIR/index.html`` (self-contained: plots inline as base64 PNG, a summary table, the
meshcat 3-D animation inline in an ``iframe srcdoc``), ``DIR/greenrun.h5`` (the run plus the
responses under ``/freqresp``) and ``DIR/summary.json``. The folder is built in a temporary
folder beside DIR and renamed into place, so a failure leaves nothing half-written.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import json
import math
import sys
from pathlib import Path

import h5py
import numpy as np

from taos.errors import InputError
from taos.harmonics import fit_sines
from taos.linear import gain_db, notch_hz
from taos.profiles import Sequence, SineDwell, TwoAxis
from taos.cli.records import load_command_source
from taos.shipped import models_dir

DEFAULT_PROFILE = models_dir() / "profiles" / "greenrun_two_axis.toml"
#: the report's own files (``--out`` receives only these, plus its mark ``.taos-output.json``)
OUTPUTS = ("index.html", "summary.json", "greenrun.h5")
#: keyframes of the embedded 3-D view (fps lowered for long runs) and samples per plotted trace
MAX_VIEW_FRAMES = 4000
MAX_PLOT_POINTS = 20000
DEFAULT_SPEC = models_dir() / "specs" / "tvc_actuator_notional.toml"
AXES = ("pitch", "yaw")


# -- analysis ---------------------------------------------------------------------------------

def dwell_segments(profile) -> list[tuple[float, SineDwell]]:
    """(start time [s], SineDwell) of each sine-dwell part of a single-axis profile."""
    parts = profile.parts if isinstance(profile, Sequence) else (profile,)
    out, t0 = [], 0.0
    for p in parts:
        if isinstance(p, SineDwell):
            out.append((t0, p))
        t0 += p.duration_s
    return out


def run_dwell_response(t_s, command_amp_rad: float, freq_hz: float, t0_s: float, cycles: int, y,
                       fit_cycles: int = 2) -> complex:
    """Fundamental of ``y`` relative to A sin(w (t - t0)) over the segment's last whole cycles."""
    m = min(fit_cycles, max(1, cycles - 1))
    lo, hi = t0_s + (cycles - m) / freq_hz, t0_s + cycles / freq_hz
    sel = (t_s >= lo) & (t_s < hi)
    return complex(fit_sines(t_s[sel] - t0_s, y[sel], freq_hz).phasor[0, 0]) / command_amp_rad


def run_responses(th, profile, moment_arm_m: float) -> dict:
    """{axis: FrequencyResponse-like dict arrays} read off the two-axis run's dwell segments."""
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


# -- helpers ---------------------------------------------------------------------------------

def decimated(th, max_points: int, t_range_s: tuple[float, float] | None = None):
    """A copy of run ``th`` (optionally cut to ``t_range_s``) keeping every k-th sample so that
    at most about ``max_points`` remain: for plots only (the HDF5 keeps every sample)."""
    import dataclasses

    sel = slice(None)
    if t_range_s is not None:
        lo, hi = np.searchsorted(th.t_s, t_range_s)
        sel = slice(int(lo), int(hi) + 1)
    n = th.t_s[sel].size
    k = max(1, int(math.ceil(n / max_points)))
    if k == 1 and t_range_s is None:
        return th
    idx = np.arange(n)[::k]
    base = sel.start or 0
    ch = {name: np.asarray(getattr(th, name))[:, base:base + n][:, idx] for name in th.ARRAYS}
    return dataclasses.replace(th, t_s=th.t_s[sel][idx], **ch)


def _png(fig) -> str:
    import matplotlib.pyplot as plt
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _h(x) -> str:
    return html.escape(str(x))


def _db(h) -> float:
    return float(gain_db(h))


def _write_h5(path: Path, th, linear: dict, dwell: dict, run: dict) -> None:
    th.to_hdf5(path)
    with h5py.File(path, "a") as h5:
        g = h5.create_group("freqresp")
        g.attrs["piston_definition"] = "x_p / (R theta_c), complex"
        g.attrs["engine_definition"] = "theta / theta_c, complex"
        for ax in linear:
            a = g.create_group(ax)
            a.create_dataset("linear/freq_hz", data=linear[ax].freq_hz)
            a.create_dataset("linear/piston", data=linear[ax].piston)
            a.create_dataset("linear/engine", data=linear[ax].engine)
            d = dwell[ax]
            a.create_dataset("sine_dwell/freq_hz", data=d["freq_hz"])
            a.create_dataset("sine_dwell/amplitude_rad", data=d["amplitude_rad"])
            a.create_dataset("sine_dwell/piston", data=d["piston"])
            a.create_dataset("sine_dwell/engine", data=d["engine"])
            for fr in run.get(ax, []):
                r = a.create_group(f"run_dwell/{math.degrees(fr.amplitude_rad):.3g}deg")
                r.attrs["amplitude_rad"] = fr.amplitude_rad
                r.create_dataset("freq_hz", data=fr.freq_hz)
                r.create_dataset("piston", data=fr.piston)
                r.create_dataset("engine", data=fr.engine)


# -- the report -------------------------------------------------------------------------------

def greenrun_report(model_path, out_dir="out/greenrun", *, profile_path=None, friction: str | None = None,
                    engine: str = "simplex", progress: bool = True, dt_s: float | None = None,
                    view_angle_scale: float = 5.0, view_fps: float = 100.0, allow_unstable: bool = False,
                    spec_path=DEFAULT_SPEC, data_path=None) -> Path:
    """Build the Green Run report folder ``out_dir`` (see the module docstring); returns its path.

    Parameters
    ----------
    model_path : str or Path
        Model file (TOML).
    out_dir : str or Path
        Report folder; replaced as a whole when the new one is complete.
    profile_path : str or Path, optional
        Two-axis profile; default the notional Green Run profile.
    friction : str, optional
        Swap the model's friction law (keeping its torque levels).
    engine : str
        ``"simplex"`` (planar, one model per axis) or ``"taos"`` (3-D: both axes on one engine,
        FEM two-half gimbal, spherical-bearing friction; :mod:`taos.taos3d`).
    progress : bool
        tqdm progress bar on standard error.
    dt_s : float, optional
        Integration step [s]; default the engine's own (:func:`taos.cli.basic.engine_default_dt_s`).
    view_angle_scale : float
        Engine-angle exaggeration of the embedded 3-D view [-].
    view_fps : float
        Keyframe rate of the embedded 3-D view [1/s]; lowered so that the view holds at most
        :data:`MAX_VIEW_FRAMES` keyframes (the page stays under 15 MB for any run length).
    spec_path : str or Path, optional
        Spec mask (:mod:`taos.report.spec`) checked against each axis' linear response and marked on
        the Bode plots; default ``models/specs/tvc_actuator_notional.toml``; None: no check.
    data_path : str or Path, optional
        A measured record (e.g. ``models/data/greenrun_hotfire_synthetic.csv``): its estimated
        responses (:func:`taos.identify.estimate.estimate`) are overlaid on the Bode plots and
        tabulated beside the model's.
    allow_unstable : bool
        Run a model whose linear block is unstable (else refused, exit 3) and skip the envelope check.

    The plotted traces are decimated to at most :data:`MAX_PLOT_POINTS` samples per line; the
    HDF5 keeps every recorded sample.
    """
    from tqdm import tqdm

    from taos.cli.basic import info_dict
    from taos.cli.report_extras import decorate_bode, extras_summary
    from taos.planar.freqresp import FrequencyResponse, linear_freqresp, sine_dwell_grid
    from taos.model import load_model
    from taos.plotting import bode, timehist
    from taos.planar.simplex import load_resonance_from_notch
    from taos.planar.simulate import simulate
    from taos.viewer import offline_html

    from taos.planar import envelope as run_checks
    from taos.results import check_output_folder, input_provenance, write_output_folder

    out = Path(out_dir)
    # bad input fails here, before any progress output: one line, nothing written
    check_output_folder(out, OUTPUTS)
    model = load_model(model_path, friction=friction)
    ppath = DEFAULT_PROFILE if profile_path is None else Path(profile_path)
    profile = load_command_source(ppath)
    if not isinstance(profile, TwoAxis):
        raise InputError(str(ppath), "(profile)", "a two-axis profile with [pitch] and [yaw] tables",
                         got=type(profile).__name__)
    if dt_s is None:
        from taos.cli.basic import engine_default_dt_s
        dt_s = engine_default_dt_s(engine)
    run_checks.check_run(model, profile, dt_s)
    run_checks.check_linear_stability(model, allow=allow_unstable)
    from taos.cli.report_extras import data_responses, spec_results
    specs = spec_results(model, spec_path)
    test = data_responses(data_path, model) if data_path is not None else None
    info = info_dict(model)
    R = model.actuator.moment_arm_m
    if engine == "taos":
        from taos.taos3d import simulate_taos, taos_freqresp, taos_model
        tm = taos_model(model)
        run_sim = lambda: simulate_taos(tm, profile, dt_s=dt_s)  # noqa: E731
        lin_fr = lambda f, ax: taos_freqresp(tm, f, None, ax)  # noqa: E731

        def dwell_fr_of(amps, freqs, ax):
            frs = [taos_freqresp(tm, freqs, a, ax) for a in amps]
            return np.array([fr.piston for fr in frs]), np.array([fr.engine for fr in frs])
    elif engine == "simplex":
        run_sim = lambda: simulate(model, profile, dt_s=dt_s)  # noqa: E731
        lin_fr = lambda f, ax: linear_freqresp(model, f, ax)  # noqa: E731
        dwell_fr_of = lambda amps, freqs, ax: sine_dwell_grid(model, amps, freqs, ax, dt_max_s=dt_s)  # noqa: E731
    else:
        raise InputError("command line", "--engine", "simplex or taos", got=repr(engine))
    steps = ["simulate", "linear response", "sine dwell", "plots", "3-D view", "write"]
    bar = tqdm(total=len(steps), desc="greenrun", unit="step", file=sys.stderr, disable=not progress)

    def step(name):
        bar.set_postfix_str(name)

    try:
        step("simulate")
        th = run_sim()
        if not allow_unstable:
            run_checks.check_envelope(th, model)
        th.provenance.update(input_provenance(ppath, "profile", th.provenance))
        bar.update()

        step("linear response")
        f_lin = np.logspace(-1, math.log10(30.0), 240)
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

        step("sine dwell")
        dwell, dwell_fr = {}, {}
        for ax in AXES:
            segs = dwell_segments(getattr(profile, ax))
            amps = sorted({s.amplitude_rad for _, s in segs})
            freqs = sorted({s.frequency_hz for _, s in segs})
            if not segs:
                dwell[ax] = {"freq_hz": np.zeros(0), "amplitude_rad": np.zeros(0),
                             "piston": np.zeros((0, 0), complex), "engine": np.zeros((0, 0), complex)}
                dwell_fr[ax] = []
                continue
            p, e = dwell_fr_of(amps, freqs, ax)
            dwell[ax] = {"freq_hz": np.array(freqs), "amplitude_rad": np.array(amps), "piston": p, "engine": e}
            dwell_fr[ax] = [FrequencyResponse(np.array(freqs), p[i], e[i], a, ax, friction_model=model.friction.name)
                            for i, a in enumerate(amps)]
        run = run_responses(th, profile, R)
        bar.update()

        step("plots")
        figs = {}
        for ax in AXES:
            fig = bode.plot_freqresp(
                [linear[ax]] + dwell_fr[ax], resonance_hz=wl[ax], notch_hz=notch[ax],
                data=run.get(ax), data_label="two-axis run", title=f"{ax}: command → piston and engine ({model.name})")
            decorate_bode(fig, specs.get(ax), test, ax, linear[ax], R)
            figs[f"bode_{ax}"] = _png(fig)
        figs["timehist"] = _png(timehist.plot_timehistory(decimated(th, MAX_PLOT_POINTS), "in", "deg"))
        zoom = decimated(th, MAX_PLOT_POINTS, t_range_s=(0.0, 4.0))
        figs["timehist_zoom"] = _png(timehist.plot_timehistory(
            zoom, "in", "deg", t_range_s=(0.0, 4.0), title="first 4 s (0.4 deg dwell, stick-slip onset)"))
        bar.update()

        step("3-D view")
        fps = min(view_fps, MAX_VIEW_FRAMES / max(float(th.t_s[-1] - th.t_s[0]), 1e-9))
        view = offline_html(th, angle_scale=view_angle_scale, fps=fps)
        bar.update()

        step("write")
        summary = _summary(model, info, th, notch, wl, dwell, run, ppath)
        summary.update(extras_summary(info, specs, test, dwell, model))
        page = _page(model, summary, figs, view, view_angle_scale, dwell, run)
        text = json.dumps(summary, indent=2, allow_nan=False) + "\n"
        write_output_folder(out, {
            "index.html": lambda p: p.write_text(page, encoding="utf-8"),
            "summary.json": lambda p: p.write_text(text),
            "greenrun.h5": lambda p: _write_h5(p, th, linear, dwell, run),
        })
        bar.update()
    finally:
        bar.close()
    return out


def _summary(model, info, th, notch, wl, dwell, run, ppath) -> dict:
    from taos.planar.freqresp import linear_phase_reference
    from taos.linear import phase_deg_continuous
    from taos.units import from_si

    fr = model.friction
    dw = {}
    for ax, d in dwell.items():
        if not len(d["freq_hz"]):
            dw[ax] = []
            continue
        rp, re = linear_phase_reference(model, d["freq_hz"], ax)
        pp = [phase_deg_continuous(d["freq_hz"], d["piston"][i], rp) for i in range(len(d["amplitude_rad"]))]
        pe = [phase_deg_continuous(d["freq_hz"], d["engine"][i], re) for i in range(len(d["amplitude_rad"]))]
        dw[ax] = [{"amplitude_deg": math.degrees(a), "freq_hz": float(f),
                   "piston_gain_db": _db(d["piston"][i, j]), "piston_phase_deg": float(pp[i][j]),
                   "engine_gain_db": _db(d["engine"][i, j]), "engine_phase_deg": float(pe[i][j])}
                  for i, a in enumerate(d["amplitude_rad"]) for j, f in enumerate(d["freq_hz"])]
    rn = {}
    for ax, rs in run.items():
        rows = []
        for r in rs:
            rp, re = linear_phase_reference(model, r.freq_hz, ax)
            pp, pe = phase_deg_continuous(r.freq_hz, r.piston, rp), phase_deg_continuous(r.freq_hz, r.engine, re)
            rows += [{"amplitude_deg": math.degrees(r.amplitude_rad), "freq_hz": float(f),
                      "piston_gain_db": _db(r.piston[j]), "piston_phase_deg": float(pp[j]),
                      "engine_gain_db": _db(r.engine[j]), "engine_phase_deg": float(pe[j])}
                     for j, f in enumerate(r.freq_hz)]
        rn[ax] = rows
    return {
        "model_file": str(model.source), "model_name": model.name, "model_sha256": model.sha256,
        "profile_file": str(ppath), "profile": th.provenance.get("profile", ""),
        "friction_model": fr.name, "engine_model": th.provenance.get("engine", "simplex"),
        "package_version": th.provenance.get("package_version", ""),
        "provenance": {k: th.provenance.get(k, "") for k in (
            "package_version", "git_revision", "model_file", "model_sha256", "profile_file", "profile_sha256",
            "stiffness_source", "stiffness_sha256", "solver", "seeds", "engine", "friction_model")},
        "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "load_resonance_hz": {ax: wl[ax] for ax in wl}, "notch_frequency_hz": notch,
        "breakaway_deflection_deg": info["breakaway_deflection_deg"],
        "load_stiffness_N_per_m": model.structure.load_stiffness_N_per_m,
        "load_stiffness_lbf_per_in": from_si(model.structure.load_stiffness_N_per_m, "N/m", "lbf/in"),
        "load_stiffness_rotational_Nm_per_rad": info["load_stiffness_rotational_Nm_per_rad"],
        "oil_column_stiffness_N_per_m": info["oil_column_stiffness_N_per_m"],
        "coulomb_torque_Nm": fr.coulomb_torque_Nm,
        "coulomb_torque_in_lbf": from_si(fr.coulomb_torque_Nm, "N*m", "in*lbf"),
        "moment_arm_m": model.actuator.moment_arm_m, "stall_force_N": info["stall_force_N"],
        "avionics_lsb_deg": info["avionics_lsb_deg"],
        "run": {"duration_s": float(th.t_s[-1]), "samples": int(th.t_s.size),
                "peak_engine_deg": {ax: float(np.degrees(np.max(np.abs(th.engine_rad[k])))) for k, ax in enumerate(th.axes)},
                "peak_piston_in": {ax: from_si(float(np.max(np.abs(th.piston_m[k]))), "m", "in") for k, ax in enumerate(th.axes)},
                "peak_friction_torque_Nm": {ax: float(np.max(np.abs(th.friction_torque_Nm[k]))) for k, ax in enumerate(th.axes)},
                "peak_load_force_N": {ax: float(np.max(np.abs(th.load_force_N[k]))) for k, ax in enumerate(th.axes)}},
        "sine_dwell": dw, "run_dwell": rn,
    }


_CSS = """body{font:14px/1.45 system-ui,sans-serif;margin:24px auto;max-width:1150px;color:#1d1f23}
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccd}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccd;padding:3px 8px;text-align:right}
th{background:#eef}td:first-child,th:first-child{text-align:left}img{max-width:100%}
.note{color:#555;font-size:12px}iframe{width:100%;height:620px;border:1px solid #ccd}
.pass{color:#1a7f37}.fail{color:#c62828}tr.fail td{background:#fdecea}"""


def _page(model, s, figs, view, scale, dwell, run) -> str:
    from taos.cli.report_extras import extras_html
    rows = [
        ("load resonance w_L (pitch / yaw)", f"{s['load_resonance_hz']['pitch']:.3f} / {s['load_resonance_hz']['yaw']:.3f} Hz"),
        ("piston notch, linear (pitch / yaw)", f"{s['notch_frequency_hz']['pitch']:.3f} / {s['notch_frequency_hz']['yaw']:.3f} Hz"),
        ("load stiffness K_L", f"{s['load_stiffness_lbf_per_in']:,.0f} lbf/in ({s['load_stiffness_N_per_m']:.4g} N/m)"),
        ("K_L R^2", f"{s['load_stiffness_rotational_Nm_per_rad']:.4g} N m/rad"),
        ("oil-column stiffness", f"{s['oil_column_stiffness_N_per_m']:.4g} N/m"),
        ("friction law, Coulomb torque", f"{_h(s['friction_model'])}, {s['coulomb_torque_in_lbf']:,.0f} in lbf ({s['coulomb_torque_Nm']:.4g} N m)"),
        ("breakaway deflection T_f / (K_L R^2)", f"{s['breakaway_deflection_deg']:.4f} deg"),
        ("moment arm R, stall force", f"{s['moment_arm_m']:.3g} m, {s['stall_force_N']:.4g} N"),
        ("avionics LSB", f"{s['avionics_lsb_deg']:.5f} deg"),
    ]
    r = s["run"]
    for ax in r["peak_engine_deg"]:
        rows.append((f"run peaks, {ax}: engine / piston / T_f / F_L",
                     f"{r['peak_engine_deg'][ax]:.3f} deg / {r['peak_piston_in'][ax]:.4f} in / "
                     f"{r['peak_friction_torque_Nm'][ax]:.4g} N m / {r['peak_load_force_N'][ax]:.4g} N"))
    table = "".join(f"<tr><td>{_h(a)}</td><td>{b}</td></tr>" for a, b in rows)
    dwell_tables = []
    for ax, items in s["sine_dwell"].items():
        runmap = {(round(x["amplitude_deg"], 6), x["freq_hz"]): x for x in s["run_dwell"].get(ax, [])}
        trs = []
        for x in items:
            rr = runmap.get((round(x["amplitude_deg"], 6), x["freq_hz"]))
            run_cells = (f"<td>{rr['engine_gain_db']:.2f}</td><td>{rr['engine_phase_deg']:.1f}</td>" if rr
                         else "<td>–</td><td>–</td>")
            trs.append(f"<tr><td>{x['freq_hz']:g}</td><td>{x['amplitude_deg']:.2g}</td>"
                       f"<td>{x['piston_gain_db']:.2f}</td><td>{x['piston_phase_deg']:.1f}</td>"
                       f"<td>{x['engine_gain_db']:.2f}</td><td>{x['engine_phase_deg']:.1f}</td>{run_cells}</tr>")
        dwell_tables.append(
            f"<h3>{_h(ax)}</h3><table><tr><th>freq [Hz]</th><th>amplitude [deg]</th><th>piston gain [dB]</th>"
            f"<th>piston phase [deg]</th><th>engine gain [dB]</th><th>engine phase [deg]</th>"
            f"<th>run: engine gain [dB]</th><th>run: engine phase [deg]</th></tr>{''.join(trs)}</table>")
    srcdoc = view.replace("&", "&amp;").replace('"', "&quot;")
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>Green Run report: {_h(model.name)}</title><style>{_CSS}</style></head>
<body>
<h1>Green Run two-axis vectoring: {_h(model.name)}</h1>
<p>Model <code>{_h(s['model_file'])}</code> (sha256 {_h(s['model_sha256'][:12])}…), profile
<code>{_h(s['profile_file'])}</code> ({_h(s['profile'])}), friction <b>{_h(s['friction_model'])}</b>,
{_h(s['engine_model'])} engine model, taos {_h(s['package_version'])}, {_h(s['created_utc'])}.</p>
<h2>Summary</h2><table>{table}</table>
<h2>3-D view</h2>
<p class="note">Engine angle exaggerated ×{scale:g}; load-path deflection x_p − Rθ exaggerated as shown in the legend. Play, pause,
time and speed (timeScale) are under “Open Controls” → Animations.</p>
<iframe title="3-D gimbal animation" srcdoc="{srcdoc}"></iframe>
{extras_html(s)}
<h2>Frequency response: pitch</h2>
<img alt="pitch Bode plot" src="{figs['bode_pitch']}">
<h2>Frequency response: yaw</h2>
<img alt="yaw Bode plot" src="{figs['bode_yaw']}">
<p class="note">Lines: exact linear response (no friction, unity avionics). Dashed/markers: sine-dwell
describing function at the profile amplitudes (friction and avionics included). Open circles: the
response read off the two-axis run, dwell by dwell (last two cycles). Triangle: the linear
command → piston notch; dashed vertical: load resonance w_L = sqrt((K_L R² + K_n)/J_n).
Piston gain is x_p/(R θ_c) (dimensionless, 0 dB at low frequency); phase is continuous from low
frequency. Grey bars: spec-mask bounds; green circle / red cross: the linear response passes / fails.
Squares: the measured record (when given), estimated from its dwells.</p>
<h2>Sine-dwell points</h2>{''.join(dwell_tables)}
<h2>Time history</h2>
<img alt="time history" src="{figs['timehist']}">
<img alt="time history, first 4 s" src="{figs['timehist_zoom']}">
</body></html>
"""
