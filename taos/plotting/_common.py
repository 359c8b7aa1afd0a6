"""Shared plotting helpers: headless backend, PNG/SVG saving, engineering length units."""

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
