"""Excitation classified per axis and per segment of a vectoring record, and the responses
estimated segment by segment (``taos estimate --method auto``).

A test record often mixes excitations: pitch dwells while yaw sweeps, a quiet stretch, a step.
:func:`segment_command` splits one axis' command theta_c(t) into segments, each with its kind,
time span and evidence:

1. **dwell**: runs of upward zero crossings at a constant period, at least 3 cycles
   (:func:`taos.identify.excitation.detect_dwells` on the whole command, so a record made of
   dwells only is estimated exactly as before). The crossing detector counts a dwell from its
   first *armed* crossing and ends it at its last one, so the first cycle of a record and the
   last cycle before a stop fall outside; an active remainder shorter than 1.5 periods beside
   a dwell is counted as part of it (ramp-in / last cycle).
2. **quiet**: outside the dwells, where the command stays within ``quiet_tol`` (1 % of the
   axis' peak |theta_c - median|) of a constant over a sliding window of ``window_s`` (0.2 s),
   the flat windows widened by half a window (a morphological opening), kept when they last at
   least ``min_quiet_s`` (0.4 s). A sine slower than about 0.1 Hz is flat enough at its peaks
   to read as quiet for up to ~0.35 s, below that minimum.
3. The active remainders between them: **sweep** or **multisine** by
   :func:`taos.identify.excitation.classify_excitation` on the piece (monotone instantaneous
   frequency; a few spectral lines holding 95 % of the power); **step/ramp** when the piece has
   fewer than 4 upward zero crossings about its mean and the command moves from one level to
   another (net change at least half its range); else **unknown** (reported, never used).

Estimation (:func:`taos.identify.estimation.estimate_by_segment`): the dwell segments of an axis by the sine-dwell
correlation (:func:`~taos.identify.estimation.estimate_dwells`, with the other axis' dwell
frequencies fitted alongside), each sweep or multisine segment by H1
(:func:`~taos.identify.estimation.estimate_h1`) over its own time span only; the points of one
axis merged into one :class:`~taos.identify.estimation.MeasuredResponse` in frequency order,
each point tagged with its segment (``segment_index``). Steps, ramps and quiet segments carry no
frequency response and are reported only. An axis with no dwell, sweep or multisine segment is
refused (:class:`~taos.errors.InputError` naming the axis and its segments). Cross-axis
coupling is separated only for dwells on both axes (exactly, by the joint fit); a sweep on the
other axis during a dwell adds its coupled response, uncorrelated with the dwell's frequency
except where the sweep passes it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from taos.identify.data import TestData

#: segment kinds, and the estimator each calls for (None: reported only)
KIND_METHOD = {"dwell": "dwell", "sweep": "h1", "multisine": "h1", "step/ramp": None, "quiet": None,
               "unknown": None}


@dataclass(frozen=True)
class ExcitationSegment:
    """One segment of one axis' command: ``kind`` (see :data:`KIND_METHOD`) over
    [``t0_s``, ``t1_s``] [s], its frequency range [Hz] and command amplitude [rad] (sine
    amplitude of a dwell, envelope of a sweep, peak of a multisine, level change of a step/ramp,
    level of a quiet stretch), the estimator it calls for, and the evidence in one sentence.
    ``dwell`` is the detected constant-period run a dwell's estimate uses."""

    axis: str
    index: int
    kind: str
    t0_s: float
    t1_s: float
    reason: str
    freq_range_hz: tuple[float, float] = (math.nan, math.nan)
    amplitude_rad: float = math.nan
    dwell: object = None

    @property
    def method(self) -> str | None:
        return KIND_METHOD[self.kind]

    def to_dict(self) -> dict:
        fin = lambda x: x if math.isfinite(x) else None  # noqa: E731
        return {"axis": self.axis, "index": self.index, "kind": self.kind, "t0_s": self.t0_s, "t1_s": self.t1_s,
                "method": self.method, "freq_range_hz": [fin(x) for x in self.freq_range_hz],
                "amplitude_deg": fin(math.degrees(self.amplitude_rad)), "reason": self.reason}

    def line(self) -> str:
        """'pitch #2 dwell 4.00-8.00 s, 2 Hz, 0.4 deg: ...' (the text report's row)."""
        f0, f1 = self.freq_range_hz
        fr = "" if not math.isfinite(f0) else (f", {f0:.3g} Hz" if f1 <= f0 * 1.0001 else f", {f0:.3g}-{f1:.3g} Hz")
        a = f", {math.degrees(self.amplitude_rad):.3g} deg" if math.isfinite(self.amplitude_rad) else ""
        return f"{self.axis} #{self.index} {self.kind} {self.t0_s:.2f}-{self.t1_s:.2f} s{fr}{a}: {self.reason}"


def _runs(mask) -> list[tuple[int, int]]:
    """[(i0, i1)) index runs where ``mask`` is true."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist()))


def _quiet_mask(t, u, tol: float, window_s: float, min_quiet_s: float):
    """True where the command is flat (module docstring, rule 2)."""
    from scipy.ndimage import maximum_filter1d, minimum_filter1d

    dt = float(np.median(np.diff(t)))
    w = max(3, int(round(window_s / dt)) | 1)
    rng = maximum_filter1d(u, w, mode="nearest") - minimum_filter1d(u, w, mode="nearest")
    # widened by half a window less two samples: two holds at different levels stay apart, the
    # samples of the jump between them an active piece of their own (a step)
    flat = maximum_filter1d((rng <= tol).astype(np.int8), max(1, w - 4), mode="constant", cval=0).astype(bool)
    out = np.zeros(u.size, bool)
    for i0, i1 in _runs(flat):
        if t[i1 - 1] - t[i0] >= min_quiet_s:
            out[i0:i1] = True
    return out


def _classify_piece(t, u, axis: str) -> tuple[str, str, tuple[float, float], float]:
    """(kind, reason, freq range, amplitude) of an active piece that is not a dwell."""
    from taos.identify.excitation import _rising_crossings, classify_excitation

    u0 = u - u.mean()
    rng = float(u.max() - u.min())
    n_cross = _rising_crossings(t, u0, 0.05 * max(float(np.max(np.abs(u0))), 1e-300)).size
    if n_cross < 4:
        net = float(u[-1] - u[0])
        if abs(net) >= 0.5 * rng and rng > 0:
            return ("step/ramp", f"the command moves from {math.degrees(u[0]):.3g} to {math.degrees(u[-1]):.3g} deg "
                    f"in {t[-1] - t[0]:.3g} s ({n_cross} zero crossings about its mean)", (math.nan, math.nan),
                    abs(net))
        return ("unknown", f"{n_cross} upward zero crossings in {t[-1] - t[0]:.3g} s and no level change: too short "
                "to tell", (math.nan, math.nan), 0.5 * rng)
    e = classify_excitation(t, u, axis)
    kind = e.kind if e.kind in ("sweep", "multisine") else "unknown"
    reason = e.reason if e.kind != "dwell" else f"constant-period runs too short for a dwell ({e.reason})"
    return kind, reason, e.freq_range_hz, e.amplitude_rad


def segment_command(t_s, command_rad, axis: str = "pitch", *, quiet_tol: float = 0.01, window_s: float = 0.2,
                    min_quiet_s: float = 0.4) -> list[ExcitationSegment]:
    """The segments of one axis' command in time order (module docstring).

    Parameters
    ----------
    t_s : array, shape (n,)
        Sample times [s], strictly increasing.
    command_rad : array, shape (n,)
        Command theta_c [rad].
    axis : str
        Axis name carried by the segments.
    quiet_tol : float
        Flatness tolerance of a quiet stretch, relative to the axis' peak |theta_c - median|.
    window_s : float
        Sliding window of the flatness test [s].
    min_quiet_s : float
        Shortest quiet stretch [s].
    """
    from taos.identify.excitation import detect_dwells

    t = np.asarray(t_s, float)
    u = np.asarray(command_rad, float)
    amp = float(np.max(np.abs(u - np.median(u)))) if u.size else 0.0
    if amp <= 0.0:
        return [ExcitationSegment(axis, 0, "quiet", float(t[0]), float(t[-1]),
                                  f"the command is constant at {math.degrees(u[0]):.3g} deg",
                                  amplitude_rad=float(u[0]))]
    pieces: list[list] = []                # [kind, i0, i1, dwell]
    dwells = detect_dwells(t, u)
    taken = np.zeros(u.size, bool)
    for d in dwells:
        i0, i1 = np.searchsorted(t, [d.t0_s, d.t1_s])
        taken[i0:i1] = True
        pieces.append(["dwell", int(i0), int(i1), d])
    quiet = _quiet_mask(t, u, quiet_tol * amp, window_s, min_quiet_s) & ~taken
    for i0, i1 in _runs(quiet):
        pieces.append(["quiet", i0, i1, None])
    for i0, i1 in _runs(~(taken | quiet)):
        pieces.append(["active", i0, i1, None])
    pieces.sort(key=lambda p: p[1])
    # an active remainder shorter than 1.5 periods beside a dwell is its ramp-in or last cycle
    for k, p in enumerate(pieces):
        if p[0] != "active":
            continue
        for nb in (pieces[k - 1] if k else None, pieces[k + 1] if k + 1 < len(pieces) else None):
            if nb is not None and nb[0] == "dwell" and t[min(p[2], t.size - 1)] - t[p[1]] <= 1.5 / nb[3].freq_hz:
                p[0] = "absorbed"
                nb[1], nb[2] = min(nb[1], p[1]), max(nb[2], p[2])
                break
    out = []
    for kind, i0, i1, d in (p for p in pieces if p[0] != "absorbed"):
        j1 = min(i1, t.size - 1)
        ts, us = t[i0:i1 + 1], u[i0:i1 + 1]
        if kind == "dwell":
            reason = f"{d.cycles} whole cycles at a constant period ({d.freq_hz:.4g} Hz)"
            a = float(0.5 * (us.max() - us.min()))
            seg = ExcitationSegment(axis, 0, "dwell", float(t[i0]), float(t[j1]), reason, (d.freq_hz, d.freq_hz), a, d)
        elif kind == "quiet":
            seg = ExcitationSegment(axis, 0, "quiet", float(t[i0]), float(t[j1]),
                                    f"the command holds {math.degrees(float(np.median(us))):.3g} deg within "
                                    f"{math.degrees(quiet_tol * amp):.2g} deg", amplitude_rad=float(np.median(us)))
        else:
            k, reason, fr, a = _classify_piece(ts, us, axis) if ts.size >= 4 else \
                ("unknown", f"{ts.size} samples: too short to tell", (math.nan, math.nan), math.nan)
            seg = ExcitationSegment(axis, 0, k, float(t[i0]), float(t[j1]), reason, fr, a)
        out.append(seg)
    return [replace(s, index=i) for i, s in enumerate(out)]


def segment_record(data: TestData) -> dict[str, list[ExcitationSegment]]:
    """:func:`segment_command` of every commanded axis of a record: {axis: segments}."""
    return {ax: segment_command(data.t_s, data.command_rad[i], ax) for i, ax in enumerate(data.axes)}


def axis_excitation(segs: list[ExcitationSegment]) -> dict:
    """The per-axis ``excitation`` entry of a response (kind, reason, method, range, amplitude):
    one kind when the used segments share it, else their kinds joined by '+'."""
    usable = [s for s in segs if s.method is not None]
    kinds = list(dict.fromkeys(s.kind for s in usable)) or ["unknown"]
    f0 = [s.freq_range_hz[0] for s in usable if math.isfinite(s.freq_range_hz[0])]
    f1 = [s.freq_range_hz[1] for s in usable if math.isfinite(s.freq_range_hz[1])]
    a = [s.amplitude_rad for s in usable if math.isfinite(s.amplitude_rad)]
    methods = sorted({s.method for s in usable})
    spans = lambda ss: "; ".join(f"#{s.index} {s.kind} {s.t0_s:.2f}-{s.t1_s:.2f} s" for s in ss)  # noqa: E731
    if len(usable) == 1:
        rest = [s for s in segs if s is not usable[0]]
        reason = usable[0].reason + (f" (#{usable[0].index}, {usable[0].t0_s:.2f}-{usable[0].t1_s:.2f} s; also "
                                     f"{spans(rest)})" if rest else "")
    else:
        counts = ", ".join(f"{sum(s.kind == k for s in segs)} {k}" for k in dict.fromkeys(s.kind for s in segs))
        reason = f"{len(segs)} segments ({counts}): {spans(segs)}"
    return {"kind": "+".join(kinds), "reason": reason, "method": "+".join(methods) if methods else None,
            "freq_range_hz": [min(f0) if f0 else None, max(f1) if f1 else None],
            "amplitude_deg": math.degrees(max(a)) if a else None}
