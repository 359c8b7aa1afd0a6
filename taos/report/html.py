"""The Green Run report page (``index.html``) of a :class:`taos.report.analysis.GreenRunResult`.

Rendering only: the numbers come from the analysis (:func:`taos.report.greenrun`, its
``summary()``); the plots from :mod:`taos.plotting` and the 3-D view from
:func:`taos.viewer.offline_html`. The page opens with the verdict in words (why the model fails
or passes its mask, and which cause) and is self-contained and works offline: interactive
Bode and time-history plots (Plotly: zoom, pan, hover readouts; :mod:`taos.plotting.interactive`)
with the plotly.js bundle inline once, the same plots as static PNG figures (matplotlib, inline
base64, in a closed "Static figures" section: for print and the documentation), a summary
table, the figures of merit, the spec-mask verdict on every basis, the measured record beside
the model, and the meshcat 3-D animation inline in an ``iframe srcdoc``. Plotted traces are
decimated to at most :data:`MAX_PLOT_POINTS` samples per line (:data:`MAX_INTERACTIVE_POINTS`
in the interactive plots; the HDF5 keeps every sample); the 3-D view holds at most
:data:`MAX_VIEW_FRAMES` keyframes (the page stays under 15 MB for any run length).
"""

from __future__ import annotations

import base64
import contextlib
import gc
import html
import io
import math
import threading

import numpy as np

#: keyframes of the embedded 3-D view (fps lowered for long runs) and samples per plotted trace
MAX_VIEW_FRAMES = 4000
MAX_PLOT_POINTS = 20000
#: samples per trace of the interactive time history (10 traces: about 0.5 MB of the page)
MAX_INTERACTIVE_POINTS = 6000
AXES = ("pitch", "yaw")


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

    from taos.plotting._common import freeze_layout
    freeze_layout(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, pil_kwargs={"compress_level": 1})  # zlib level 1: 40 % faster, +10 % bytes
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _h(x) -> str:
    return html.escape(str(x))


def decorate_bode(fig, spec_result, test, axis, linear_fr, moment_arm_m: float) -> None:
    """Spec marks and the measured record's points on one axis' Bode figure."""
    from taos.plotting import bode
    from taos.plotting._common import legend_once
    from taos.plotting.spec import bode_axes, draw_spec

    ax = bode_axes(fig)
    if test and axis in test:
        fr = test[axis].to_freqresp(moment_arm_m)
        bode.draw_response(ax, fr, 1.0, color="tab:orange", label=f"test record ({test[axis].method})",
                           gid="test-data", marker="s", linestyle="none", ref=linear_fr)
        legend_once(fig, ax[0, 0], fontsize=8, loc="best")
    if spec_result is not None:
        draw_spec(ax, spec_result)


def render_html(result, summary: dict | None = None, *, view_angle_scale: float = 5.0,
                view_fps: float = 100.0, progress=None) -> str:
    """The report page of ``result`` (a :class:`taos.report.analysis.GreenRunResult`; ``summary``: its ``summary()``, computed when not given).

    ``view_angle_scale``: engine-angle exaggeration of the 3-D view [-]; ``view_fps``: its
    keyframe rate [1/s], lowered to keep at most :data:`MAX_VIEW_FRAMES` keyframes;
    ``progress``: a tqdm bar advanced after the plots and after the 3-D view, or None."""
    s = result.summary() if summary is None else summary
    with _no_full_collection():
        return _render(result, s, view_angle_scale, view_fps, progress)


_GC_LOCK = threading.Lock()
_gc_saved: list = []     # [depth, thresholds before the outermost render]


@contextlib.contextmanager
def _no_full_collection():
    """No full (generation-2) garbage collection while the page renders: the plotting
    libraries' first import and the figures make many long-lived objects, and each full
    collection then scans every object of the process (in a fresh ``taos greenrun`` two or
    three of them, ~0.1-0.2 CPU-s each); the young generations are still collected, and the
    thresholds are restored when the last of the renders running at once ends (the next full
    collection then comes as usual)."""
    with _GC_LOCK:
        if not _gc_saved:
            t = gc.get_threshold()
            _gc_saved[:] = [0, t]
            gc.set_threshold(t[0], t[1], max(t[2], 1 << 30))
        _gc_saved[0] += 1
    try:
        yield
    finally:
        with _GC_LOCK:
            _gc_saved[0] -= 1
            if not _gc_saved[0]:
                gc.set_threshold(*_gc_saved[1])
                _gc_saved.clear()


def _render(result, s, view_angle_scale, view_fps, progress) -> str:
    from taos.viewer import offline_html

    th = result.time_history
    if progress is not None:
        progress.set_postfix_str("plots")
    figs = {**_static_figures(result), **_interactive_figures(result)}
    if progress is not None:
        progress.update()
        progress.set_postfix_str("3-D view")
    fps = min(view_fps, MAX_VIEW_FRAMES / max(float(th.t_s[-1] - th.t_s[0]), 1e-9))
    view = offline_html(th, angle_scale=view_angle_scale, fps=fps)
    if progress is not None:
        progress.update()
        progress.set_postfix_str("write")
    return _page(result.model, s, figs, view, view_angle_scale)


def _bode_title(result, ax: str) -> str:
    return f"{ax}: command → piston and engine ({result.model.name})"


def _static_figures(result) -> dict:
    """The static PNG figures (matplotlib) as data URLs: Bode per axis, time history and its zoom."""
    from taos.plotting import bode, timehist

    th, R = result.time_history, result.model.actuator.moment_arm_m
    figs = {}
    for ax in AXES:
        fig = bode.plot_freqresp(
            [result.linear[ax]] + list(result.dwell[ax]), resonance_hz=result.load_resonance_hz[ax],
            notch_hz=result.notch_hz[ax], data=result.run.get(ax), data_label="two-axis run",
            title=_bode_title(result, ax))
        decorate_bode(fig, result.spec.get(ax), result.measured, ax, result.linear[ax], R)
        figs[f"bode_{ax}"] = _png(fig)
    figs["timehist"] = _png(timehist.plot_timehistory(decimated(th, MAX_PLOT_POINTS), "in", "deg"))
    zoom = decimated(th, MAX_PLOT_POINTS, t_range_s=(0.0, 4.0))
    figs["timehist_zoom"] = _png(timehist.plot_timehistory(
        zoom, "in", "deg", t_range_s=(0.0, 4.0), title="first 4 s (0.4 deg dwell, stick-slip onset)"))
    return figs


def _interactive_figures(result) -> dict:
    """The interactive plots (Plotly ``<div>``s): Bode per axis (ids ``bode-pitch``, ``bode-yaw``)
    and the time history (``timehist``)."""
    from taos.plotting import interactive as ia

    R = result.model.actuator.moment_arm_m
    out = {}
    for ax in AXES:
        meas = result.measured.get(ax) if result.measured else None
        fig = ia.bode_figure([result.linear[ax]] + list(result.dwell[ax]), resonance_hz=result.load_resonance_hz[ax],
                             notch_hz=result.notch_hz[ax], data=result.run.get(ax), data_label="two-axis run",
                             measured=None if meas is None else meas.to_freqresp(R),
                             measured_label=None if meas is None else f"test record ({meas.method})",
                             spec_result=result.spec.get(ax), title=_bode_title(result, ax))
        out[f"i_bode_{ax}"] = ia.page_html(fig, f"bode-{ax}")
    th = decimated(result.time_history, MAX_INTERACTIVE_POINTS)
    out["i_timehist"] = ia.page_html(ia.timehistory_figure(th, title="two-axis run (zoom: drag; reset: double-click)"),
                                     "timehist")
    return out


_CSS = """body{font:14px/1.45 system-ui,sans-serif;margin:24px auto;max-width:1150px;color:#1d1f23}
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccd}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccd;padding:3px 8px;text-align:right}
th{background:#eef}td:first-child,th:first-child{text-align:left}img{max-width:100%}
.note{color:#555;font-size:12px}iframe{width:100%;height:620px;border:1px solid #ccd}
.verdict{font-size:15px;padding:8px 12px;border-left:4px solid}.verdict.pass{border-color:#1a7f37}
.verdict.fail{border-color:#c62828}.pass{color:#1a7f37}.fail{color:#c62828}tr.fail td{background:#fdecea}"""


def _page(model, s, figs, view, scale) -> str:
    from taos.plotting.interactive import plotly_script

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
<html><head><meta charset="utf-8"><title>Green Run report: {_h(model.name)}</title><style>{_CSS}</style>
{plotly_script()}</head>
<body>
<h1>Green Run two-axis vectoring: {_h(model.name)}</h1>
{verdict_line_html(s)}
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
{figs['i_bode_pitch']}
<h2>Frequency response: yaw</h2>
{figs['i_bode_yaw']}
<p class="note">Interactive: drag to zoom, double-click to reset, hover for the values; a click on a legend
entry hides or shows that curve. Lines: exact linear response (no friction, unity avionics). Lines with markers:
sine-dwell describing function at the profile amplitudes (friction and avionics included). Open circles: the
response read off the two-axis run, dwell by dwell (last two cycles). Triangle: the linear
command → piston notch; dashed vertical: load resonance w_L = sqrt((K_L R² + K_n)/J_n).
Piston gain is x_p/(R θ_c) (dimensionless, 0 dB at low frequency); phase is continuous from low
frequency. Grey bars: spec-mask bounds; green circle / red cross: the linear response passes / fails.
Squares: the measured record (when given), estimated from its dwells.</p>
<h2>Sine-dwell points</h2>{''.join(dwell_tables)}
<h2>Time history</h2>
{figs['i_timehist']}
<details id="static-figures"><summary>Static figures (PNG, for print and documents)</summary>
<img alt="pitch Bode plot" src="{figs['bode_pitch']}">
<img alt="yaw Bode plot" src="{figs['bode_yaw']}">
<img alt="time history" src="{figs['timehist']}">
<img alt="time history, first 4 s" src="{figs['timehist_zoom']}">
</details>
</body></html>
"""


def _fmt(x, spec=".2f", unit=""):
    return "–" if x is None else f"{x:{spec}}{unit}"


def extras_html(s: dict) -> str:
    """The report's "Figures of merit", "Spec mask" and "Test record" sections."""
    fm = s.get("figures_of_merit", {})
    rows = []
    for ax, m in fm.items():
        e, p, st = m["engine"], m["piston"], m.get("step") or {}
        rows.append(f"<tr><td>{_h(ax)}</td><td>{_fmt(e['bandwidth_3db_hz'], '.2f', ' Hz')}</td>"
                    f"<td>{_fmt(e['phase_90_hz'], '.2f', ' Hz')}</td>"
                    f"<td>{e['peak_gain_db']:+.2f} dB at {e['peak_freq_hz']:.2f} Hz</td>"
                    f"<td>{p['peak_gain_db']:+.2f} dB at {p['peak_freq_hz']:.2f} Hz</td>"
                    f"<td>{m['load_resonance_hz']:.3f} / {m['notch_hz']:.3f} Hz</td>"
                    f"<td>{_fmt(st.get('rise_time_s') and 1e3 * st['rise_time_s'], '.1f', ' ms')}</td>"
                    f"<td>{_fmt(st.get('overshoot_pct'), '.1f', ' %')}</td>"
                    f"<td>{_fmt(st.get('threshold_deg'), '.4f', ' deg')}</td>"
                    f"<td>{_fmt(st.get('hysteresis_deg'), '.4f', ' deg')}</td></tr>")
    step_amp = next((m.get("step", {}).get("step_amplitude_deg") for m in fm.values()), None)
    out = [f"""<h2 id="figures-of-merit">Figures of merit</h2>
<table><tr><th>axis</th><th>engine −3 dB</th><th>engine −90°</th><th>engine peak</th><th>piston peak</th>
<th>w_L / notch</th><th>rise 10–90 %</th><th>overshoot</th><th>threshold</th><th>hysteresis</th></tr>{''.join(rows)}</table>
<p class="note">Frequency figures from the exact linear response (gains relative to the low-frequency gain; lowest
−3 dB and −90° crossings; planar simplex model). Step figures by simulating the full simplex model ({_h(s.get('friction_model', ''))} friction,
avionics): a {_fmt(step_amp, 'g')} deg step (rise time, overshoot), the smallest step that moves the engine half
way (threshold), and a slow ±0.2 deg triangle (hysteresis: engine angle down minus up at zero command).</p>"""]
    if "spec" in s:
        verdict = "PASS" if s["spec_pass"] else "FAIL"
        srows = []
        for ax, r in s["spec"].items():
            for p in r["points"]:
                for kind, b, v, ok in (("gain [dB]", p["gain_db_bounds"], p["gain_db"], p["gain_pass"]),
                                       ("phase [deg]", p["phase_deg_bounds"], p["phase_deg"], p["phase_pass"])):
                    if b is None:
                        continue
                    cls = "pass" if ok else "fail"
                    srows.append(f"<tr class='{cls}'><td>{_h(ax)}</td><td>{_h(p['response'])} {kind}</td>"
                                 f"<td>{p['freq_hz']:g}</td><td>[{b[0]:g}, {b[1]:g}]</td><td>{v:.2f}</td>"
                                 f"<td><b>{'pass' if ok else 'FAIL'}</b></td></tr>")
        name = next(iter(s["spec"].values()))["spec"]
        planar = "" if s.get("engine_model", "simplex") == "simplex" else " (planar simplex model)"
        out.append(f"""<h2 id="spec-mask">Spec mask on the linear response{planar}: {_h(name)} — <span class="{'pass' if s['spec_pass'] else 'fail'}">{verdict}</span></h2>
<table><tr><th>axis</th><th>bound</th><th>freq [Hz]</th><th>limits</th><th>model (linear)</th><th>result</th></tr>{''.join(srows)}</table>
<p class="note">Mask file <code>{_h(next(iter(s['spec'].values()))['spec_file'])}</code>; the same marks are on the Bode plots.</p>""")
    out.append(verdict_table_html(s))
    if "test_data" in s:
        trs = []
        for ax, r in s["test_data"]["axes"].items():
            for p in r["points"]:
                trs.append(f"<tr><td>{_h(ax)}</td><td>{p['freq_hz']:.4g}</td><td>{p['amplitude_deg']:.2g}</td>"
                           f"<td>{p['piston_gain_db']:.2f}</td><td>{_fmt(p.get('model_piston_gain_db'))}</td>"
                           f"<td>{_fmt(p.get('engine_gain_db'))}</td><td>{_fmt(p.get('model_engine_gain_db'))}</td></tr>")
        out.append(f"""<h2 id="test-record">Test record vs model</h2>
<p>Record <code>{_h(s['test_data']['source'])}</code>: {_h('; '.join(f"{ax}: {r['excitation']['kind']} ({r['excitation']['reason']})" for ax, r in s['test_data']['axes'].items()))}</p>
<table><tr><th>axis</th><th>freq [Hz]</th><th>amplitude [deg]</th><th>test piston [dB]</th><th>model piston [dB]</th>
<th>test engine [dB]</th><th>model engine [dB]</th></tr>{''.join(trs)}</table>""")
    return "\n".join(out)


def verdict_line_html(s: dict) -> str:
    """The report's first line: why the model fails (or passes) its mask, in words
    (``spec_verdict_text``; :mod:`taos.report.verdict`); empty when no mask was checked."""
    if "spec_verdict_text" not in s:
        return ""
    cls = "pass" if s["spec_verdict_pass"] else "fail"
    return f'<p id="spec-verdict" class="verdict {cls}"><b>{_h(s["spec_verdict_text"])}</b></p>'


def verdict_table_html(s: dict) -> str:
    """The "Spec mask on every basis" section: each point on the linear, dwell, measured and step
    bases, its value, bounds, result and (failing) cause."""
    if "spec_points" not in s:
        return ""
    trs = []
    for p in s["spec_points"]:
        for q in [k for k in p if k + "_bounds" in p]:
            b, v, ok = p[q + "_bounds"], p[q], p[q + "_pass"]
            where = "step" if p["response"] == "step" else f"{p['response']} {p['freq_hz']:g} Hz"
            amp = "–" if p["amplitude_deg"] is None else f"{p['amplitude_deg']:.2g}"
            cause = ", ".join(p["cause"]) if (p["cause"] and not ok) else ""
            if p.get("cross_axis_freq_hz"):   # a 3-D dwell with the other axis moving
                amp += f" (other axis {p['cross_axis_amplitude_deg']:.2g} at {p['cross_axis_freq_hz']:g} Hz)"
            trs.append(f"<tr class='{'pass' if ok else 'fail'}'><td>{_h(p['basis'])}</td><td>{_h(p.get('engine', ''))}</td>"
                       f"<td>{_h(p['axis'])}</td>"
                       f"<td>{_h(where)}</td><td>{amp}</td><td>{_h(q)}</td><td>{_fmt(v, '.2f')}</td>"
                       f"<td>[{b[0]:g}, {b[1]:g}]</td><td><b>{'pass' if ok else 'FAIL'}</b></td><td>{_h(cause)}</td></tr>")
    by = ", ".join(f"{k} {'pass' if v else 'FAIL'}" for k, v in s["spec_pass_by_basis"].items())
    att = s["spec_attribution"]
    return f"""<h2 id="spec-verdict-table">Spec mask on every basis: {_h(by)}</h2>
<p>{_h(s['spec_verdict_text'])}</p>
<table><tr><th>basis</th><th>engine</th><th>axis</th><th>point</th><th>amplitude [deg]</th><th>quantity</th><th>value</th><th>limits</th>
<th>result</th><th>cause</th></tr>{''.join(trs)}</table>
<p class="note">Every point was evaluated on the engine named in its row: {_h(_engine_words(att.get('engine', 'simplex')))}.
Bases: linear (exact linear response), dwell (nonlinear sine dwell, friction and avionics included,
at the profile's amplitude for that frequency; on the 3-D model with the other axis running the dwell the profile
commands at the same time), measured (the record's points at mask frequencies), step (the
simulated step figures). Cause of a failing point: the factor(s) whose removal alone makes it pass, found by
re-evaluating it on the same engine with gimbal friction none, the laboratory load (K_L ≥
{att['laboratory_load_stiffness_N_per_m']:.3g} N/m), unity avionics or the supply-pressure limit lifted
(pressure_limit: valve pressure saturation); "combined" when only removing friction, load path and avionics together
passes, "servo" when even the servo alone (those three removed) fails, "unexplained" when the model's own dwell passes
where the measurement fails. The mask's bounds and their sources are in {_h(s.get('spec', {}).get('pitch', {}).get('spec_file', 'the mask file'))}.</p>"""


def _engine_words(engine: str) -> str:
    return {"simplex": "the planar simplex model", "taos": "the 3-D taos model (its own dwells and causes)"}.get(
        engine, engine)
