"""Shared plotting helpers: headless backend, PNG/SVG saving, engineering length units, one
legend per figure (each label once) and titles wrapped to the figure's width."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from ..results import atomic_write  # noqa: E402
from ..units import to_si  # noqa: E402

#: selectable length units for piston positions: name -> metres per unit
LENGTH_UNITS = {u: to_si(f"1 {u}", "length", source="taos.plotting", field="LENGTH_UNITS") for u in ("in", "mm", "m")}


def save(fig, path, dpi: int = 120) -> None:
    """Save a figure as PNG or SVG (by suffix), atomically."""
    suffix = Path(path).suffix.lower()
    if suffix not in (".png", ".svg"):
        from ..errors import InputError
        raise InputError("command line", "plot path", "a .png or .svg file name", got=str(path))
    atomic_write(path, lambda p: fig.savefig(p, dpi=dpi, format=suffix[1:]))


def finish_bode_axes(ax) -> None:
    """Log frequency axes with grids on a 2-row (gain, phase) grid of Bode axes; x labels on
    the phase row."""
    for a in ax.flat:
        a.set_xscale("log")
        a.grid(True, which="both", alpha=0.3)
    for a in ax[1]:
        a.set_xlabel("frequency [Hz]")


def legend_once(fig, ax, **kw):
    """One legend on ``ax`` holding every labelled artist of ``fig``'s axes, each label once
    (the same curve drawn on several panels is one entry)."""
    seen = {}
    for a in fig.axes:
        for h, lab in zip(*a.get_legend_handles_labels()):
            seen.setdefault(lab, h)
    return ax.legend(list(seen.values()), list(seen), **kw)


def wrapped_title(fig, text: str, fontsize: float = 12.0) -> str:
    """``text`` broken into lines that fit the width of ``fig`` at ``fontsize`` [pt] (about 0.55
    em per character): a long title is never clipped at the figure's edges."""
    import textwrap

    width_pt = fig.get_figwidth() * 72.0
    return "\n".join(textwrap.wrap(text, max(20, int(width_pt / (0.55 * fontsize))))) if text else text
