"""Shared plotting helpers: headless backend, PNG/SVG saving, engineering length units, one
legend per figure (each label once) and titles wrapped to the figure's width."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from matplotlib.artist import Artist  # noqa: E402
from matplotlib.layout_engine import LayoutEngine  # noqa: E402

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
    freeze_layout(fig)
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


def _text_size_in(renderer, texts, fontsize, dpi: float) -> tuple[float, float]:
    """(widest, tallest) of ``texts`` [in] at ``fontsize`` [pt]: lines 1.2 line heights apart as
    :class:`matplotlib.text.Text` sets them; mathtext where a line holds ``$``."""
    from matplotlib.font_manager import FontProperties

    prop, w, h = FontProperties(size=fontsize), 0.0, 0.0
    _, lp, _ = renderer.get_text_width_height_descent("lp", prop, ismath=False)
    for s in texts:
        if not s:
            continue
        lines = s.split("\n")
        for line in lines:
            tw, th, _ = renderer.get_text_width_height_descent(line, prop, ismath="$" in line)
            w, h = max(w, tw), max(h, max(th, lp) + 1.2 * lp * (len(lines) - 1))
    return w / dpi, h / dpi


def _tick_strings(axis, minor: bool = False) -> list[str]:
    """The tick labels ``axis`` will draw at its current view limits (no Tick objects made)."""
    loc = axis.get_minor_locator() if minor else axis.get_major_locator()
    fmt = axis.get_minor_formatter() if minor else axis.get_major_formatter()
    lo, hi = sorted(axis.get_view_interval())
    locs = [x for x in loc() if lo <= x <= hi]
    return list(fmt.format_ticks(locs)) if locs else []


def grid_layout(fig, ax, pad_in: float = 3 / 72) -> None:
    """Fixed margins for a 2-D grid ``ax`` of axes sharing x (tick labels and x label on the
    bottom row only): the space each text needs, measured once from the texts the figure will
    draw (suptitle, column titles, y labels and the y tick labels at the current limits, x
    labels), then ``subplots_adjust``; ``pad_in`` [in] is the padding around each text. In
    place of constrained layout, which measures every axis' tight box (and its shared
    siblings') twice per draw. Call it once the axes' limits are final (the figure's layout
    engine, if any, must allow ``subplots_adjust``: :class:`GridLayout` does)."""
    import numpy as np
    from matplotlib import rcParams as rc
    from matplotlib.font_manager import FontProperties

    ax = np.asarray(ax, dtype=object).reshape(len(ax), -1)
    nrow, ncol = ax.shape
    W, H = fig.get_size_inches()
    dpi = fig.dpi
    r = fig.canvas.get_renderer()
    pt = 1 / 72
    fs = {k: FontProperties(size=rc[k]).get_size_in_points()
          for k in ("ytick.labelsize", "xtick.labelsize", "axes.labelsize", "axes.titlesize", "figure.titlesize")}
    tick_y = (max(rc["ytick.major.size"], 0) + rc["ytick.major.pad"]) * pt
    tick_x = (max(rc["xtick.major.size"], 0) + rc["xtick.major.pad"]) * pt
    # left of each column: y tick labels (widest of the column, one digit spare for a finer
    # step after the resize), the y label beside them
    digit, _ = _text_size_in(r, ["0"], fs["ytick.labelsize"], dpi)
    need = []
    for c in range(ncol):
        labels = [s for a in ax[:, c] for s in _tick_strings(a.yaxis)]
        wt, _ = _text_size_in(r, labels, fs["ytick.labelsize"], dpi)
        _, hl = _text_size_in(r, [a.get_ylabel() for a in ax[:, c]], fs["axes.labelsize"], dpi)
        need.append(tick_y + wt + digit + rc["axes.labelpad"] * pt + hl + pad_in)
    # bottom: x tick labels (major and minor) and the x label of the bottom row
    xt = [s for a in ax[-1] for s in _tick_strings(a.xaxis) + _tick_strings(a.xaxis, minor=True)]
    _, ht = _text_size_in(r, xt, fs["xtick.labelsize"], dpi)
    _, hx = _text_size_in(r, [a.get_xlabel() for a in ax[-1]], fs["axes.labelsize"], dpi)
    bottom = tick_x + ht + rc["axes.labelpad"] * pt + hx + 2 * pad_in
    # top: the suptitle (lines as wrapped) and the top row's titles; half a tick label above
    sup = fig.get_suptitle()
    _, hs = _text_size_in(r, [sup], fs["figure.titlesize"], dpi)
    _, htt = _text_size_in(r, [a.get_title() for a in ax[0]], fs["axes.titlesize"], dpi)
    _, hy = _text_size_in(r, ["0"], fs["ytick.labelsize"], dpi)
    top = 2 * pad_in + (hs + pad_in if sup else 0.0) + (htt + rc["axes.titlepad"] * pt if htt else hy / 2)
    right = 0.15                                         # half a last x tick label may stand past the axes
    gap_w = max(need[1:], default=0.0) + 2 * pad_in     # between columns: the right column's labels
    gap_h = hy + 2 * pad_in                              # between rows: half tick labels above and below
    aw = (W - need[0] - right - (ncol - 1) * gap_w) / ncol
    ah = (H - top - bottom - (nrow - 1) * gap_h) / nrow
    fig.subplots_adjust(left=need[0] / W, right=1 - right / W, bottom=bottom / H, top=1 - top / H,
                        wspace=gap_w / aw if ncol > 1 else 0.2, hspace=gap_h / ah if nrow > 1 else 0.2)
    if sup:
        fig._suptitle.set_y(1 - pad_in / H)


class GridLayout(LayoutEngine):
    """Layout engine of a figure whose axes form one grid sharing x: :func:`grid_layout` at
    each draw (so the margins follow the limits of the drawn data)."""

    _adjust_compatible = True
    _colorbar_gridspec = False

    def __init__(self, ax, **kwargs):
        super().__init__(**kwargs)
        self._ax = ax

    def execute(self, fig) -> None:
        grid_layout(fig, self._ax)


def use_grid_layout(fig, ax) -> None:
    """Give ``fig`` (made without a layout engine) a :class:`GridLayout` on its axes grid ``ax``."""
    fig.set_layout_engine(GridLayout(ax))


def freeze_layout(fig) -> None:
    """Run ``fig``'s :class:`GridLayout` now and drop the engine: a save then draws the figure
    once (matplotlib draws a figure that has a layout engine twice when saving it). The
    figure's limits are final from here on: the unlabelled minor ticks of its log x axes
    become one artist per axes (:func:`merge_log_minor_ticks`)."""
    eng = fig.get_layout_engine()
    if isinstance(eng, GridLayout):
        eng.execute(fig)
        fig.set_layout_engine(None)
        merge_log_minor_ticks(fig)


class _MergedTicks(Artist):
    """Grid lines and tick marks of many ticks of one axis, drawn at the axis' z-order: one
    :class:`~matplotlib.lines.Line2D` per kind (grid line, bottom mark, top mark), each with the
    properties of the axis' own tick of that kind."""

    def __init__(self, parts, zorder: float):
        super().__init__()
        self._parts = parts
        self.set_zorder(zorder)
        self.set_in_layout(False)

    def draw(self, renderer) -> None:
        for p in self._parts:
            p.draw(renderer)


def merge_log_minor_ticks(fig) -> None:
    """The minor ticks (marks and grid lines) of each log-scaled x axis of ``fig`` whose minor
    tick labels are all empty (a span over a decade: LogFormatter labels the decades only)
    drawn as one :class:`_MergedTicks` per axes instead of matplotlib's minor Tick objects
    (three lines and two texts each, ~32 per Bode panel: most of a Bode figure's drawing time).
    Same positions (the axis' minor locator, less the major ticks, within the view as
    ``Axis._update_ticks`` keeps them), same line and marker properties (copied from the axis'
    own minor tick); the axis' minor locator becomes a NullLocator. Call once the limits are
    final (:func:`freeze_layout` does); an axis with labelled minor ticks is left as it is."""
    import numpy as np
    from matplotlib.lines import Line2D
    from matplotlib.ticker import LogLocator, NullLocator
    from matplotlib.transforms import _interval_contains_close

    todo = []
    for a in fig.axes:
        xa = a.xaxis
        if (xa.get_scale() != "log" or not isinstance(xa.get_minor_locator(), LogLocator)
                or a.name != "rectilinear"):
            continue
        locs = np.asarray(xa.get_minorticklocs(), float)
        if any(xa.get_minor_formatter().format_ticks(locs)):
            continue
        tr = xa.get_transform()
        interval_t = tr.transform(sorted(xa.get_view_interval()))
        locs = np.array([x for x in locs if _interval_contains_close(interval_t, tr.transform(x))])
        todo.append((a, locs, xa.get_minor_ticks(1)[0]))
    for a, locs, ref in todo:   # (shared x axes share their locators: all positions first)
        parts = []
        for src, y in ((ref.gridline, (0.0, 1.0)), (ref.tick1line, (0.0,)), (ref.tick2line, (1.0,))):
            if not (src.get_visible() and locs.size):
                continue
            line = Line2D([], [])
            line.update_from(src)
            if len(y) == 2:   # one segment per grid line, NaN between them
                x = np.column_stack([locs, locs, np.full(locs.size, np.nan)]).ravel()
                line.set_data(x, np.tile([y[0], y[1], np.nan], locs.size))
            else:
                line.set_data(locs, np.full(locs.size, y[0]))
            line.axes = a
            parts.append(line)
        a.xaxis.set_minor_locator(NullLocator())
        if parts:
            a.add_artist(_MergedTicks(parts, a.xaxis.get_zorder()))
