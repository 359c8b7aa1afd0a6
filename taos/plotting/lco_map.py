"""LCO verdict map: engine LCO amplitude where a cycle is predicted, remaining margin where not,
over one or two swept parameters (:class:`taos.flight.lco_map.LcoMap`)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np


def plot_lco_map(m, title: str | None = None):
    """One parameter: engine amplitude [deg] and margin [dB] against the value. Two
    parameters: a cell grid, cycles coloured by engine amplitude, no-cycle cells labelled with
    their margin, the flip between them outlined. Returns the figure."""
    fig, ax = plt.subplots(figsize=(7, 5))
    a0 = m.axes[0]
    if len(m.axes) == 1:
        x = np.asarray(a0.values)
        ax.plot(x, m.engine_amplitude_deg, "o-", color="C3", label="LCO engine amplitude [deg]")
        ax2 = ax.twinx()
        ax2.plot(x, np.where(m.lco, np.nan, m.margin_db), "s--", color="C0", label="remaining margin [dB]")
        ax2.set_ylabel("remaining margin (no LCO) [dB]", color="C0")
        ax.set_ylabel("LCO engine amplitude [deg]", color="C3")
        ax.set_xlabel(f"{a0.name} [{a0.unit}]")
        ax.set_xscale("log")
    else:
        a1 = m.axes[1]
        amp = np.where(m.lco, m.engine_amplitude_deg, np.nan)
        im = ax.imshow(amp.T, origin="lower", cmap="Reds", aspect="auto",
                       extent=(-0.5, len(a0.values) - 0.5, -0.5, len(a1.values) - 0.5))
        fig.colorbar(im, ax=ax, label="LCO engine amplitude [deg]")
        for i in range(len(a0.values)):
            for j in range(len(a1.values)):
                txt = (f"{m.engine_amplitude_deg[i, j]:.3f} deg\n{m.frequency_hz[i, j]:.2f} Hz" if m.lco[i, j]
                       else f"no LCO\n{m.margin_db[i, j]:.2f} dB")
                ax.text(i, j, txt, ha="center", va="center", fontsize=7)
        ax.contour(np.arange(len(a0.values)), np.arange(len(a1.values)), m.lco.T.astype(float), levels=[0.5],
                   colors="k", linewidths=2)
        ax.set_xticks(range(len(a0.values)), [f"{v:.3g}" for v in a0.values])
        ax.set_yticks(range(len(a1.values)), [f"{v:.3g}" for v in a1.values])
        ax.set_xlabel(f"{a0.name} [{a0.unit}]")
        ax.set_ylabel(f"{a1.name} [{a1.unit}]")
    ax.set_title(title or f"LCO verdict map ({m.friction_model}); black line: where the verdict flips")
    fig.tight_layout()
    return fig
