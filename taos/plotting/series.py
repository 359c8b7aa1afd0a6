"""Plots of a series of test records (thin layers over :class:`taos.identify.series.RecordSeries`).

* :func:`plot_series_responses`: the estimated command -> piston responses of every record
  overlaid (gain in dB re 1 in/deg and phase; one colour per record, open circles), each with
  its fitted model at the same points and amplitudes (crosses joined by a line: describing
  function with the fit's time-domain correction) and the fitted model's exact linear response
  (dotted, friction-free), one column per axis.
* :func:`plot_series_trend`: each fitted quantity (K_L, friction level, notch per axis) against
  the record order or the test date, with 1-sigma error bars and the weighted straight line.

Artists carry ``gid`` tags: "data", "model", "linear", "trend", "estimate".
"""

from __future__ import annotations

import numpy as np

from ._common import wrapped_title  # (importing _common also sets the Agg backend)
from ..linear import gain_db, phase_deg, phase_deg_continuous
from ..units import from_si

import matplotlib.pyplot as plt  # noqa: E402

IN_PER_DEG = from_si(1.0, "m/rad", "in/deg")   # (m/rad) -> (in/deg)
#: readable names of the trend quantities
TITLES = {"load_stiffness": "load stiffness K_L", "coulomb_torque": "friction level (Coulomb torque T_c)",
          "notch_pitch_hz": "piston notch, pitch", "notch_yaw_hz": "piston notch, yaw"}


def _colours(n: int):
    cmap = plt.get_cmap("viridis")
    return [cmap(0.05 + 0.85 * k / max(1, n - 1)) for k in range(n)]


def plot_series_responses(series, curves: dict, title: str | None = None):
    """Every record's measured piston response and its fitted linear curve (``curves`` from
    :func:`taos.identify.series.series_curves`)."""
    axes = sorted({r.axis for rec in series.records for r in rec.responses})
    fig, ax = plt.subplots(2, len(axes), figsize=(6.5 * len(axes), 7), sharex=True, squeeze=False,
                           constrained_layout=True)
    for c, rec in zip(_colours(len(series.records)), series.records):
        for j, axis in enumerate(axes):
            lin = curves[rec.label].get(axis)
            ref_f = ref_ph = None
            if lin is not None:
                R = rec.fit.model.actuator.moment_arm_m
                ref_f, ref_ph = np.asarray(lin.freq_hz), phase_deg(lin.piston)
                ax[0, j].plot(lin.freq_hz, gain_db(lin.piston * R * IN_PER_DEG), ":", color=c, lw=1, gid="linear")
                ax[1, j].plot(lin.freq_hz, ref_ph, ":", color=c, lw=1, gid="linear")
            for d, mp in zip(rec.fit.data, rec.fit.fitted_piston):
                if d.axis != axis:
                    continue
                ax[0, j].plot(d.freq_hz, gain_db(d.piston_m_per_rad * IN_PER_DEG), "o", mfc="none", color=c,
                              gid="data")
                ax[1, j].plot(d.freq_hz, phase_deg_continuous(d.freq_hz, d.piston_m_per_rad, ref_ph, ref_f), "o",
                              mfc="none", color=c, gid="data")
                ax[0, j].plot(d.freq_hz, gain_db(mp * IN_PER_DEG), "x-", lw=0.8, ms=5, color=c, gid="model")
                ax[1, j].plot(d.freq_hz, phase_deg_continuous(d.freq_hz, mp, ref_ph, ref_f), "x-", lw=0.8, ms=5,
                              color=c, gid="model")
    for j, axis in enumerate(axes):
        ax[0, j].set_title(f"command → piston ({axis})")
        ax[0, j].set_ylabel("gain [dB re 1 in/deg]")
        ax[1, j].set_ylabel("phase [deg]")
        ax[1, j].set_xlabel("frequency [Hz]")
    for a in ax.flat:
        a.set_xscale("log")
        a.grid(True, which="both", alpha=0.3)
    _legend(fig, ax[0, -1], series)
    fig.suptitle(wrapped_title(fig, title or f"{len(series.records)} records: estimated responses and fits"))
    return fig


def _legend(fig, a, series) -> None:
    """One entry per record (its colour; a colour bar over the record order beyond 10 records)
    and one per style: data, fitted model at the data, fitted linear response."""
    from matplotlib.lines import Line2D

    cols = _colours(len(series.records))
    styles = [Line2D([], [], color="0.4", marker="o", mfc="none", ls="none", label="data"),
              Line2D([], [], color="0.4", marker="x", lw=0.8, label="fitted model at the data's amplitudes"),
              Line2D([], [], color="0.4", ls=":", lw=1, label="fitted model, linear (no friction)")]
    if len(series.records) <= 10:
        recs = [Line2D([], [], color=c, lw=3, label=r.label) for c, r in zip(cols, series.records)]
        a.legend(handles=recs + styles, fontsize=7, loc="lower left")
        return
    import matplotlib as mpl

    sm = mpl.cm.ScalarMappable(cmap="viridis", norm=mpl.colors.Normalize(1, len(series.records)))
    fig.colorbar(sm, ax=a, label=f"record (1 = {series.records[0].label})")
    a.legend(handles=styles, fontsize=7, loc="lower left")


def plot_series_trend(series, title: str | None = None):
    """Each quantity over the series with 1-sigma error bars and its weighted straight line."""
    names = series.quantity_names
    ncol = 2
    nrow = (len(names) + ncol - 1) // ncol
    fig, ax = plt.subplots(nrow, ncol, figsize=(11, 3.2 * nrow), squeeze=False, constrained_layout=True)
    for a, n in zip(ax.flat, names):
        recs = [r for r in series.records if n in r.quantities]
        x = np.array([r.x for r in recs])
        y = np.array([r.quantities[n].value for r in recs])
        s = np.array([r.quantities[n].std_error for r in recs])
        unit = recs[0].quantities[n].unit
        a.errorbar(x, y, yerr=s, fmt="o", capsize=4, color="tab:blue", gid="estimate", label="fit +- 1 sigma")
        for xi, yi, r in zip(x, y, recs):
            a.annotate(r.label, (xi, yi), textcoords="offset points", xytext=(4, 6), fontsize=7)
        t = series.trends[n]
        if np.isfinite(t.slope):
            xx = np.linspace(x.min(), x.max(), 50)
            a.plot(xx, t.intercept + t.slope * xx, "--", color="tab:red", gid="trend",
                   label=f"trend {t.slope:.4g} +- {t.slope_std_error:.2g} {unit}/x")
        a.set_title(TITLES.get(n, n))
        a.set_ylabel(f"[{unit}]")
        a.set_xlabel(series.x_label)
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    for a in list(ax.flat)[len(names):]:
        a.set_visible(False)
    fig.suptitle(wrapped_title(fig, title or "fitted parameters across the series"))
    return fig
