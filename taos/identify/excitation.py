"""What a command is: sine-dwell segments (constant-period runs of upward zero crossings) and
the whole-command classification as dwells, a sweep or a multisine with its evidence (seed
paper secs. 2.2, 3.2). Used by :mod:`taos.identify.segments` (per segment) and
:mod:`taos.identify.estimation` (the estimators)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.identify.data import TestData


@dataclass(frozen=True)
class DwellSegment:
    """A sine-dwell segment of one axis' command: [t0_s, t1_s] holding ``cycles`` whole cycles."""

    t0_s: float
    t1_s: float
    freq_hz: float
    cycles: int


def _rising_crossings(t, u, hyst):
    """Times of upward zero crossings of u with hysteresis ``hyst`` (linear interpolation)."""
    out = []
    armed = False
    for i in range(1, u.size):
        if u[i] < -hyst:
            armed = True
        if armed and u[i - 1] <= 0.0 < u[i]:
            out.append(t[i - 1] + (t[i] - t[i - 1]) * (-u[i - 1]) / (u[i] - u[i - 1]))
            armed = False
    return np.asarray(out)


def detect_dwells(t_s, command_rad, *, period_tol: float = 0.02, min_cycles: int = 3) -> list[DwellSegment]:
    """Sine-dwell segments of a command: runs of upward zero crossings with a constant
    period, at least ``min_cycles`` cycles.

    A run continues while every period stays within ``period_tol`` of the run's *first*
    period (not merely of its neighbour), so the slowly changing period of a logarithmic
    sweep (about k/f per cycle, 1 % at 8 Hz for 0.5-14 Hz in 40 s) never passes as a dwell."""
    t = np.asarray(t_s, float)
    u = np.asarray(command_rad, float)
    amp = np.max(np.abs(u)) if u.size else 0.0
    if amp <= 0:
        return []
    tc = _rising_crossings(t, u, 0.05 * amp)
    segs: list[DwellSegment] = []
    if tc.size < 2:
        return segs
    P = np.diff(tc)
    start = 0
    for k in range(1, P.size + 1):
        if k == P.size or abs(P[k] / P[start] - 1.0) > period_tol:
            ncyc = k - start
            if ncyc >= min_cycles and abs(_period_drift(P[start:k])) <= 0.25 * period_tol:
                t0, t1 = tc[start], tc[k]
                segs.append(DwellSegment(float(t0), float(t1), float(ncyc / (t1 - t0)), int(ncyc)))
            start = k
    return segs


def _period_drift(P) -> float:
    """Relative change of the period over a run of periods, from a least-squares line
    (0 for a dwell up to crossing jitter; about n k / f for n cycles of a log sweep)."""
    P = np.asarray(P, float)
    if P.size < 2:
        return 0.0
    slope = np.polyfit(np.arange(P.size), P, 1)[0]
    return float(slope * (P.size - 1) / P.mean())


@dataclass(frozen=True)
class Excitation:
    """What a command record is, and why: ``kind`` is 'dwell', 'sweep', 'multisine' or
    'unknown'; ``reason`` one sentence with the evidence; ``method`` the estimator it calls for
    ('dwell', 'h1' or None when unsure); ``amplitude_rad`` the command's sine amplitude (the
    envelope of a sweep, the dwell amplitudes' maximum, the peak of a multisine)."""

    axis: str
    kind: str
    reason: str
    method: str | None
    freq_range_hz: tuple[float, float] = (math.nan, math.nan)
    amplitude_rad: float = math.nan

    def to_dict(self) -> dict:
        return {"axis": self.axis, "kind": self.kind, "reason": self.reason, "method": self.method,
                "freq_range_hz": [None if not math.isfinite(x) else x for x in self.freq_range_hz],
                "amplitude_deg": math.degrees(self.amplitude_rad) if math.isfinite(self.amplitude_rad) else None}


def classify_excitation(t_s, command_rad, axis: str = "pitch", *, dwell_fraction: float = 0.8,
                        monotone_fraction: float = 0.95, line_power: float = 0.95) -> Excitation:
    """Classify one command as sine dwells, a sweep or a multisine, with the evidence.

    Rules (in order), from the upward zero crossings (instantaneous frequency f_k = 1/P_k)
    and the record's periodogram:

    * **dwell** when constant-period runs (:func:`detect_dwells`) hold at least
      ``dwell_fraction`` of all cycles;
    * **sweep** when f_k moves one way in at least ``monotone_fraction`` of the cycles and
      spans more than a factor 1.5 (logarithmic if log f is closer to a line in time than f);
    * **multisine** when at most a few dozen spectral lines (peaks above 1 % of the largest,
      +-1 bin) hold at least ``line_power`` of the command's power;
    * else **unknown**: the caller refuses to guess (force ``--method``).
    """
    t = np.asarray(t_s, float)
    u = np.asarray(command_rad, float)
    u0 = u - np.mean(u)
    amp_pk = float(np.max(np.abs(u))) if u.size else 0.0
    if amp_pk <= 0:
        return Excitation(axis, "unknown", "the command is identically zero", None)
    tc = _rising_crossings(t, u, 0.05 * amp_pk)
    if tc.size < 4:
        return Excitation(axis, "unknown", f"only {tc.size} upward zero crossings (too few cycles to tell)", None)
    P = np.diff(tc)
    f_inst = 1.0 / P
    segs = detect_dwells(t, u)
    dwell_cycles = sum(s.cycles for s in segs)
    frac = dwell_cycles / P.size
    fr = (float(f_inst.min()), float(f_inst.max()))
    if frac >= dwell_fraction:
        fl = ", ".join(f"{s.freq_hz:.3g}" for s in segs)
        return Excitation(axis, "dwell", f"{len(segs)} constant-period segment(s) at {fl} Hz hold {frac:.0%} of "
                          f"the {P.size} cycles", "dwell", (min(s.freq_hz for s in segs), max(s.freq_hz for s in segs)),
                          amp_pk)
    df = np.diff(f_inst)
    up = float(np.mean(df > 0)) if df.size else 0.0
    mono = max(up, 1.0 - up)
    span = fr[1] / fr[0]
    if mono >= monotone_fraction and span > 1.5:
        tm = 0.5 * (tc[1:] + tc[:-1])
        r2 = {}
        for name, y in (("logarithmic", np.log(f_inst)), ("linear", f_inst)):
            c = np.polyfit(tm, y, 1)
            res = y - np.polyval(c, tm)
            r2[name] = 1.0 - float(np.sum(res ** 2) / max(np.sum((y - y.mean()) ** 2), 1e-300))
        kind = max(r2, key=r2.get)
        env = float(np.percentile(np.abs(u0), 99.9))
        return Excitation(axis, "sweep", f"instantaneous frequency {'rises' if up >= 0.5 else 'falls'} in {mono:.0%} "
                          f"of {P.size} cycles from {fr[0]:.3g} to {fr[1]:.3g} Hz ({kind} sweep: R^2 = {r2[kind]:.4f}); "
                          f"only {frac:.0%} of the cycles sit in constant-period runs", "h1", fr, env)
    spec = np.abs(np.fft.rfft(u0)) ** 2
    fbin = np.fft.rfftfreq(u0.size, float(np.median(np.diff(t))))
    pk = np.flatnonzero((spec > 0.01 * spec.max()) & (spec >= np.roll(spec, 1)) & (spec >= np.roll(spec, -1)))
    pk = pk[pk > 0]
    near = np.zeros(spec.size, bool)
    for k in pk:
        near[max(k - 1, 0):k + 2] = True
    share = float(spec[near].sum() / max(spec.sum(), 1e-300))
    if 2 <= pk.size <= 64 and share >= line_power:
        return Excitation(axis, "multisine", f"{pk.size} spectral lines from {fbin[pk].min():.3g} to "
                          f"{fbin[pk].max():.3g} Hz hold {share:.0%} of the command power; zero crossings are neither "
                          f"constant-period ({frac:.0%} of cycles) nor monotone ({mono:.0%})", "h1",
                          (float(fbin[pk].min()), float(fbin[pk].max())), amp_pk)
    return Excitation(axis, "unknown", f"not dwells ({frac:.0%} of {P.size} cycles at a constant period), not a sweep "
                      f"(frequency monotone in {mono:.0%} of cycles, span x{span:.2g}), not a multisine "
                      f"({pk.size} lines hold {share:.0%} of the power)", None, fr, amp_pk)


def classify_record(data: TestData) -> list[Excitation]:
    """:func:`classify_excitation` of each commanded axis of a record."""
    return [classify_excitation(data.t_s, data.command_rad[i], ax) for i, ax in enumerate(data.axes)]
