"""A flight record against its Monte Carlo envelope (:mod:`taos.montecarlo.envelope`): the
percentile bands of the stored command (or engine angle) over time, the median, the record overlaid and the samples
outside marked, the fraction of time outside in the title. Drawing only."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from taos.plotting import _common  # noqa: F401  (sets the headless backend)


def plot_envelopes(pairs):
    """Several envelopes one above the other on a shared time axis: ``pairs`` of (envelope,
    comparison or None), each drawn as :func:`plot_envelope`. Returns the figure."""
    pairs = list(pairs)
    fig, axs = plt.subplots(len(pairs), 1, figsize=(11, 4.0 * len(pairs)), sharex=True, squeeze=False)
    for ax, (env, cmp) in zip(axs[:, 0], pairs):
        plot_envelope(env, cmp, ax=ax)
    for ax in axs[:-1, 0]:
        ax.set_xlabel("")
    fig.tight_layout()
    return fig


def plot_envelope(env, comparison=None, ax=None):
    """The envelope ``env`` (:class:`taos.montecarlo.envelope.Envelope`) in degrees: the outer band
    shaded, inner pairs of percentiles shaded darker, the middle percentile as a line; with a
    ``comparison`` (:class:`taos.montecarlo.envelope.EnvelopeComparison`) the record and its
    samples outside. Returns the figure (drawn on ``ax`` when given)."""
    if ax is None:
        fig, ax = plt.subplots(figsize=(11, 4.5))
    else:
        fig = ax.figure
    b = np.degrees(env.bands_rad)
    k = len(env.percentiles)
    for i in range(k // 2):
        lo, hi = env.percentiles[i], env.percentiles[k - 1 - i]
        ax.fill_between(env.t_s, b[i], b[k - 1 - i], color="tab:blue", alpha=0.15 + 0.15 * i, lw=0,
                        label=f"{lo:g}-{hi:g} % of {env.runs_ok} runs")
    if k % 2:
        ax.plot(env.t_s, b[k // 2], color="tab:blue", lw=1.0, label=f"{env.percentiles[k // 2]:g} %")
    name = {"command": "FCS command", "engine": "engine angle"}.get(env.quantity, env.quantity)
    title = f"{name} envelope" + (f", {env.axis} axis" if env.axis else "")
    if comparison is not None:
        c = comparison
        v = np.degrees(c.value_rad)
        out = (c.value_rad > c.hi_rad) | (c.value_rad < c.lo_rad)
        ax.plot(c.t_s, v, "k-", lw=1.0, label=f"record {c.source}")
        ax.plot(c.t_s[out], v[out], "r.", ms=4, label="outside")
        title += f": record outside {100 * c.fraction_outside:.1f} % of the time"
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"{name} [deg]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if len(fig.axes) == 1:
        fig.tight_layout()
    return fig
