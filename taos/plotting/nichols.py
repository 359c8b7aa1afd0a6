"""Nichols chart of the flight-control open loop with the TVC describing function (the seed
paper's figure 6), and flight-loop time histories (figures 7-8)."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from ..linear import gain_db, phase_deg
from ..units import from_si


def plot_lco_nichols(pred, amplitudes_rad=None, n_freq: int = 400, ax=None):
    """Nichols chart (phase [deg] vs gain [dB]) of L0 N(A, .) at several command amplitudes of
    ``pred`` (a :class:`taos.flight.lco.LcoPrediction`), the loop without friction (L0 alone), the
    critical point (-180 deg, 0 dB), the exclusion zone (+-6 dB, +-30 deg around it), frequency
    marks on every locus (labelled on L0) and the predicted limit cycles. Returns the figure."""
    fig, ax = (plt.subplots(figsize=(7, 6)) if ax is None else (ax.figure, ax))
    df = pred.df
    f = np.logspace(np.log10(df.freq_hz[0]), np.log10(df.freq_hz[-1]), n_freq)
    amps = df.amplitude_rad[::2] if amplitudes_rad is None else np.asarray(amplitudes_rad, float)

    def draw(h, **kw):
        ph = phase_deg(h)
        ph -= 360.0 * np.round((ph[len(ph) // 2] + 180.0) / 360.0)  # the branch around -180
        ax.plot(ph, gain_db(h, 1e-6), **kw)

    # exclusion zone: the usual 6 dB / 30 deg margin box around the critical point
    ax.add_patch(plt.Rectangle((-210, -6), 60, 12, facecolor="tab:red", alpha=0.12, edgecolor="tab:red",
                               linestyle="--", gid="exclusion-zone", label="exclusion zone (6 dB, 30 deg)"))
    marks = [x for x in (0.03, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0) if f[0] <= x <= f[-1]]

    def mark(h_of, color, text: bool):
        hm = h_of(np.asarray(marks))
        hf = h_of(f)
        ph_f = phase_deg(hf)
        ph_f -= 360.0 * np.round((ph_f[len(ph_f) // 2] + 180.0) / 360.0)
        ph_m = np.interp(np.log10(marks), np.log10(f), ph_f)
        g_m = 20 * np.log10(np.maximum(np.abs(hm), 1e-6))
        ax.plot(ph_m, g_m, "o", ms=3.5, color=color, gid="frequency-marks")
        if text:
            for x, y, fm in zip(ph_m, g_m, marks):
                ax.annotate(f"{fm:g} Hz", (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7)

    draw(pred.loop(f), color="k", lw=2, label="L0 (TVC = 1)")
    if marks:
        mark(pred.loop, "k", True)
    cmap = plt.get_cmap("plasma")
    for i, a in enumerate(amps):
        col = cmap(0.85 * i / max(len(amps) - 1, 1))   # (not the top of plasma: pale yellow on white)
        draw(pred.open_loop(a, f), color=col, lw=1, label=f"L0 N, A = {math.degrees(a):.3g} deg")
        if marks:
            mark(lambda x, a=a: pred.open_loop(a, x), col, False)
    ax.plot([-180], [0], "r+", ms=14, mew=2, label="critical point")
    for stable in (True, False):   # one marker per kind: every solution sits at the critical point
        cs = [c for c in pred.cycles if c.stable == stable]
        if cs:
            ax.plot([-180], [0], "o", mfc="none", mec="g" if stable else "m", ms=12 if stable else 16,
                    gid="stable-lco" if stable else "unstable-lco", label=cycles_label(cs, stable))
    ax.axhline(0, color="0.6", lw=0.5)
    ax.axvline(-180, color="0.6", lw=0.5)
    ax.set_xlim(-330, -30)
    ax.set_ylim(-25, 30)
    ax.set_xlabel("open-loop phase [deg]")
    ax.set_ylabel("open-loop gain [dB]")
    ax.set_title(f"FCS open loop with TVC describing function ({df.friction_model})", fontsize=11)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig


def cycles_label(cycles, stable: bool) -> str:
    """Legend text of the harmonic-balance solutions ``cycles`` of one kind: each one when there
    are at most three, else their number and the ranges of command amplitude and frequency."""
    kind = "stable LCO" if stable else "unstable solution (threshold)"
    if len(cycles) <= 3:
        return f"{kind}: " + "; ".join(f"{math.degrees(c.amplitude_rad):.3g} deg, {c.freq_hz:.3g} Hz" for c in cycles)
    a = [math.degrees(c.amplitude_rad) for c in cycles]
    f = [c.freq_hz for c in cycles]
    return (f"{len(cycles)} {kind}s: {min(a):.3g}-{max(a):.3g} deg, {min(f):.3g}-{max(f):.3g} Hz")


def plot_flight_histories(histories, labels=None, ax=None):
    """Engine angle [deg] against time [s] for one or more :class:`taos.flight.lco.FlightHistory`."""
    fig, ax = (plt.subplots(figsize=(8, 4)) if ax is None else (ax.figure, ax))
    for i, h in enumerate(histories):
        lab = labels[i] if labels else f"{h.friction_model}, K_L = {from_si(h.load_stiffness_N_per_m, 'N/m', 'lbf/in'):.0f} lbf/in"
        ax.plot(h.t_s, np.degrees(h.engine_rad), lw=0.8, label=lab)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("engine angle [deg]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
