"""Side-by-side overlays of two (or more) model conditions, e.g. ambient vs hot fire.

:func:`plot_compare_freqresp`: the Bode layout of :mod:`taos.plotting.bode` with one colour per
condition, the linear response as a line and sine-dwell responses as dashed lines with markers,
each condition's load resonance as a dashed vertical line and its piston notch as a marker
(the notch moves up with load stiffness: w_L = sqrt((K_L R^2 + K_n) / J_n), paper sec. 2.2),
optional test data as open circles.

:func:`plot_compare_timehist`: piston position, engine angle and friction torque of one axis
of two runs overlaid.
"""

from __future__ import annotations

import math

import numpy as np

from . import bode
from ._common import legend_once, use_grid_layout, wrapped_title
from ..linear import sampled_notch_hz
from .timehist import units

import matplotlib.pyplot as plt  # noqa: E402

COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple")


def plot_compare_freqresp(sets, *, resonance_hz=None, notch_hz=None, data=None, length_unit: str = "in",
                          moment_arm_m: float | None = None, title: str | None = None):
    """Overlay frequency-response families of several conditions.

    Parameters
    ----------
    sets : mapping label -> list of FrequencyResponse
        E.g. {"ambient": [linear, dwell_0.4deg], "hot fire": [...]}.
    resonance_hz : mapping label -> float, optional
        Load resonance per condition [Hz] (dashed line in the condition's colour).
    notch_hz : mapping label -> float, optional
        Piston notch per condition [Hz]; default located on each condition's densest response.
    data : mapping label -> FrequencyResponse, optional
        Test data per condition (open circles).
    length_unit, moment_arm_m : see :func:`taos.plotting.bode.plot_freqresp`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale, plabel = bode.piston_scale(length_unit, moment_arm_m)
    fig, ax = bode.new_bode_figure(title, plabel)
    for k, (label, rs) in enumerate(sets.items()):
        c = COLOURS[k % len(COLOURS)]
        rs = list(rs)
        ref = bode.reference_response(rs) if rs else None
        for fr in rs:
            dwell = fr.amplitude_rad is not None
            bode.draw_response(ax, fr, scale, color=c, label=f"{label}: {bode.response_label(fr)}",
                               linestyle="--" if dwell else "-", ref=ref)
        if resonance_hz and label in resonance_hz:
            bode.mark_resonance(ax, resonance_hz[label], color=c, label_prefix=f"{label}: ")
        if rs:
            nf = notch_hz[label] if notch_hz and label in notch_hz else sampled_notch_hz(ref.freq_hz, ref.piston)
            if math.isfinite(nf):
                bode.mark_notch(ax, ref, nf, scale, color=c, label_prefix=f"{label}: ")
        if data and label in data:
            bode.draw_response(ax, data[label], scale, color=c, label=f"{label}: data", gid="data",
                               marker="o", linestyle="none", ref=ref)
            for a in ax.flat:
                a.lines[-1].set_markerfacecolor("none")
    legend_once(fig, ax[0, 0], fontsize=7, loc="best")
    return fig


def plot_compare_timehist(runs, axis: str = "pitch", length_unit: str = "in", angle_unit: str = "deg", *,
                          t_range_s=None, title: str | None = None):
    """Overlay piston, engine angle and friction torque of ``axis`` for runs {label: TimeHistory}."""
    m_per, rad_per, tname, nm_per = units(length_unit, angle_unit)
    fig, ax = plt.subplots(3, 1, figsize=(11, 7), sharex=True)
    use_grid_layout(fig, ax)
    for k, (label, th) in enumerate(runs.items()):
        c = COLOURS[k % len(COLOURS)]
        i = th.axes.index(axis)
        t = np.asarray(th.t_s)
        w = slice(None) if t_range_s is None else (t >= t_range_s[0]) & (t <= t_range_s[1])
        ax[0].plot(t[w], th.piston_m[i][w] / m_per, color=c, label=label, gid=f"piston:{label}")
        ax[1].plot(t[w], th.engine_rad[i][w] / rad_per, color=c, label=label, gid=f"engine:{label}")
        ax[2].plot(t[w], th.friction_torque_Nm[i][w] / nm_per, color=c, label=label, gid=f"friction:{label}")
    ax[0].set_ylabel(f"piston x_p [{length_unit}]")
    ax[1].set_ylabel(f"engine angle θ [{angle_unit}]")
    ax[2].set_ylabel(f"friction torque T_f [{tname}]")
    ax[2].set_xlabel("time [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8, loc="upper right")
    fig.suptitle(wrapped_title(fig, title or f"{axis}: " + " vs ".join(runs)))
    return fig


def plot_compare3d(curves, title: str | None = None):
    """The paper's Figure 11 analogue: test data (markers) against the 3-D TAOS fit (lines through
    the fitted points) for each condition, piston x_p/(R theta_c) and engine theta/theta_c gain
    [dB] and phase [deg]; ``curves`` from :func:`taos.identify.compare3d.comparison3d_curves`."""
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    labels = sorted({c["label"] for c in curves}, key=[c["label"] for c in curves].index)
    styles = {"pitch": "o", "yaw": "s"}
    for c in curves:
        col = COLOURS[labels.index(c["label"]) % len(COLOURS)]
        for j, key in enumerate(("piston", "engine")):
            if key not in c:
                continue
            v = c[key]
            name = f"{c['label']} {c['axis']}"
            ax[0, j].semilogx(c["freq_hz"], v["fit_db"], "-", color=col, alpha=0.7, label=f"{name}: 3-D fit")
            ax[0, j].semilogx(c["freq_hz"], v["data_db"], styles.get(c["axis"], "o"), mfc="none", color=col,
                              label=f"{name}: data")
            ax[1, j].semilogx(c["freq_hz"], v["fit_deg"], "-", color=col, alpha=0.7)
            ax[1, j].semilogx(c["freq_hz"], v["data_deg"], styles.get(c["axis"], "o"), mfc="none", color=col)
    for j, key in enumerate(("piston x_p/(R theta_c)", "engine theta/theta_c")):
        ax[0, j].set_title(key)
        ax[0, j].set_ylabel("gain [dB]")
        ax[1, j].set_ylabel("phase [deg]")
        ax[1, j].set_xlabel("frequency [Hz]")
        for a in ax[:, j]:
            a.grid(True, which="both", alpha=0.3)
    ax[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(title or "Data against the 3-D TAOS fit (Figure 11 analogue)")
    fig.tight_layout()
    return fig
