"""Bode plots of command -> piston and command -> engine responses (families by amplitude).

Layout: 2 x 2 axes, left column command -> piston (gain, phase), right column command ->
engine angle (gain, phase); frequency [Hz] on a log axis, gain [dB], phase [deg].

Piston gain: with ``moment_arm_m`` R given, the plotted quantity is x_p / theta_c in
``length_unit`` per deg, i.e. 20 log10(|H_p| R (pi/180) / unit) [dB re 1 unit/deg], where
H_p = x_p / (R theta_c) is the stored dimensionless gain; without R it is H_p itself [dB].
Engine gain theta / theta_c [dB]. Markers: the notch of the command -> piston gain (the load
resonance seen by the actuator, paper eq. 1 and sec. 2.2) and a vertical line at the load
resonance w_L = sqrt((K_L R^2 + K_n) / J_n) / 2 pi when ``resonance_hz`` is given.

Artists carry ``gid`` tags so tests and tools can find them: "response" (one curve per
response per panel), "data" (measured points), "notch", "load-resonance".
"""

from __future__ import annotations

import math

import numpy as np

from ._common import LENGTH_UNITS, finish_bode_axes, legend_once, use_grid_layout, wrapped_title  # (sets the Agg backend)
from ..errors import InputError
from ..linear import gain_db, phase_deg, phase_deg_continuous, sampled_notch_hz

import matplotlib.pyplot as plt  # noqa: E402


def _check_unit(length_unit: str) -> float:
    if length_unit not in LENGTH_UNITS:
        raise InputError("plot", "length_unit", f"one of {', '.join(LENGTH_UNITS)}", got=repr(length_unit))
    return LENGTH_UNITS[length_unit]


def piston_scale(length_unit: str, moment_arm_m: float | None) -> tuple[float, str]:
    """(factor, label): factor turns the stored x_p/(R theta_c) into the plotted quantity."""
    unit_m = _check_unit(length_unit)
    if moment_arm_m is None:
        return 1.0, "x_p / (R θ_c)"
    return moment_arm_m * math.pi / 180.0 / unit_m, f"x_p / θ_c [{length_unit}/deg]"


def response_label(fr) -> str:
    if fr.amplitude_rad is None:
        return "linear"
    return f"{math.degrees(fr.amplitude_rad):.3g} deg ({fr.friction_model})"


def reference_response(responses):
    """The response used for the notch and for phase alignment: linear first, then densest."""
    return max(responses, key=lambda r: (r.amplitude_rad is None, np.size(r.freq_hz)))


def new_bode_figure(title: str | None = None, piston_label: str = "x_p / (R θ_c)"):
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    use_grid_layout(fig, ax)
    # y = 1.0, where matplotlib's automatic placement puts it (x tick labels at the bottom): a
    # fixed title skips the tight box of the y axes (a second tick update) at every draw
    ax[0, 0].set_title("command → piston", y=1.0)
    ax[0, 1].set_title("command → engine angle", y=1.0)
    ax[0, 0].set_ylabel(f"gain [dB]  ({piston_label})")
    ax[0, 1].set_ylabel("gain [dB]  (θ / θ_c)")
    ax[1, 0].set_ylabel("phase [deg]")
    ax[1, 1].set_ylabel("phase [deg]")
    finish_bode_axes(ax)
    if title:
        fig.suptitle(wrapped_title(fig, title))
    return fig, ax


def draw_response(ax, fr, scale: float, *, color, label: str, gid: str = "response", marker=None,
                  linestyle="-", ref=None):
    """Draw one response on a 2 x 2 Bode axes array; ``ref`` = reference response for phase
    alignment: each phase point on the 360-deg branch nearest the reference's unwrapped phase
    (:func:`taos.linear.phase_deg_continuous`; sparse sine-dwell points cannot be unwrapped on
    their own)."""
    f = np.asarray(fr.freq_hz, float)
    if marker is None:
        marker = None if fr.amplitude_rad is None and f.size > 12 else "o"
    kw = dict(color=color, marker=marker, markersize=4, linestyle=linestyle, gid=gid)
    ax[0, 0].plot(f, gain_db(np.asarray(fr.piston) * scale), label=label, **kw)
    rf = rp = re = None
    if ref is not None and ref is not fr:
        rf = np.asarray(ref.freq_hz, float)
        rp, re = phase_deg(ref.piston), phase_deg(ref.engine)
    ax[1, 0].plot(f, phase_deg_continuous(f, fr.piston, rp, rf), **kw)
    held = fr.engine_held() if hasattr(fr, "engine_held") else np.zeros(f.size, bool)
    ax[0, 1].plot(f, np.where(held, np.nan, gain_db(fr.engine)), label=label, **kw)
    ax[1, 1].plot(f, np.where(held, np.nan, phase_deg_continuous(f, fr.engine, re, rf)), **kw)
    if held.any():  # no motion is not a number: say so on the plot, one line per response, stacked
        n = sum(1 for t in ax[0, 1].texts if t.get_gid() == "engine-held")
        ax[0, 1].text(0.02, 0.04 + 0.06 * n, f"engine held (no motion) at {', '.join(f'{x:g}' for x in f[held])} Hz, "
                      f"{label}", transform=ax[0, 1].transAxes, fontsize=8, color=kw["color"], gid="engine-held")


def mark_resonance(ax, resonance_hz: float, color="0.3", label_prefix: str = "") -> None:
    for i, a in enumerate(ax.flat):
        a.axvline(resonance_hz, color=color, linestyle="--", linewidth=1, gid="load-resonance",
                  label=(f"{label_prefix}load resonance {resonance_hz:.2f} Hz" if i == 0 else None))


def mark_notch(ax, fr, notch_hz: float, scale: float, color="k", label_prefix: str = "") -> None:
    """Marker on the piston gain at ``notch_hz`` (gain interpolated on the response in log f)."""
    f = np.asarray(fr.freq_hz, float)
    g = gain_db(np.asarray(fr.piston) * scale)
    y = float(np.interp(math.log10(notch_hz), np.log10(f), g))
    ax[0, 0].plot([notch_hz], [y], marker="v", markersize=10, color=color, linestyle="none", gid="notch",
                  label=f"{label_prefix}notch {notch_hz:.2f} Hz")


def plot_freqresp(responses, resonance_hz: float | None = None, length_unit: str = "in", *,
                  moment_arm_m: float | None = None, notch_hz: float | None | bool = None,
                  title: str | None = None, data=None, data_label: str = "data"):
    """Bode families of ``responses`` (list of :class:`~taos.planar.freqresp.FrequencyResponse`).

    Parameters
    ----------
    responses : list of FrequencyResponse
        One curve each (linear: black line; sine dwell: one colour per amplitude, markers).
    resonance_hz : float, optional
        Load resonance [Hz]: a dashed vertical line on every panel.
    length_unit : {'in', 'mm', 'm'}
        Piston length unit when ``moment_arm_m`` is given.
    moment_arm_m : float, optional
        Moment arm R [m]; turns the piston gain into length_unit/deg.
    notch_hz : float, optional
        Notch frequency [Hz] to mark on the piston gain. None: located on the densest
        response's grid (:func:`taos.linear.sampled_notch_hz`); False: no marker.
    title : str, optional
    data : list of FrequencyResponse, optional
        Measured points drawn as open circles (gid "data"), labelled ``data_label``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    responses = list(responses)
    if not responses:
        raise InputError("plot", "responses", "at least one frequency response", got="none")
    scale, plabel = piston_scale(length_unit, moment_arm_m)
    ref = reference_response(responses)
    fig, ax = new_bode_figure(title, plabel)
    amps = sorted({fr.amplitude_rad for fr in responses if fr.amplitude_rad is not None})
    cmap = plt.get_cmap("viridis")
    for fr in responses:
        if fr.amplitude_rad is None:
            color = "k"
        else:
            color = cmap(0.15 + 0.7 * amps.index(fr.amplitude_rad) / max(1, len(amps) - 1))
        draw_response(ax, fr, scale, color=color, label=response_label(fr), ref=ref)
    for fr in data or []:
        draw_response(ax, fr, scale, color="tab:red", label=f"{data_label} {response_label(fr)}", gid="data",
                      marker="o", linestyle="none", ref=ref)
        for line in ax[0, 0].lines[-1:] + ax[0, 1].lines[-1:] + ax[1, 0].lines[-1:] + ax[1, 1].lines[-1:]:
            line.set_markerfacecolor("none")
    if resonance_hz is not None:
        mark_resonance(ax, resonance_hz)
    if notch_hz is not False:
        nf = sampled_notch_hz(ref.freq_hz, ref.piston) if notch_hz is None else float(notch_hz)
        if math.isfinite(nf):
            mark_notch(ax, ref, nf, scale)
    legend_once(fig, ax[0, 0], fontsize=8, loc="best")
    return fig
