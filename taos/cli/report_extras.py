"""Green Run report additions: figures of merit (:mod:`taos.report.merit`), the spec-mask verdict
(:mod:`taos.report.spec`) and a measured record overlaid on the model (:mod:`taos.identify`).

Kept beside :mod:`taos.cli.report` so the report module stays small; the numbers come from
the analysis modules, this module only gathers, tabulates and draws them."""

from __future__ import annotations

import html
import math

import numpy as np

AXES = ("pitch", "yaw")


def _h(x) -> str:
    return html.escape(str(x))


def spec_results(model, spec_path) -> dict:
    """{axis: SpecResult} of the model's linear response against the mask (empty if None)."""
    if spec_path is None:
        return {}
    from taos.report.spec import check_spec, load_spec
    mask = load_spec(spec_path)
    return {ax: check_spec(model, mask, ax) for ax in AXES}


def data_responses(data_path, model) -> dict:
    """{axis: MeasuredResponse} estimated from a measured record (estimator chosen and
    explained by :func:`taos.identify.estimation.estimate`)."""
    from taos.identify.data import load_test_data
    from taos.identify.estimation import estimate
    data = load_test_data(data_path)
    return {r.axis: r for r in estimate(data)}


def decorate_bode(fig, spec_result, test, axis, linear_fr, moment_arm_m: float) -> None:
    """Spec marks and the measured record's points on one axis' Bode figure."""
    from taos.plotting import bode
    from taos.plotting.spec import bode_axes, draw_spec

    ax = bode_axes(fig)
    if test and axis in test:
        fr = test[axis].to_freqresp(moment_arm_m)
        bode.draw_response(ax, fr, 1.0, color="tab:orange", label=f"test record ({test[axis].method})",
                           gid="test-data", marker="s", linestyle="none", ref=linear_fr)
        ax[0, 0].legend(fontsize=8, loc="best")
    if spec_result is not None:
        draw_spec(ax, spec_result)


def extras_summary(info: dict, specs: dict, test, dwell: dict, model) -> dict:
    """summary.json additions: ``figures_of_merit`` (per axis), ``spec`` (per axis, with
    ``spec_pass``) and ``test_data`` (measured vs model at the record's points)."""
    out = {"figures_of_merit": info["figures_of_merit"]}
    if specs:
        out["spec"] = {ax: r.to_dict() for ax, r in specs.items()}
        out["spec_pass"] = all(r.passed for r in specs.values())
    if test:
        rows = {}
        for ax, r in test.items():
            d = r.to_dict(model=model)
            dm = dwell.get(ax)
            items = []
            for k, f in enumerate(r.freq_hz):
                it = {"freq_hz": float(f), "amplitude_deg": math.degrees(r.amplitude_rad[k]),
                      "piston_gain_db": d["piston"]["gain_db"][k], "piston_phase_deg": d["piston"]["phase_deg"][k]}
                if d["engine"]:
                    it.update(engine_gain_db=d["engine"]["gain_db"][k], engine_phase_deg=d["engine"]["phase_deg"][k])
                if dm is not None and len(dm["freq_hz"]):
                    j = np.flatnonzero(np.isclose(dm["freq_hz"], f, rtol=2e-3))
                    i = np.flatnonzero(np.isclose(dm["amplitude_rad"], r.amplitude_rad[k], rtol=2e-2))
                    if i.size and j.size:
                        it["model_piston_gain_db"] = float(20 * np.log10(abs(dm["piston"][i[0], j[0]])))
                        it["model_engine_gain_db"] = float(20 * np.log10(abs(dm["engine"][i[0], j[0]])))
                items.append(it)
            rows[ax] = {"method": r.method, "excitation": d["excitation"], "points": items}
        out["test_data"] = {"source": next(iter(test.values())).source, "axes": rows}
    return out


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
        out.append(f"""<h2 id="spec-mask">Spec mask: {_h(name)} — <span class="{'pass' if s['spec_pass'] else 'fail'}">{verdict}</span></h2>
<table><tr><th>axis</th><th>bound</th><th>freq [Hz]</th><th>limits</th><th>model (linear)</th><th>result</th></tr>{''.join(srows)}</table>
<p class="note">Mask file <code>{_h(next(iter(s['spec'].values()))['spec_file'])}</code>; the same marks are on the Bode plots.</p>""")
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
