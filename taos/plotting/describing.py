"""Describing-function plots: gain and phase families of N(A, w), one curve per amplitude."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from ..units import from_si


def plot_df_map(df, which: str = "engine", title: str | None = None, ax=None):
    """Gain [dB] and phase [deg] of ``df`` (a :class:`taos.flight.describing.DescribingFunctionMap`)
    against frequency [Hz], one curve per command amplitude. Returns the figure."""
    if ax is None:
        fig, (ag, ap) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    else:
        ag, ap = ax
        fig = ag.figure
    g = df.gain_db(which)
    p = df.phase_deg(which)
    cmap = plt.get_cmap("viridis")
    n = len(df.amplitude_rad)
    for i, a in enumerate(df.amplitude_rad):
        c = cmap(i / max(n - 1, 1))
        lab = f"{math.degrees(a):.3g} deg"
        ag.semilogx(df.freq_hz, g[i], "o-", ms=3, color=c, label=lab)
        ap.semilogx(df.freq_hz, np.where(g[i] > -100, p[i], np.nan), "o-", ms=3, color=c)
    ag.set_ylabel(f"{which} gain [dB]")
    ap.set_ylabel(f"{which} phase [deg]")
    ap.set_xlabel("frequency [Hz]")
    ag.set_ylim(max(ag.get_ylim()[0], -40), ag.get_ylim()[1])
    for a in (ag, ap):
        a.grid(True, which="both", alpha=0.3)
    ag.legend(fontsize=7, ncol=2, title="command amplitude", title_fontsize=7)
    ag.set_title(title or f"TVC describing function N(A, w): {df.friction_model}, "
                 f"K_L = {from_si(df.load_stiffness_N_per_m, 'N/m', 'lbf/in'):.0f} lbf/in")
    fig.tight_layout()
    return fig

