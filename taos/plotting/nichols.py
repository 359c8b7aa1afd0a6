"""Nichols chart of the flight-control open loop with the TVC describing function (the seed
paper's figure 6), and flight-loop time histories (figures 7-8)."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from ..linear import gain_db
from ..units import from_si


def plot_lco_nichols(pred, amplitudes_rad=None, n_freq: int = 400, ax=None):
    """Nichols chart (phase [deg] vs gain [dB]) of L0 N(A, .) at several command amplitudes of
    ``pred`` (a :class:`taos.flight.lco.LcoPrediction`), the loop without friction (L0 alone), the
    critical point (-180 deg, 0 dB) and the predicted limit cycles. Returns the figure."""
    fig, ax = (plt.subplots(figsize=(7, 6)) if ax is None else (ax.figure, ax))
    df = pred.df
    f = np.logspace(np.log10(df.freq_hz[0]), np.log10(df.freq_hz[-1]), n_freq)
    amps = df.amplitude_rad[::2] if amplitudes_rad is None else np.asarray(amplitudes_rad, float)

    def draw(h, **kw):
        ph = np.degrees(np.unwrap(np.angle(h)))
        ph -= 360.0 * np.round((ph[len(ph) // 2] + 180.0) / 360.0)  # the branch around -180
        ax.plot(ph, gain_db(h, 1e-6), **kw)

    draw(pred.loop(f), color="k", lw=2, label="L0 (TVC = 1)")
    cmap = plt.get_cmap("plasma")
    for i, a in enumerate(amps):
        draw(pred.open_loop(a, f), color=cmap(i / max(len(amps) - 1, 1)), lw=1,
             label=f"L0 N, A = {math.degrees(a):.3g} deg")
    ax.plot([-180], [0], "r+", ms=14, mew=2, label="critical point")
    for c in pred.cycles:
        ax.plot([-180], [0], "o", mfc="none", mec="g" if c.stable else "m", ms=12,
                label=f"{'stable' if c.stable else 'unstable'} LCO {math.degrees(c.amplitude_rad):.3g} deg, "
                      f"{c.freq_hz:.3g} Hz")
    ax.axhline(0, color="0.6", lw=0.5)
    ax.axvline(-180, color="0.6", lw=0.5)
    ax.set_xlim(-330, -30)
    ax.set_ylim(-25, 30)
    ax.set_xlabel("open-loop phase [deg]")
    ax.set_ylabel("open-loop gain [dB]")
    ax.set_title(f"FCS open loop with TVC describing function ({df.friction_model})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig


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
