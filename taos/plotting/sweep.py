"""A sweep's metrics over its one or two swept keys (:class:`taos.montecarlo.sweep.SweepResult`).

One panel per metric. One key: the metric against the key's values. Two keys on a grid: one
curve per value of the second key; on a Latin hypercube: the points coloured by the metric.
Unstable and failed points are marked on the axis (red x, grey +) where the figure has no value.
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from taos.montecarlo.store import STATUS


def _label(k) -> str:
    return f"{k.key} [{k.unit}]" if k.unit and k.unit != "(choice)" else k.key


def _marks(ax, x, y_base, status) -> None:
    for code, style, name in ((STATUS["diverged"], "x", "unstable"), (STATUS["failed"], "+", "failed")):
        m = status == code
        if np.any(m):
            ax.plot(x[m], np.full(int(m.sum()), y_base), style, color="C3" if name == "unstable" else "0.5",
                    ms=9, mew=2, label=name, clip_on=False)


def _base(y) -> float:
    f = y[np.isfinite(y)]
    return float(np.min(f)) if f.size else 0.0


def plot_sweep(res, title: str | None = None):
    """The figure (module docstring)."""
    d = res.definition.design
    keys = d.keys
    metrics = res.definition.metrics
    n = len(metrics)
    cols = 1 if n == 1 else 2
    fig, axs = plt.subplots(math.ceil(n / cols), cols, figsize=(6.4 * cols, 3.8 * math.ceil(n / cols)), squeeze=False)
    x = d.factors[:, 0]
    for ax, m in zip(axs.flat, metrics):
        y = np.where(res.status == STATUS["ok"], res.values[m], np.nan)
        if len(keys) == 1:
            o = np.argsort(x)
            ax.plot(x[o], y[o], "o-", color="C0", label=m)
            _marks(ax, x, _base(y), res.status)
        elif d.shape is not None:
            x2 = d.factors[:, 1]
            for j, v in enumerate(sorted(set(x2))):
                s = x2 == v
                o = np.argsort(x[s])
                shown = d.texts[int(np.flatnonzero(s)[0])][keys[1].key]
                ax.plot(x[s][o], y[s][o], "o-", color=f"C{j % 10}", label=f"{keys[1].key} = {shown}")
            _marks(ax, x, _base(y), res.status)
        else:
            sc = ax.scatter(x, d.factors[:, 1], c=y, cmap="viridis", s=30)
            fig.colorbar(sc, ax=ax, label=m)
            bad = res.status != STATUS["ok"]
            ax.plot(x[bad], d.factors[bad, 1], "rx", ms=8, label="unstable or failed")
            ax.set_ylabel(_label(keys[1]))
        if keys[0].words:
            ax.set_xticks(range(len(keys[0].texts)), keys[0].texts)
        ax.set_xlabel(_label(keys[0]))
        if len(keys) == 1 or d.shape is not None:
            ax.set_ylabel(m)
        ax.grid(True, alpha=0.3)
        h, lab = ax.get_legend_handles_labels()
        if len(set(lab)) > 1:
            ax.legend(dict(zip(lab, h)).values(), dict(zip(lab, h)).keys(), fontsize=7)
    for ax in list(axs.flat)[n:]:
        ax.set_visible(False)
    fig.suptitle(title or f"taos sweep of {res.definition.model_file} ({d.design}, {d.n} points)", fontsize=10)
    fig.tight_layout()
    return fig
