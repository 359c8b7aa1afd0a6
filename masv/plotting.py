"""MASV plots (matplotlib, headless): thin functions over the analysis result objects.

Lives in masv because taos must not import masv; saving goes through :func:`taos.plotting.save`.
"""

from __future__ import annotations

import numpy as np

from taos.plotting import save  # noqa: F401  (re-exported: masv.plotting.save(fig, path))
from taos.plotting._common import merge_log_minor_ticks

from .analysis import CouplingResult, MasvFrequencyResponse, TvseLoop, _db


def plot_gain_grid(fr: MasvFrequencyResponse, kind: str = "engine", floor_db: float = -120.0):
    """n x n grid of gain curves [dB] against frequency [Hz]: panel (i, j) is output i for command j
    (``kind`` 'engine' theta_i/theta_c,j or 'piston' x_p,i/(R_i theta_c,j))."""
    import matplotlib.pyplot as plt

    H = fr.engine if kind == "engine" else fr.piston
    n = len(fr.actuators)
    fig, axes = plt.subplots(n, n, sharex=True, sharey=True, figsize=(2.0 * n, 1.6 * n), squeeze=False)
    g = np.maximum(_db(H), floor_db)
    for i in range(n):
        for j in range(n):
            ax = axes[i, j]
            ax.semilogx(fr.freq_hz, g[:, i, j], lw=0.8, color="C0" if i == j else "C1")
            ax.grid(True, which="both", lw=0.3)
            if i == n - 1:
                ax.set_xlabel(f"{fr.actuators[j]}\nfreq [Hz]", fontsize=6)
            if j == 0:
                ax.set_ylabel(f"{fr.actuators[i]}\n[dB]", fontsize=6)
            ax.tick_params(labelsize=5)
    fig.suptitle(f"MASV command -> {kind} gains (row: response, column: command)")
    # fixed margins [in] instead of tight_layout (which measured the 64 panels of the 8 x 8 grid
    # for 4 of its 5 CPU-s): two-line 6-pt labels and 5-pt ticks on the outer panels only
    # (shared axes), the title on top
    w, h = fig.get_size_inches()
    fig.subplots_adjust(left=0.62 / w, right=1 - 0.08 / w, bottom=0.5 / h, top=1 - 0.55 / h,
                        wspace=0.12 * n / (w - 0.7), hspace=0.16 * n / (h - 1.05))
    # the limits are final: the unlabelled minor ticks of the log axes as one artist per panel
    # (the same pixels; matplotlib's own ~2,400 Tick objects were most of the 8 x 8 grid's drawing)
    merge_log_minor_ticks(fig)
    return fig


def plot_actuator_vs_simplex(fr: MasvFrequencyResponse, name: str, simplex):
    """Bode plot of actuator ``name``'s own response in MASV beside the simplex model's
    (``simplex`` a taos.planar.freqresp.FrequencyResponse on the same or any frequency grid)."""
    import matplotlib.pyplot as plt

    from taos.linear import phase_deg

    d = fr.diagonal(name)
    fig, ax = plt.subplots(2, 2, sharex=True, figsize=(10, 6))
    for r, (label, fm, fs) in enumerate((("piston", d.piston, simplex.piston), ("engine", d.engine, simplex.engine))):
        ax[0, r].semilogx(fr.freq_hz, _db(fm), label="MASV")
        ax[0, r].semilogx(simplex.freq_hz, _db(fs), "--", label="simplex")
        ax[1, r].semilogx(fr.freq_hz, phase_deg(fm), label="MASV")
        ax[1, r].semilogx(simplex.freq_hz, phase_deg(fs), "--", label="simplex")
        ax[0, r].set_title(f"{name}: command -> {label}")
        ax[0, r].set_ylabel("gain [dB]")
        ax[1, r].set_ylabel("phase [deg]")
        ax[1, r].set_xlabel("freq [Hz]")
        for a in ax[:, r]:
            a.grid(True, which="both", lw=0.3)
            a.legend(fontsize=7)
    fig.tight_layout()
    return fig


def plot_coupling_matrix(c: CouplingResult, kind: str = "engine"):
    """Heat map of peak coupling gains over the band [dB]."""
    import matplotlib.pyplot as plt

    P = c.engine_peak_db if kind == "engine" else c.piston_peak_db
    fig, ax = plt.subplots(figsize=(7, 6))
    im = ax.imshow(np.maximum(P, -120.0), cmap="viridis")
    n = len(c.actuators)
    ax.set_xticks(range(n), c.actuators, rotation=60, fontsize=7)
    ax.set_yticks(range(n), c.actuators, fontsize=7)
    ax.set_xlabel("command")
    ax.set_ylabel("response")
    fig.colorbar(im, label=f"peak {kind} gain [dB], {c.band_hz[0]:g}-{c.band_hz[1]:g} Hz")
    fig.tight_layout()
    return fig


def plot_tvse_loops(loops: "tuple[TvseLoop, ...]"):
    """Bode plot of the TVSE loops L(j w) (gain [dB], phase [deg]) of every actuator, with the
    0 dB line; the critical point of each loop is 1 + L = 0 (0 dB at +-180 deg)."""
    import matplotlib.pyplot as plt

    from taos.linear import phase_deg

    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
    for lp in loops:
        if not np.any(lp.loop):
            continue
        ax[0].semilogx(lp.freq_hz, _db(lp.loop), lw=0.9, label=lp.actuator)
        ax[1].semilogx(lp.freq_hz, phase_deg(lp.loop), lw=0.9)
    ax[0].axhline(0.0, color="k", lw=0.6)
    for p in (-180.0, 180.0):
        ax[1].axhline(p, color="k", lw=0.6, ls="--")
    ax[0].set_ylabel("TVSE loop gain [dB]")
    ax[1].set_ylabel("phase [deg]")
    ax[1].set_xlabel("frequency [Hz]")
    for a in ax:
        a.grid(True, which="both", lw=0.3)
    if len(ax[0].lines) > 2:
        ax[0].legend(fontsize=7, ncol=2)
    fig.suptitle("TVSE loops (broken at the engines' inertial coupling into the structure)")
    fig.tight_layout()
    return fig
