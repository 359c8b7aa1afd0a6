"""Plots of fits and of condition comparisons (thin layers over result objects).

* :func:`plot_fit`: measured responses (open circles) and the fitted model at the same points
  (crosses) with the fitted model's exact linear response (grey line), command -> piston
  (in/deg) and command -> engine, gain and phase, and the normalised residuals
  (ln|H_m/H_d| and arg(H_m/H_d) over their 1-sigma errors) in the bottom row.
* :func:`plot_compare_side_by_side`: the paper's fig. 2 layout, command -> piston gain and
  phase for condition A (left) and B (right): model lines, data circles, notch markers.
* :func:`plot_compare_overlay`: fig. 11 style, both conditions overlaid on one Bode layout.

Artists carry ``gid`` tags: "data", "model", "linear", "notch", "residual".
"""

from __future__ import annotations

import math

import numpy as np

from ._common import finish_bode_axes, use_grid_layout, wrapped_title  # (importing _common also sets the Agg backend)
from ..linear import gain_db as _db
from ..linear import phase_deg, phase_deg_continuous
from ..units import from_si

import matplotlib.pyplot as plt  # noqa: E402

COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple")
IN_PER_DEG = from_si(1.0, "m/rad", "in/deg")   # (m/rad) -> (in/deg)


def _ph(h, ref_f, ref_ph, f):
    """Phase [deg] of sparse points, each on the 360-deg branch nearest the dense reference."""
    return phase_deg_continuous(f, h, ref_ph, ref_f)


def plot_fit(result, linear: dict, title: str | None = None):
    """Data vs fitted model and residuals of a :class:`taos.identify.fit.FitResult`;
    ``linear`` maps axis -> the fitted model's linear FrequencyResponse
    (:func:`taos.identify.fit.fitted_linear_curves`)."""
    has_e = any(e is not None for e in result.fitted_engine)
    ncol = 2 if has_e else 1
    fig, ax = plt.subplots(3, ncol, figsize=(6 * ncol + 1, 9), sharex=True, squeeze=False)
    use_grid_layout(fig, ax)
    R = result.model.actuator.moment_arm_m
    for k, ax_name in enumerate(sorted(linear)):
        lin = linear[ax_name]
        fl = lin.freq_hz
        lp = phase_deg(lin.piston)
        le = phase_deg(lin.engine)
        ls = "-" if k == 0 else "--"
        ax[0, 0].plot(fl, _db(lin.piston * R * IN_PER_DEG), color="0.6", ls=ls, gid="linear",
                      label=f"fitted model, linear ({ax_name})")
        ax[1, 0].plot(fl, lp, color="0.6", ls=ls, gid="linear")
        if has_e:
            ax[0, 1].plot(fl, _db(lin.engine), color="0.6", ls=ls, gid="linear", label=f"linear ({ax_name})")
            ax[1, 1].plot(fl, le, color="0.6", ls=ls, gid="linear")
        for j, d in enumerate(result.data):
            if d.axis != ax_name:
                continue
            c = COLOURS[j % len(COLOURS)]
            lab = f"{d.axis} {d.condition or ''} ({d.method})".replace("  ", " ")
            hp, mp = d.piston_m_per_rad, result.fitted_piston[j]
            ax[0, 0].plot(d.freq_hz, _db(hp * IN_PER_DEG), "o", mfc="none", color=c, gid="data", label=f"data {lab}")
            ax[0, 0].plot(d.freq_hz, _db(mp * IN_PER_DEG), "x", color=c, gid="model", label=f"model {lab}")
            ax[1, 0].plot(d.freq_hz, _ph(hp, fl, lp, d.freq_hz), "o", mfc="none", color=c, gid="data")
            ax[1, 0].plot(d.freq_hz, _ph(mp, fl, lp, d.freq_hz), "x", color=c, gid="model")
            sp = np.maximum(d.sigma_piston, 1e-3)
            ax[2, 0].plot(d.freq_hz, np.log(np.abs(mp / hp)) / sp, "o", color=c, gid="residual", label="ln gain")
            ax[2, 0].plot(d.freq_hz, np.angle(mp / hp) / sp, "s", mfc="none", color=c, gid="residual", label="phase")
            if has_e and d.engine is not None and result.fitted_engine[j] is not None:
                he, me = d.engine, result.fitted_engine[j]
                ax[0, 1].plot(d.freq_hz, _db(he), "o", mfc="none", color=c, gid="data")
                ax[0, 1].plot(d.freq_hz, _db(me), "x", color=c, gid="model")
                ax[1, 1].plot(d.freq_hz, _ph(he, fl, le, d.freq_hz), "o", mfc="none", color=c, gid="data")
                ax[1, 1].plot(d.freq_hz, _ph(me, fl, le, d.freq_hz), "x", color=c, gid="model")
                se = np.maximum(d.sigma_engine, 1e-3)
                ax[2, 1].plot(d.freq_hz, np.log(np.abs(me / he)) / se, "o", color=c, gid="residual")
                ax[2, 1].plot(d.freq_hz, np.angle(me / he) / se, "s", mfc="none", color=c, gid="residual")
        nf = result.notch_hz.get(ax_name)
        if nf:
            ax[0, 0].axvline(nf, color="k", ls=":", lw=1, gid="notch", label=f"notch {ax_name} {nf:.3f} Hz")
    ax[0, 0].set_title("command → piston")
    ax[0, 0].set_ylabel("gain [dB re 1 in/deg]")
    ax[1, 0].set_ylabel("phase [deg]")
    ax[2, 0].set_ylabel("residual [σ]  (● ln gain, □ phase)")
    if has_e:
        ax[0, 1].set_title("command → engine angle (DC level not used)")
        ax[0, 1].set_ylabel("gain [dB]")
    for a in ax.flat:
        a.set_xscale("log")
        a.grid(True, which="both", alpha=0.3)
    for a in ax[2]:
        a.axhline(0, color="k", lw=0.8)
        a.set_xlabel("frequency [Hz]")
    ax[0, 0].legend(fontsize=7)
    txt = "  ".join(f"{n} = {result.eng(i):.5g} ± {abs(result.eng(i, result.values[i] + result.std_errors[i]) - result.eng(i)):.2g}"
                    f" {unit}" for i, (n, unit) in enumerate(zip(result.names, result.units())))
    fig.suptitle(wrapped_title(fig, title or f"fit: {txt}", 10), fontsize=10)
    return fig


def plot_compare_side_by_side(curves):
    """Command -> piston gain and phase (in/deg), condition A left, B right (paper fig. 2);
    ``curves`` from :func:`taos.identify.compare.comparison_curves`."""
    fig, ax = plt.subplots(2, 2, figsize=(12, 7), sharex=True)
    use_grid_layout(fig, ax)
    for k, cc in enumerate(curves):
        axis = cc.axis
        R = cc.moment_arm_m
        lin, dwell = cc.linear, cc.dwell
        lp = phase_deg(lin.piston)
        ax[0, k].plot(lin.freq_hz, _db(lin.piston * R * IN_PER_DEG), "k-", gid="linear", label="model, linear")
        ax[1, k].plot(lin.freq_hz, lp, "k-", gid="linear")
        for j, fr in enumerate(dwell):
            c = plt.get_cmap("viridis")(0.2 + 0.6 * j / max(1, len(dwell) - 1))
            lab = f"model, {math.degrees(fr.amplitude_rad):.2g} deg sine dwell"
            ax[0, k].plot(fr.freq_hz, _db(fr.piston * R * IN_PER_DEG), "-", color=c, gid="model", label=lab)
            ax[1, k].plot(fr.freq_hz, _ph(fr.piston, lin.freq_hz, lp, fr.freq_hz), "-", color=c, gid="model")
        for d in cc.data:
            ax[0, k].plot(d.freq_hz, _db(d.piston_m_per_rad * IN_PER_DEG), "o", mfc="none", color="tab:red",
                          gid="data", label=f"test data ({d.method})")
            ax[1, k].plot(d.freq_hz, _ph(d.piston_m_per_rad, lin.freq_hz, lp, d.freq_hz), "o", mfc="none",
                          color="tab:red", gid="data")
        nf = cc.notch_hz
        y = float(np.interp(np.log10(nf), np.log10(lin.freq_hz), _db(lin.piston * R * IN_PER_DEG)))
        ax[0, k].plot([nf], [y], "v", color="k", ms=9, gid="notch", label=f"notch {nf:.2f} Hz")
        ax[0, k].set_title(f"{cc.label}: command → piston ({axis})\nK_L = "
                           f"{from_si(cc.load_stiffness_N_per_m, 'N/m', 'lbf/in'):.4g} lbf/in", fontsize=10)
        ax[0, k].legend(fontsize=7)
    ax[0, 0].set_ylabel("gain [dB re 1 in/deg]")
    ax[1, 0].set_ylabel("phase [deg]")
    finish_bode_axes(ax)
    return fig


def plot_compare_overlay(curves):
    """Both conditions on one Bode layout: piston (in/deg) and engine, gain and phase;
    ``curves`` from :func:`taos.identify.compare.comparison_curves`."""
    fig, ax = plt.subplots(2, 2, figsize=(12, 7), sharex=True)
    use_grid_layout(fig, ax)
    for k, cc in enumerate(curves):
        c = COLOURS[k]
        axis = cc.axis
        R = cc.moment_arm_m
        lin, dwell = cc.linear, cc.dwell
        lp = phase_deg(lin.piston)
        le = phase_deg(lin.engine)
        lab = cc.label
        ax[0, 0].plot(lin.freq_hz, _db(lin.piston * R * IN_PER_DEG), "-", color=c, gid="linear", label=f"{lab}: linear")
        ax[1, 0].plot(lin.freq_hz, lp, "-", color=c, gid="linear")
        ax[0, 1].plot(lin.freq_hz, _db(lin.engine), "-", color=c, gid="linear", label=f"{lab}: linear")
        ax[1, 1].plot(lin.freq_hz, le, "-", color=c, gid="linear")
        for fr in dwell:
            ax[0, 0].plot(fr.freq_hz, _db(fr.piston * R * IN_PER_DEG), "--", color=c, gid="model",
                          label=f"{lab}: {math.degrees(fr.amplitude_rad):.2g} deg")
            ax[1, 0].plot(fr.freq_hz, _ph(fr.piston, lin.freq_hz, lp, fr.freq_hz), "--", color=c, gid="model")
            ax[0, 1].plot(fr.freq_hz, _db(fr.engine), "--", color=c, gid="model")
            ax[1, 1].plot(fr.freq_hz, _ph(fr.engine, lin.freq_hz, le, fr.freq_hz), "--", color=c, gid="model")
        for d in cc.data:
            ax[0, 0].plot(d.freq_hz, _db(d.piston_m_per_rad * IN_PER_DEG), "o", mfc="none", color=c, gid="data",
                          label=f"{lab}: data")
            ax[1, 0].plot(d.freq_hz, _ph(d.piston_m_per_rad, lin.freq_hz, lp, d.freq_hz), "o", mfc="none", color=c,
                          gid="data")
            if d.engine is not None:
                ax[0, 1].plot(d.freq_hz, _db(d.engine), "o", mfc="none", color=c, gid="data")
                ax[1, 1].plot(d.freq_hz, _ph(d.engine, lin.freq_hz, le, d.freq_hz), "o", mfc="none", color=c,
                              gid="data")
        nf = cc.notch_hz
        ax[0, 0].axvline(nf, color=c, ls=":", lw=1, gid="notch", label=f"{lab}: notch {nf:.2f} Hz")
    ax[0, 0].set_title(f"command → piston ({axis})")
    ax[0, 1].set_title(f"command → engine angle ({axis})")
    ax[0, 0].set_ylabel("gain [dB re 1 in/deg]")
    ax[0, 1].set_ylabel("gain [dB]")
    for a in ax[1]:
        a.set_ylabel("phase [deg]")
        a.set_xlabel("frequency [Hz]")
    for a in ax.flat:
        a.set_xscale("log")
        a.grid(True, which="both", alpha=0.3)
    ax[0, 0].legend(fontsize=7)
    fig.suptitle(wrapped_title(fig, f"{curves[0].label} vs {curves[1].label}"))
    return fig
