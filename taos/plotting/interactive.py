"""Interactive (Plotly) plots for the HTML pages: zoom, pan and hover readouts of every point.

The same quantities as the static figures (:mod:`.bode`, :mod:`.timehist`, :mod:`.nichols`),
which stay the library's and the documentation's pictures:

* :func:`bode_figure`: 2 x 2 Bode panels, command -> piston x_p / (R theta_c) and command ->
  engine theta / theta_c, gain [dB] (20 log10 |H|) and phase [deg] (continuous from low frequency,
  each response on the branch of the reference response, :func:`taos.linear.phase_deg_continuous`)
  against frequency [Hz] on a log axis; spec-mask bounds and the model's value at each mask point;
* :func:`timehistory_figure`: commands [deg], piston x_p [in], engine angle [deg] and friction
  torque [in lbf] against time [s];
* :func:`nichols_figure`: open-loop gain [dB] against phase [deg] of L0 N(A, .) with the critical
  point, the exclusion zone and the predicted limit cycles, grouped by kind.

Each trace appears once in the legend (one legend group per response across the four panels).
:func:`page_html` makes the ``<div>`` of a figure for a page that carries the plotly.js bundle
once, inline (:func:`plotly_script`): no script is fetched from the network.
Drawing only: the numbers come from the analysis' result objects.
"""

from __future__ import annotations

import math

import numpy as np

from ..linear import gain_db, phase_deg, phase_deg_continuous

#: the Bode panels (row, col) of each (response, quantity)
PANELS = {("piston", "gain"): (1, 1), ("engine", "gain"): (1, 2), ("piston", "phase"): (2, 1),
          ("engine", "phase"): (2, 2)}
UNITS = {"gain": "dB", "phase": "deg"}
#: one colour per axis (matplotlib's tab:blue and tab:orange, as in :mod:`.timehist`)
AXIS_COLOURS = {"pitch": "#1f77b4", "yaw": "#ff7f0e"}
#: plotly.js modebar and behaviour: no logo, no link to a web service; PNG export stays (client-side)
CONFIG = {"displaylogo": False, "responsive": True, "scrollZoom": False}


def _hover(name: str, qty: str, unit: str, fmt: str = ".2f") -> str:
    return f"<b>{name}</b><br>f = %{{x:.4g}} Hz<br>{qty} = %{{y:{fmt}}} {unit}<extra></extra>"


def _label(fr) -> str:
    return "linear" if fr.amplitude_rad is None else f"{math.degrees(fr.amplitude_rad):.3g} deg ({fr.friction_model})"


def _colour(i: int, n: int) -> str:
    """Blue to green to yellow-brown, readable on white (the amplitude families)."""
    import plotly.colors as pc

    return pc.sample_colorscale("Viridis", [0.1 + 0.7 * i / max(1, n - 1)])[0]


def _scatter(row: int, col: int, ncols: int, **props) -> dict:
    """A scatter trace (plotly's JSON form, as ``go.Scatter(**props)`` holds it) on subplot
    (``row``, ``col``) of a :func:`plotly.subplots.make_subplots` grid of ``ncols`` columns
    (axes numbered row by row: ``x``/``y``, ``x2``/``y2``, ...)."""
    k = (row - 1) * ncols + col
    return {"type": "scatter", **props, "xaxis": "x" if k == 1 else f"x{k}", "yaxis": "y" if k == 1 else f"y{k}"}


def _subplots(**kw):
    """:func:`plotly.subplots.make_subplots` (``kw``) on a figure made with the
    ``plotly_white`` template (the template validated once, not also plotly's default)."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    return make_subplots(figure=go.Figure(layout=dict(template="plotly_white")), **kw)


def _figure(layout_fig, traces):
    """A ``go.Figure`` of ``layout_fig``'s layout (validated: the template expanded) and the
    trace dicts ``traces`` (:func:`_scatter`), both taken as they are: plotly's per-property
    validation of every trace (most of a figure's build time) and a second one of the layout
    are skipped; the traces are made here, from numbers and fixed names, as plotly's JSON form."""
    import plotly.graph_objects as go

    return go.Figure(data=traces, layout=layout_fig.layout.to_plotly_json(), _validate=False)


def bode_traces(traces: list, fr, *, name: str, colour: str, ref=None, mode: str = "lines", symbol: str = "circle",
                group: str | None = None, open_marker: bool = False) -> None:
    """One response on the four Bode panels (four trace dicts appended to ``traces``), one legend
    entry; engine points where friction holds the engine (no motion: no gain or phase) left out
    and named in the legend entry."""
    f = np.asarray(fr.freq_hz, float)
    held = fr.engine_held() if hasattr(fr, "engine_held") else np.zeros(f.size, bool)
    if held.any():
        name = f"{name}; engine held at {', '.join(f'{x:g}' for x in f[held])} Hz"
    rf = rp = re = None
    if ref is not None and ref is not fr:
        rf = np.asarray(ref.freq_hz, float)
        rp, re = phase_deg(ref.piston), phase_deg(ref.engine)
    vals = {("piston", "gain"): gain_db(fr.piston),
            ("engine", "gain"): np.where(held, np.nan, gain_db(fr.engine)),
            ("piston", "phase"): phase_deg_continuous(f, fr.piston, rp, rf),
            ("engine", "phase"): np.where(held, np.nan, phase_deg_continuous(f, fr.engine, re, rf))}
    group = group or name
    marker = dict(color=colour, symbol=symbol + ("-open" if open_marker else ""), size=7)
    for k, (key, y) in enumerate(vals.items()):
        r, c = PANELS[key]
        traces.append(_scatter(r, c, 2, x=f, y=y, mode=mode, name=name, legendgroup=group, showlegend=k == 0,
                               line=dict(color=colour, width=2 if fr.amplitude_rad is None else 1.5),
                               marker=dict(marker), hovertemplate=_hover(name, f"{key[0]} {key[1]}", UNITS[key[1]],
                                                                         ".2f" if key[1] == "gain" else ".1f")))


def spec_traces(traces: list, result) -> None:
    """Mask bounds (grey bars) and the linear model's value (green circle pass, red cross fail)
    at every mask point of a :class:`taos.report.spec.SpecResult` (trace dicts appended to
    ``traces``)."""
    bars = {}
    marks = {}
    for r in result.rows:
        p = r.point
        for qty, bounds, val, ok in (("gain", p.gain_db, r.gain_db, r.gain_pass),
                                     ("phase", p.phase_deg, r.phase_deg, r.phase_pass)):
            if bounds is None:
                continue
            key = PANELS[(p.response, qty)]
            bx, by, bt = bars.setdefault(key, ([], [], []))
            bx += [p.freq_hz, p.freq_hz, None]
            by += [bounds[0], bounds[1], None]
            bt += [f"[{bounds[0]:g}, {bounds[1]:g}] {UNITS[qty]}"] * 3
            marks.setdefault((key, ok), []).append((p.freq_hz, val, f"{p.response} {qty}: limits "
                                                    f"[{bounds[0]:g}, {bounds[1]:g}] {UNITS[qty]}"))
    first = True
    for (r, c), (x, y, t) in bars.items():
        traces.append(_scatter(r, c, 2, x=x, y=y, mode="lines", line=dict(color="rgba(110,110,110,0.45)", width=7),
                               name=f"spec mask: {result.mask.name}", legendgroup="spec-bounds", showlegend=first,
                               text=t, hovertemplate="mask limits %{text} at %{x:.4g} Hz<extra></extra>"))
        first = False
    shown = set()
    for ((r, c), ok), pts in marks.items():
        name = "linear model within the mask" if ok else "linear model outside the mask"
        traces.append(_scatter(
            r, c, 2, x=[p[0] for p in pts], y=[p[1] for p in pts], mode="markers", name=name, legendgroup=name,
            showlegend=name not in shown, text=[p[2] for p in pts],
            marker=dict(symbol="circle" if ok else "x", size=10, color="#1a7f37" if ok else "#c62828"),
            hovertemplate="%{text}<br>model %{y:.2f} at %{x:.4g} Hz<extra>" + ("pass" if ok else "FAIL") + "</extra>"))
        shown.add(name)


def bode_figure(responses, *, resonance_hz: float | None = None, notch_hz: float | None = None, data=(),
                data_label: str = "data", measured=None, measured_label: str = "test record", spec_result=None,
                title: str | None = None):
    """Interactive Bode panels (module docstring) of ``responses`` (list of
    :class:`~taos.planar.freqresp.FrequencyResponse`: the linear one as a black line, sine dwells
    one colour per amplitude with markers), ``data`` (responses read off a run: open circles),
    ``measured`` (a measured record's response: orange squares), the load resonance
    ``resonance_hz`` [Hz] (dashed line) and the piston notch ``notch_hz`` [Hz] (triangle), and
    the spec mask ``spec_result``. Returns a ``plotly.graph_objects.Figure``."""
    responses = list(responses)
    ref = max(responses, key=lambda r: (r.amplitude_rad is None, np.size(r.freq_hz)))
    fig = _subplots(rows=2, cols=2, shared_xaxes=True, vertical_spacing=0.07, horizontal_spacing=0.08,
                    subplot_titles=("command → piston, x_p / (R θ_c)", "command → engine angle, θ / θ_c", "", ""))
    amps = sorted({fr.amplitude_rad for fr in responses if fr.amplitude_rad is not None})
    traces = []
    for fr in responses:
        if fr.amplitude_rad is None:
            bode_traces(traces, fr, name="linear", colour="black", ref=ref)
        else:
            bode_traces(traces, fr, name=_label(fr), colour=_colour(amps.index(fr.amplitude_rad), len(amps)),
                        ref=ref, mode="lines+markers")
    for fr in data or ():
        bode_traces(traces, fr, name=f"{data_label} {_label(fr)}", colour="#c62828", ref=ref, mode="markers",
                    open_marker=True)
    if measured is not None:
        bode_traces(traces, measured, name=measured_label, colour="#ef6c00", ref=ref, mode="markers", symbol="square")
    if spec_result is not None:
        spec_traces(traces, spec_result)
    _marks(fig, traces, ref, resonance_hz, notch_hz)
    for (r, c), key in ((v, k) for k, v in PANELS.items()):
        fig.update_xaxes(type="log", showgrid=True, row=r, col=c, title_text="frequency [Hz]" if r == 2 else None)
        fig.update_yaxes(title_text=f"{key[1]} [{UNITS[key[1]]}]", row=r, col=c)
    fig.update_layout(height=720, hovermode="closest", margin=dict(l=60, r=20, t=70, b=50),
                      title=dict(text=title or "", x=0.01, font=dict(size=15)),
                      legend=dict(orientation="h", yanchor="top", y=-0.09, x=0, font=dict(size=11)))
    return _figure(fig, traces)


def _marks(fig, traces: list, ref, resonance_hz, notch_hz) -> None:
    """The load resonance (a dashed vertical line on each panel: layout shapes of ``fig``, as
    ``add_vline`` makes them) and the piston notch (a triangle) of a Bode figure."""
    if resonance_hz is not None:
        shapes = []
        for r, c in PANELS.values():
            k = (r - 1) * 2 + c
            ref_x, ref_y = ("x", "y") if k == 1 else (f"x{k}", f"y{k}")
            shapes.append(dict(type="line", x0=resonance_hz, x1=resonance_hz, xref=ref_x, y0=0, y1=1,
                               yref=f"{ref_y} domain", line=dict(color="grey", dash="dash", width=1)))
        fig.update_layout(shapes=list(fig.layout.shapes) + shapes)
        traces.append(_scatter(1, 1, 2, x=[None], y=[None], mode="lines", line=dict(color="grey", dash="dash"),
                               name=f"load resonance w_L {resonance_hz:.3f} Hz", hoverinfo="skip"))
    if notch_hz is not None and math.isfinite(notch_hz):
        f = np.asarray(ref.freq_hz, float)
        y = float(np.interp(math.log10(notch_hz), np.log10(f), gain_db(ref.piston)))
        traces.append(_scatter(1, 1, 2, x=[notch_hz], y=[y], mode="markers", name=f"piston notch {notch_hz:.3f} Hz",
                               marker=dict(symbol="triangle-down", size=13, color="black"),
                               hovertemplate="notch %{x:.4g} Hz<br>piston gain %{y:.2f} dB<extra></extra>"))


def timehistory_figure(th, title: str | None = None):
    """Commands (FCS, solid; after avionics, dotted) [deg], piston x_p [in], engine angle [deg]
    and friction torque T_f [in lbf] of run ``th`` against time [s], one colour per axis."""
    from ..units import from_si

    m_per_in = 1.0 / from_si(1.0, "m", "in")
    nm_per_inlbf = 1.0 / from_si(1.0, "N*m", "inch*lbf")
    rows = (("command", "command [deg]"), ("piston", "piston x_p [in]"), ("engine", "engine θ [deg]"),
            ("friction", "friction torque T_f [in lbf]"))
    fig = _subplots(rows=4, cols=1, shared_xaxes=True, vertical_spacing=0.03)
    t = np.asarray(th.t_s, float)
    traces = []
    for i, ax in enumerate(th.axes):
        col = AXIS_COLOURS.get(ax, None)
        series = ((1, f"{ax} FCS command", np.degrees(th.command_rad[i]), "deg", "solid"),
                  (1, f"{ax} after avionics", np.degrees(th.command_avionics_rad[i]), "deg", "dot"),
                  (2, f"{ax} piston", np.asarray(th.piston_m[i]) / m_per_in, "in", "solid"),
                  (3, f"{ax} engine", np.degrees(th.engine_rad[i]), "deg", "solid"),
                  (4, f"{ax} friction torque", np.asarray(th.friction_torque_Nm[i]) / nm_per_inlbf, "in lbf", "solid"))
        for row, name, y, unit, dash in series:
            traces.append(_scatter(row, 1, 1, x=t.astype(np.float32), y=np.asarray(y, np.float32), mode="lines",
                                   name=name, line=dict(color=col, width=1.2, dash=dash),
                                   hovertemplate=f"<b>{name}</b><br>t = %{{x:.4f}} s<br>%{{y:.4g}} {unit}"
                                                 "<extra></extra>"))
    for k, (_, label) in enumerate(rows, start=1):
        fig.update_yaxes(title_text=label, row=k, col=1)
    fig.update_xaxes(title_text="time [s]", row=4, col=1)
    fig.update_layout(height=900, hovermode="closest", margin=dict(l=70, r=20, t=50, b=40),
                      title=dict(text=title or "", x=0.01, font=dict(size=15)), legend=dict(font=dict(size=11)))
    return _figure(fig, traces)


def nichols_figure(pred, amplitudes_rad=None, n_freq: int = 400, title: str | None = None):
    """Open-loop gain [dB] against phase [deg] of L0 (TVC = 1) and L0 N(A, .) at several command
    amplitudes A of ``pred`` (a :class:`taos.flight.lco.LcoPrediction`), the critical point
    (-180 deg, 0 dB), the exclusion zone (+-6 dB, +-30 deg around it) and the predicted limit
    cycles: one marker per kind (stable, unstable), every cycle's amplitude and frequency in its
    hover text. The hover shows each locus' frequency [Hz]."""
    import plotly.graph_objects as go

    df = pred.df
    f = np.logspace(np.log10(df.freq_hz[0]), np.log10(df.freq_hz[-1]), n_freq)
    amps = df.amplitude_rad[::2] if amplitudes_rad is None else np.asarray(amplitudes_rad, float)
    fig = go.Figure()
    fig.add_shape(type="rect", x0=-210, x1=-150, y0=-6, y1=6, fillcolor="rgba(198,40,40,0.10)",
                  line=dict(color="rgba(198,40,40,0.6)", dash="dash"))

    def locus(h, name, colour, width):
        ph = phase_deg(h)
        ph -= 360.0 * np.round((ph[len(ph) // 2] + 180.0) / 360.0)
        fig.add_trace(go.Scatter(x=ph, y=gain_db(h, 1e-6), mode="lines", name=name, customdata=f,
                                 line=dict(color=colour, width=width),
                                 hovertemplate=f"<b>{name}</b><br>f = %{{customdata:.4g}} Hz<br>phase = %{{x:.1f}} deg"
                                               "<br>gain = %{y:.2f} dB<extra></extra>"))

    locus(pred.loop(f), "L0 (TVC = 1)", "black", 3)
    for i, a in enumerate(amps):
        locus(pred.open_loop(a, f), f"L0 N, A = {math.degrees(a):.3g} deg", _colour(i, len(amps)), 1.5)
    fig.add_trace(go.Scatter(x=[-180], y=[0], mode="markers", name="critical point",
                             marker=dict(symbol="cross-thin", size=16, line=dict(width=3, color="red")),
                             hovertemplate="critical point (-180 deg, 0 dB)<extra></extra>"))
    from .nichols import cycles_label

    for stable in (True, False):
        cs = [c for c in pred.cycles if c.stable == stable]
        if not cs:
            continue
        kind = "stable LCO" if stable else "unstable harmonic-balance solution (threshold)"
        text = "<br>".join(f"{math.degrees(c.amplitude_rad):.3g} deg, {c.freq_hz:.3g} Hz" for c in cs)
        fig.add_trace(go.Scatter(x=[-180], y=[0], mode="markers", name=cycles_label(cs, stable),
                                 marker=dict(symbol="circle-open", size=18 if stable else 24,
                                             line=dict(width=2), color="green" if stable else "magenta"),
                                 hovertemplate=f"<b>{kind}</b><br>{text}<extra></extra>"))
    fig.update_xaxes(title_text="open-loop phase [deg]", range=[-330, -30])
    fig.update_yaxes(title_text="open-loop gain [dB]", range=[-25, 30])
    fig.update_layout(height=560, template="plotly_white", hovermode="closest", margin=dict(l=60, r=20, t=50, b=50),
                      title=dict(text=title or f"FCS open loop with TVC describing function ({df.friction_model})",
                                 x=0.01, font=dict(size=15)))
    return fig


def plotly_script() -> str:
    """The plotly.js bundle in a ``<script>`` element, to be put once in a page (offline)."""
    from plotly.offline import get_plotlyjs

    return f'<script type="text/javascript">{get_plotlyjs()}</script>'


def page_html(fig, div_id: str) -> str:
    """The ``<div>`` and drawing script of ``fig`` for a page that carries :func:`plotly_script`."""
    import plotly.io as pio

    return pio.to_html(fig, full_html=False, include_plotlyjs=False, div_id=div_id, config=CONFIG,
                       default_height=f"{fig.layout.height or 600}px")
