"""Ascent and Monte Carlo plots in the manner of the seed paper's figures 7-9: engine angle over
the whole flight with a zoom on the late core-stage burn (friction laws overlaid), and the
dispersed FCS command of every run with the nominal overlaid. Drawing only."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from taos.plotting import _common  # noqa: F401  (sets the headless backend)


def plot_ascent(histories, axis: str = "yaw", zoom_s: float = 60.0, signal: str = "engine_rad"):
    """Left: ``signal`` [deg] of each run in ``histories`` (:class:`taos.flight.ascent_sim.AscentHistory`,
    e.g. one per friction law) over the whole run, PTI windows shaded and separation marked;
    right: the last ``zoom_s`` seconds (late core-stage burn). Returns the figure."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.5), gridspec_kw={"width_ratios": [2, 1]})
    h0 = histories[0]
    for a, b in h0.pti_windows.get(axis, []):
        for ax in (a1, a2):
            ax.axvspan(a, b, color="0.9", lw=0)
    for h in histories:
        y = np.degrees(h.signal(signal, axis))
        a1.plot(h.t_s, y, lw=0.7, label=h.friction_model)
        sel = h.t_s >= h.t_s[-1] - zoom_s
        a2.plot(h.t_s[sel], y[sel], lw=1.0, label=h.friction_model)
    if h0.t_s[0] < h0.separation_time_s < h0.t_s[-1]:
        a1.axvline(h0.separation_time_s, color="k", ls="--", lw=0.8, label="booster separation")
    name = {"engine_rad": "engine angle", "command_rad": "FCS command", "attitude_rad": "attitude"}.get(signal, signal)
    for ax in (a1, a2):
        ax.set_xlabel("flight time [s]")
        ax.set_ylabel(f"{axis} {name} [deg]")
        ax.grid(True, alpha=0.3)
    a2.set_xlim(h0.t_s[-1] - zoom_s, h0.t_s[-1])
    a1.set_xlim(h0.t_s[0], h0.t_s[-1])
    a1.set_title(f"{axis} {name}, whole run (PTI windows shaded)")
    a2.set_title(f"last {zoom_s:g} s")
    a1.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    return fig


def plot_study(study, signal: str = "engine_rad"):
    """:func:`plot_ascent` of an ascent study (:class:`taos.flight.ascent_sim.AscentStudy`): its
    runs on its last flown axis, zoomed on its :attr:`~taos.flight.ascent_sim.AscentStudy.zoom_s`."""
    return plot_ascent(list(study.runs), axis=study.axes[-1], zoom_s=study.zoom_s, signal=signal)


def plot_campaign(result, max_runs: int = 400):
    """Every run's FCS command normalised by the nominal run's peak (grey), the 5-95 %
    envelope, and the nominal (black): figure 9 of the seed paper. ``result`` is a
    :class:`taos.montecarlo.stats.CampaignResult`. Returns the figure."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.5), gridspec_kw={"width_ratios": [2, 1]})
    t = result.trace_t_s
    # normalised by the nominal run's command oscillation amplitude (its peak if it has none)
    nom = result.summary["nominal"]
    ref = (np.radians(nom["amplitude_deg"]) if nom.get("status") == 1 and (nom.get("amplitude_deg") or 0) > 0
           else np.max(np.abs(result.nominal_trace_rad)))
    ref = max(float(ref), 1e-12)
    ok = result.ok
    traces = np.asarray(result.traces_rad[: max_runs])[ok[: max_runs]]
    for y in traces:
        a1.plot(t, y / ref, color="0.7", lw=0.4)
    env = result.summary["envelope"]
    if ok.any():
        lo, hi = np.radians(env["p5_deg"]) / ref, np.radians(env["p95_deg"]) / ref
        a1.fill_between(t, lo, hi, color="tab:blue", alpha=0.25, label="5-95 % of runs")
    a1.plot(t, result.nominal_trace_rad / ref, color="k", lw=1.2, label="nominal")
    a1.set_xlabel("flight time [s]")
    a1.set_ylabel("FCS command / nominal oscillation amplitude [-]")
    a1.set_title(f"{result.campaign_name}: case {result.case}, {result.n_runs} runs")
    a1.grid(True, alpha=0.3)
    a1.legend(fontsize=8)
    amp = result.amplitude_deg[ok]
    lco = result.lco[ok]
    if amp.size:
        bins = np.linspace(0, max(float(amp.max()), 1e-3) * 1.05, 30)
        a2.hist(amp[~lco], bins=bins, color="0.6", label="no LCO")
        a2.hist(amp[lco], bins=bins, color="tab:red", alpha=0.8, label="LCO")
    f = result.summary["lco_fraction"]
    a2.set_title(f"LCO in {100 * (f['value'] or 0):.1f} % of completed runs (95 % CI {100 * f['ci_low']:.1f}-{100 * f['ci_high']:.1f} %)",
                 fontsize=9)
    a2.set_xlabel("command oscillation amplitude [deg]")
    a2.set_ylabel("runs")
    a2.legend(fontsize=8)
    fig.tight_layout()
    return fig

