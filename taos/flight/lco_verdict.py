"""The limit-cycle verdict in words a reviewer can sign, with the evidence beside it.

From a :class:`taos.flight.lco.LcoReport` (describing-function prediction and time-domain run):

* ``text``: one sentence, e.g. "limit cycle expected: 0.17 deg command (engine 0.11 deg),
  0.11 Hz, self-sustaining (stable by Loeb's test); vehicle attitude +-0.02 deg, rate
  +-0.01 deg/s". An unstable (Loeb) harmonic-balance solution is a *threshold*: motion smaller
  than it decays, larger grows, so it is not reported as a limit cycle. Without any solution
  the text names the margin meant: the smallest distance in dB between 0 dB and the gain
  of L0 N(A, .) at its -180 deg (mod 360) crossings over all command amplitudes of the map,
  with the amplitude and frequency where it occurs, and whether the loop gain would have to
  rise or fall by it.
  When the loop with the TVC is still unstable at the map's largest amplitude (a negative phase
  margin, or a negative signed low-frequency gain margin: :func:`signed_low_gain_margin`), there
  is no cycle inside the map because the motion outgrows it, and the text says so.
* ``margin_table``: for each describing-function amplitude, the loop margins of L0 N(A, .)
  (:func:`taos.flight.vehicle.margins`): the low-frequency gain margin (how far the gain may
  fall, which friction does as the amplitude falls) and its frequency, the high-frequency gain
  margin, the phase margin and the gain-crossover frequency.
* ``motion``: the vehicle motion of the cycle: attitude amplitude |G_att(j w)| |N| A with
  G_att the engine-deflection -> attitude response of the vehicle with its FCS
  (:func:`taos.flight.vehicle.vehicle_fcs_state_space`, inputs delta and delta' = j w delta),
  and the attitude-rate amplitude w times that; from the time-domain run too when it shows a
  cycle (least-squares fundamental of the attitude over the final window).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.linear import phase_deg

MARGIN_MEANING = ("smallest distance [dB] from 0 dB of the gain of L0 N(A, .) at its -180 deg (mod 360) "
                  "crossings, over all command amplitudes A of the describing-function map: how far the loop gain "
                  "would have to move for a limit cycle to appear")


@dataclass(frozen=True)
class CycleMotion:
    """Vehicle motion during a limit cycle (SI)."""

    source: str
    freq_hz: float
    command_amplitude_rad: float
    engine_amplitude_rad: float
    attitude_amplitude_rad: float
    attitude_rate_amplitude_rad_s: float

    def to_dict(self) -> dict:
        return {"source": self.source, "frequency_hz": self.freq_hz,
                "command_amplitude_deg": math.degrees(self.command_amplitude_rad),
                "engine_amplitude_deg": math.degrees(self.engine_amplitude_rad),
                "attitude_amplitude_deg": math.degrees(self.attitude_amplitude_rad),
                "attitude_rate_amplitude_deg_s": math.degrees(self.attitude_rate_amplitude_rad_s)}


@dataclass(frozen=True)
class NearestMargin:
    """Where the loop comes closest to a cycle without one."""

    margin_db: float
    amplitude_rad: float
    freq_hz: float
    direction: str  # "rise" or "fall": what the loop gain would have to do

    def to_dict(self) -> dict:
        return {"margin_db": self.margin_db, "amplitude_deg": math.degrees(self.amplitude_rad),
                "frequency_hz": self.freq_hz, "loop_gain_would_have_to": self.direction}


@dataclass(frozen=True)
class LcoVerdict:
    kind: str            # "limit-cycle", "threshold-only", "grows-beyond-map" or "none"
    text: str
    margin_table: tuple[dict, ...]
    nearest: NearestMargin | None
    motion: tuple[CycleMotion, ...]

    def to_dict(self) -> dict:
        return {"kind": self.kind, "text": self.text, "margin_meaning": MARGIN_MEANING,
                "nearest_margin": None if self.nearest is None else self.nearest.to_dict(),
                "margin_table": list(self.margin_table), "cycle_motion": [m.to_dict() for m in self.motion]}

    def table_text(self) -> str:
        lines = [f"{'A [deg]':>9} {'low GM [dB]':>11} {'at [Hz]':>8} {'high GM [dB]':>12} {'PM [deg]':>9} "
                 f"{'crossover [Hz]':>14}"]
        f = lambda x, s: "-".rjust(int(s.split(".")[0])) if x is None else format(x, s)  # noqa: E731
        for r in self.margin_table:
            lines.append(f"{r['amplitude_deg']:9.3g} {f(r['low_gain_margin_db'], '11.2f')} "
                         f"{f(r['low_phase_crossover_hz'], '8.3f')} {f(r['high_gain_margin_db'], '12.2f')} "
                         f"{f(r['phase_margin_deg'], '9.1f')} {f(r['gain_crossover_hz'], '14.3f')}")
        return "\n".join(lines)


def attitude_per_engine(flight, freq_hz, axis: str) -> np.ndarray:
    """Vehicle attitude per engine deflection, xi / delta (j w) [-], with the FCS closed around
    the vehicle as in the flight loop (inputs delta and delta' = j w delta)."""
    from taos.flight.vehicle import VF_INPUTS, vehicle_fcs_state_space
    f = np.atleast_1d(np.asarray(freq_hz, float))
    h = vehicle_fcs_state_space(flight, axis).freqresp(f, list(VF_INPUTS), "attitude_rad")
    return h[:, 0] + 2j * np.pi * f * h[:, 1]


def nearest_margin(pred, n_amp: int = 60, n_freq: int = 600) -> NearestMargin | None:
    """The smallest |gain| of L0 N(A, .) at a -180 deg crossing over the map (MARGIN_MEANING)."""
    df = pred.df
    amps = np.exp(np.linspace(math.log(df.amplitude_rad[0]), math.log(df.amplitude_rad[-1]), n_amp))
    f = np.logspace(math.log10(df.freq_hz[0]), math.log10(df.freq_hz[-1]), n_freq)
    L0 = pred.loop(f)
    best = None
    for a in amps:
        L = L0 * df(a, f)
        g = 20 * np.log10(np.abs(L))
        e = (phase_deg(L) + 180.0 + 180.0) % 360.0 - 180.0
        k = np.flatnonzero((np.sign(e[:-1]) != np.sign(e[1:])) & (np.abs(e[:-1]) < 90) & (np.abs(e[1:]) < 90))
        for j in k:
            t = e[j] / (e[j] - e[j + 1])
            gx = g[j] + t * (g[j + 1] - g[j])
            fx = 10 ** (math.log10(f[j]) + t * (math.log10(f[j + 1]) - math.log10(f[j])))
            if best is None or abs(gx) < best.margin_db:
                best = NearestMargin(abs(float(gx)), float(a), float(fx), "rise" if gx < 0 else "fall")
    return best


def low_frequency_crossing_hz(pred, n: int = 800) -> float | None:
    """The -180 deg crossing [Hz] of the rigid loop L0 where |L0| > 1 (the conditionally stable
    crossing), over the describing-function map's frequency range; None when there is none."""
    from taos.flight.vehicle import margins

    f = np.logspace(np.log10(pred.df.freq_hz[0]), np.log10(pred.df.freq_hz[-1]), n)
    return margins(f, pred.loop(f)).low_phase_crossover_hz


def signed_low_gain_margin(pred, amplitude_rad: float, f0_hz: float, n: int = 800) -> tuple[float | None, float | None]:
    """(20 log10 |L0 N(A)| [dB], frequency [Hz]) at the -180 deg crossing of L0 N(A, .) nearest
    ``f0_hz`` in log frequency; (None, None) without a crossing."""
    f = np.logspace(np.log10(pred.df.freq_hz[0]), np.log10(pred.df.freq_hz[-1]), n)
    L = pred.open_loop(amplitude_rad, f)
    e = (phase_deg(L) + 360.0) % 360.0 - 180.0          # 0 at -180 deg (mod 360)
    g = 20 * np.log10(np.abs(L))
    k = np.flatnonzero((np.sign(e[:-1]) != np.sign(e[1:])) & (np.abs(e[:-1] - e[1:]) < 180))
    if not k.size:
        return None, None
    t = e[k] / (e[k] - e[k + 1])
    lf = np.log10(f[k]) + t * (np.log10(f[k + 1]) - np.log10(f[k]))
    j = int(np.argmin(np.abs(lf - math.log10(f0_hz))))
    return float(g[k[j]] + t[j] * (g[k[j] + 1] - g[k[j]])), float(10 ** lf[j])


def grows_beyond_map(pred) -> str:
    """Why the motion outgrows the describing-function map ("" when it does not): the loop with
    the TVC at the map's largest amplitude is still unstable (a negative phase margin, or a
    negative signed low-frequency gain margin), so any cycle lies above that amplitude."""
    a = pred.df.amplitude_rad[-1]
    pm = pred.margins_by_amplitude[-1].phase_margin_deg
    f0 = low_frequency_crossing_hz(pred)
    g = signed_low_gain_margin(pred, a, f0)[0] if f0 is not None else None
    if (pm is not None and pm < 0) or (g is not None and g < 0):
        return (f"the loop is unstable at the map's largest amplitude {math.degrees(a):.3g} deg "
                f"(phase margin {_num(pm)} deg, low-frequency gain margin {_num(g)} dB): motion grows beyond it")
    return ""


def _num(x) -> str:
    return "-" if x is None else f"{x:.4g}"


def lco_verdict(report) -> LcoVerdict:
    """The verdict of a :class:`taos.flight.lco.LcoReport` (module docstring)."""
    pred = report.prediction
    fl, axis = pred.flight, pred.axis
    table = tuple({"amplitude_deg": math.degrees(a), **m.to_dict()}
                  for a, m in zip(pred.df.amplitude_rad, pred.margins_by_amplitude))
    motion = []
    c = pred.stable_cycle
    if c is not None:
        att = abs(attitude_per_engine(fl, [c.freq_hz], axis)[0]) * c.engine_amplitude_rad
        motion.append(CycleMotion("describing function", c.freq_hz, c.amplitude_rad, c.engine_amplitude_rad, att,
                                  2 * math.pi * c.freq_hz * att))
    td, h = report.time_domain, report.history
    if td is not None and td.lco and h is not None:
        from taos.harmonics import harmonic_amplitudes as _fit
        m = h.t_s >= h.t_s[-1] - td.window_s
        att, _ = _fit(h.t_s[m], h.attitude_rad[m], td.freq_hz)
        motion.append(CycleMotion("time domain", td.freq_hz, td.amplitude_rad, td.engine_amplitude_rad, att,
                                  2 * math.pi * td.freq_hz * att))
    if c is not None:
        mo = motion[0]
        text = (f"limit cycle expected: {math.degrees(c.amplitude_rad):.3g} deg command (engine "
                f"{math.degrees(c.engine_amplitude_rad):.3g} deg), {c.freq_hz:.3g} Hz, self-sustaining (stable by "
                f"Loeb's test); vehicle attitude +-{math.degrees(mo.attitude_amplitude_rad):.3g} deg, rate "
                f"+-{math.degrees(mo.attitude_rate_amplitude_rad_s):.3g} deg/s")
        if td is not None:
            text += ("; the time-domain run confirms it" if td.lco else
                     "; the time-domain run did NOT settle into it (check the seed and duration)")
        if pred.grid_warnings:
            text += "; WARNING: another cycle may lie outside the describing-function map: " + \
                "; ".join(pred.grid_warnings)
        return LcoVerdict("limit-cycle", text, table, None, tuple(motion))
    near = nearest_margin(pred)
    if pred.cycles:
        u = min(pred.cycles, key=lambda x: x.amplitude_rad)
        text = (f"no self-sustaining limit cycle: an unstable harmonic-balance solution at "
                f"{math.degrees(u.amplitude_rad):.3g} deg command, {u.freq_hz:.3g} Hz is a threshold (smaller "
                f"motion decays, larger grows)")
        kind = "threshold-only"
    elif grows_beyond_map(pred):
        text = "no limit cycle inside the describing-function map: " + grows_beyond_map(pred) + \
               " (extend the amplitudes, or see the time-domain run)"
        kind = "grows-beyond-map"
    else:
        text = "no limit cycle expected"
        kind = "none"
        if near is not None:
            text += (f": the loop gain would have to {near.direction} by {near.margin_db:.2f} dB for one to appear "
                     f"(closest at {math.degrees(near.amplitude_rad):.3g} deg command, {near.freq_hz:.3g} Hz)")
    extra = [w for w in pred.grid_warnings if kind != "grows-beyond-map" or "largest" not in w]
    if extra:   # a cycle may lie outside the map: the verdict above is the map's, not the loop's
        text += "; WARNING: a cycle may lie outside the describing-function map: " + "; ".join(extra)
    if td is not None and td.lco:
        text += (f"; BUT the time-domain run oscillates at {math.degrees(td.amplitude_rad):.3g} deg, "
                 f"{td.freq_hz:.3g} Hz")
    return LcoVerdict(kind, text, table, near, tuple(motion))
