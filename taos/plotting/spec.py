"""Spec-mask marks on a 2 x 2 Bode figure (:func:`taos.plotting.bode.new_bode_figure` layout:
piston gain, engine gain / piston phase, engine phase). Plotting only draws: the pass/fail
comes from :func:`taos.report.spec.check_spec`."""

from __future__ import annotations

import numpy as np


def bode_axes(fig):
    """The 2 x 2 axes array of a Bode figure made by :mod:`taos.plotting.bode`."""
    return np.array(fig.axes[:4], dtype=object).reshape(2, 2)


def draw_spec(ax, result, piston_scale_db: float = 0.0) -> None:
    """Each mask point as a bound bar (grey) and the model's value (green circle: pass, red
    cross: fail) on the gain and phase panels of its response; the verdict in a corner.
    ``piston_scale_db`` shifts piston gain marks when the plot shows another piston unit."""
    col = {"engine": 1, "piston": 0}
    for r in result.rows:
        p = r.point
        c = col[p.response]
        shift = piston_scale_db if p.response == "piston" else 0.0
        for row, bounds, val, ok in ((0, p.gain_db, r.gain_db, r.gain_pass), (1, p.phase_deg, r.phase_deg, r.phase_pass)):
            if bounds is None:
                continue
            a = ax[row, c]
            lo, hi = bounds[0] + (shift if row == 0 else 0), bounds[1] + (shift if row == 0 else 0)
            a.plot([p.freq_hz, p.freq_hz], [lo, hi], color="0.45", linewidth=4, alpha=0.45, solid_capstyle="butt",
                   gid="spec-bound")
            a.plot([p.freq_hz], [val + (shift if row == 0 else 0)], linestyle="none",
                   marker="o" if ok else "X", markersize=7, color="tab:green" if ok else "tab:red",
                   gid="spec-pass" if ok else "spec-fail")
    verdict = "PASS" if result.passed else f"FAIL ({len(result.failures())})"
    ax[1, 1].text(0.02, 0.04, f"spec, linear response: {result.mask.name}: {verdict}", transform=ax[1, 1].transAxes, ha="left",
                  va="bottom", fontsize=8, color="tab:green" if result.passed else "tab:red", gid="spec-verdict",
                  bbox=dict(facecolor="white", edgecolor="0.7", alpha=0.85))
