"""What flight shows: the loop broken at the PTI and the TVC command-to-piston response
reconstructed from a flight record (:class:`taos.flight.pti.PtiAnalysis`), with the model's linear
and friction-degraded predictions. Drawing only."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from taos.plotting import _common  # noqa: F401  (sets the headless backend)
from taos.plotting._common import finish_bode_axes


def _db(h):
    return 20 * np.log10(np.maximum(np.abs(h), 1e-300))


def _ph(f, h, ref=None):
    from taos.linear import phase_deg_continuous
    return phase_deg_continuous(f, h, ref)


def plot_pti(analysis, axis: str | None = None):
    """One row per PTI window of ``axis`` (default: every axis): left the open loop L (gain and
    phase, error bars 1 sigma), right the command-to-piston response [m/rad]; the linear model
    (line) and the describing-function model (dashed) overlaid; the verdict in the title.
    Returns the figure."""
    rs = [r for r in analysis.responses if axis is None or r.axis == axis]
    n = max(1, len(rs))
    fig, ax = plt.subplots(2 * n, 2, figsize=(12, 5.0 * n), squeeze=False, sharex="col")
    for i, r in enumerate(rs):
        f = r.freq_hz
        a = ax[2 * i:2 * i + 2]
        for col, (meas, sig, lin, df, name) in enumerate((
                (r.loop, r.loop_sigma, r.model.loop, r.model_loop_df, "open loop L (broken at the PTI)"),
                (r.piston, r.piston_sigma, r.model.piston, r.model_piston_df, "command to piston [m/rad]"))):
            ref = _ph(f, lin)
            a[0, col].plot(f, _db(lin), "k-", lw=1.2, label="model, linear")
            a[1, col].plot(f, ref, "k-", lw=1.2)
            if df is not None:
                a[0, col].plot(f, _db(df), "k--", lw=1.0, label="model, describing function")
                a[1, col].plot(f, _ph(f, df, ref), "k--", lw=1.0)
            e = 20 / np.log(10) * np.nan_to_num(sig)
            a[0, col].errorbar(f, _db(meas), yerr=e, fmt="o", ms=4, color="C3", label="flight record")
            a[1, col].errorbar(f, _ph(f, meas, ref), yerr=np.degrees(np.nan_to_num(sig)), fmt="o", ms=4, color="C3")
            a[0, col].set_ylabel("gain [dB]")
            a[1, col].set_ylabel("phase [deg]")
            a[0, col].set_title(f"{r.axis} {r.kind} {r.start_s:g}-{r.end_s:g} s: {name}", fontsize=9)
        a[0, 0].legend(fontsize=8)
        import textwrap
        a[1, 0].set_title("\n".join(textwrap.wrap(r.friction()["verdict"], 90)), fontsize=7)
        finish_bode_axes(a)
    fig.tight_layout()
    return fig
