"""Frequency-response estimation from vectoring time histories (seed paper secs. 2.2, 3.2).

Two estimators, per axis, command -> piston (x_p / theta_c [m/rad]) and command -> engine
(theta / theta_c):

* **Sine dwells** (:func:`estimate_dwells`): dwell segments are found from the command (upward
  zero crossings with a constant period, at least 3 cycles) or given. In the last whole
  cycles of each segment (default: the second half, at least 2 cycles, so the transient of
  the segment change has decayed) command and outputs are fitted by least squares to
  ``a sin(w t) + b cos(w t) + c0 + c1 t`` plus sin/cos at the other axis' dwell frequency in
  that window (two axes excited at once at different frequencies are separated exactly;
  Green Run commanded both). H = (a_y + j b_y) / (a_u + j b_u). Over whole cycles this is the
  correlation estimate; the constant and slope absorb the string pots' unknown offset and a
  slow drift. Coherence is the fraction of the output's variance in the window explained by
  the fundamental; the 1-sigma relative error of H is sqrt(2/N) s / |Y| (s the fit residual
  RMS, N samples).
* **H1** (:func:`estimate_h1`, sweeps and multisines): H1 = S_uy / S_uu with Welch
  averaging (``scipy.signal.csd``/``welch``, constant detrend), coherence
  gamma^2 = |S_uy|^2 / (S_uu S_yy), random error of |H| sqrt((1 - gamma^2) / (2 n_d gamma^2))
  (Bendat & Piersol, *Random Data*, 4th ed., eq. 9.90) with n_d the number of averages.
  Results at the excited bins (S_uu above ``excitation_threshold`` of its peak, or at given
  frequencies). With two axes excited at once the inputs must not share bins (disjoint
  multisine sets with ``nperseg`` a whole number of periods and ``window='boxcar'``).

The engine angle's DC term is flagged unobservable (``engine_dc_observable``) when the data
has no absolute engine reference (string pots, paper sec. 2): the 0 Hz engine gain cannot be
estimated and fits never use it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from taos.harmonics import fit_sines

from taos.identify.data import TestData
from taos.identify.excitation import (  # noqa: F401 (re-exported: the estimators' segment finders)
    DwellSegment, Excitation, _rising_crossings, classify_excitation, classify_record, detect_dwells)
from taos.errors import InputError
from taos.linear import gain_db
from taos.units import from_si


@dataclass(frozen=True, eq=False)
class MeasuredResponse:
    """Estimated responses of one axis at discrete points (SI).

    ``piston_m_per_rad`` x_p / theta_c [m/rad] and ``engine`` theta / theta_c [-] (None when no
    engine angles) are complex; ``amplitude_rad`` the command amplitude at each point (NaN for
    broadband H1 points); ``sigma_*`` the 1-sigma relative error of H (of ln|H| and of the
    phase in rad); ``coherence_*`` in [0, 1].
    """

    axis: str
    freq_hz: np.ndarray
    amplitude_rad: np.ndarray
    piston_m_per_rad: np.ndarray
    engine: np.ndarray | None
    coherence_piston: np.ndarray
    coherence_engine: np.ndarray | None
    sigma_piston: np.ndarray
    sigma_engine: np.ndarray | None
    method: str = "sine-dwell"
    engine_dc_observable: bool = False
    source: str = ""
    condition: str = ""
    meta: dict = field(default_factory=dict)
    #: per point, the index of the command segment it was estimated from
    #: (:mod:`taos.identify.segments`; None when not segmented)
    segment_index: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.freq_hz.size)

    def select(self, mask) -> "MeasuredResponse":
        """The points where ``mask`` is true."""
        m = np.asarray(mask, bool)
        opt = lambda a: None if a is None else np.asarray(a)[m]  # noqa: E731
        return replace(self, freq_hz=self.freq_hz[m], amplitude_rad=self.amplitude_rad[m],
                       piston_m_per_rad=self.piston_m_per_rad[m], engine=opt(self.engine),
                       coherence_piston=self.coherence_piston[m], coherence_engine=opt(self.coherence_engine),
                       sigma_piston=self.sigma_piston[m], sigma_engine=opt(self.sigma_engine),
                       segment_index=opt(self.segment_index))

    def to_freqresp(self, moment_arm_m: float):
        """As a :class:`~taos.planar.freqresp.FrequencyResponse` (piston x_p / (R theta_c)) for plots."""
        from taos.planar.freqresp import FrequencyResponse
        amps = self.amplitude_rad[np.isfinite(self.amplitude_rad)]
        amp = float(np.median(amps)) if amps.size else None
        eng = self.engine if self.engine is not None else np.full(self.freq_hz.shape, np.nan + 0j)
        return FrequencyResponse(self.freq_hz, self.piston_m_per_rad / moment_arm_m, eng, amp, self.axis,
                                 friction_model="data", provenance={"source": self.source, "method": self.method})

    def phase_deg(self, h, reference_deg=None) -> np.ndarray:
        """Phase of ``h`` at these points [deg], continuous from low frequency: on the branch of
        ``reference_deg`` (a model's continuous phase at these points) when given, else
        unwrapped over all points in frequency order (dwells at 0.4 and 0.8 deg lie on one
        curve, as the test steps the amplitude up with frequency;
        :func:`taos.linear.phase_deg_continuous`). Sparse points far apart cannot be unwrapped
        without a reference: give the model (``taos estimate --model``)."""
        from taos.linear import phase_deg_continuous
        return phase_deg_continuous(self.freq_hz, np.asarray(h), reference_deg)

    def to_dict(self, moment_arm_m: float | None = None, model=None) -> dict:
        """JSON: ``piston`` is x_p / (R theta_c) (the project's piston convention) when the
        moment arm is known (argument, or ``meta['moment_arm_m']``), else null;
        ``piston_in_per_deg`` is x_p / theta_c in in/deg, named by its unit. Phases are
        continuous from low frequency (:meth:`phase_deg`; on ``model``'s branch when given,
        whose moment arm then also defines the piston)."""
        rp = re = None
        if model is not None and len(self):
            from taos.planar.freqresp import linear_phase_reference
            rp, re = linear_phase_reference(model, self.freq_hz, self.axis)
            moment_arm_m = model.actuator.moment_arm_m

        def gp(h, ref=None):
            return None if h is None else {"gain_db": gain_db(h).tolist(),
                                           "phase_deg": self.phase_deg(h, ref).tolist()}
        R = moment_arm_m if moment_arm_m is not None else self.meta.get("moment_arm_m")
        return {"axis": self.axis, "method": self.method, "source": self.source, "condition": self.condition,
                "excitation": self.meta.get("excitation"),
                "point_segment": None if self.segment_index is None else [int(k) for k in self.segment_index],
                "freq_hz": self.freq_hz.tolist(), "amplitude_deg": np.degrees(self.amplitude_rad).tolist(),
                "piston_definition": "x_p / (R theta_c), dimensionless" if R else
                "x_p / (R theta_c) needs the moment arm (taos estimate --model MODEL); see piston_in_per_deg",
                "moment_arm_m": R,
                "phase_reference": "model" if rp is not None else "data (unwrapped from the lowest frequency)",
                "piston": gp(self.piston_m_per_rad / R, rp) if R else None,
                "piston_in_per_deg": gp(self.piston_m_per_rad * from_si(1.0, "m/rad", "in/deg"), rp),
                "engine": gp(self.engine, re), "coherence_piston": self.coherence_piston.tolist(),
                "coherence_engine": None if self.coherence_engine is None else self.coherence_engine.tolist(),
                "engine_dc_observable": self.engine_dc_observable}


def estimate_dwells(data: TestData, axes=None, *, segments: dict | None = None, settle_fraction: float = 0.5,
                    min_cycles: int = 2) -> list[MeasuredResponse]:
    """Sine-dwell responses of each axis (see the module docstring).

    Parameters
    ----------
    data : TestData
    axes : iterable of str, optional
        Axes to estimate (default all in the data).
    segments : dict axis -> list of DwellSegment, optional
        Known segments (default: :func:`detect_dwells` on each command).
    settle_fraction : float
        Fraction of each segment's cycles skipped as transient.
    min_cycles : int
        Fewest whole cycles used per segment.
    """
    axes = data.axes if axes is None else tuple(axes)
    t = data.t_s
    segs = {ax: (segments or {}).get(ax) or detect_dwells(t, data.command_rad[data.axis_index(ax)])
            for ax in data.axes}
    out = []
    for ax in axes:
        i = data.axis_index(ax)
        if not segs[ax]:
            raise InputError(data.source, f"{ax}_command", "sine-dwell segments (>= 3 cycles at a constant period)",
                             got="none found (use the H1 estimator for sweeps and multisines)")
        rows = {k: [] for k in ("f", "A", "hp", "he", "cp", "ce", "sp", "se")}
        for sg in segs[ax]:
            ncyc = max(min_cycles, int(math.floor(sg.cycles * (1.0 - settle_fraction))))
            ncyc = min(ncyc, sg.cycles)
            period = 1.0 / sg.freq_hz
            w0, w1 = sg.t1_s - ncyc * period, sg.t1_s
            m = (t >= w0) & (t < w1)
            if m.sum() < 8 * ncyc:
                continue
            freqs = [sg.freq_hz]
            for other, osegs in segs.items():
                if other == ax:
                    continue
                for os_ in osegs:
                    if os_.t0_s < w1 and os_.t1_s > w0 and abs(os_.freq_hz / sg.freq_hz - 1) > 0.02:
                        freqs.append(os_.freq_hz)
            ys = [data.command_rad[i][m], data.piston_m[i][m]]
            if data.engine_rad is not None:
                ys.append(data.engine_rad[i][m])
            sf = fit_sines(t[m], ys, freqs, trend=True)
            Y, rms = sf.phasor[:, 0], sf.residual_rms
            U = Y[0]
            n = int(m.sum())
            var = np.var(np.asarray(ys), axis=1)
            coh = np.clip(0.5 * np.abs(Y) ** 2 / np.maximum(var, 1e-300), 0.0, 1.0)
            sig = np.sqrt(2.0 / n) * rms / np.maximum(np.abs(Y), 1e-300)
            rows["f"].append(sg.freq_hz)
            rows["A"].append(abs(U))
            rows["hp"].append(Y[1] / U)
            rows["cp"].append(coh[1])
            rows["sp"].append(math.hypot(sig[1], sig[0]))
            if data.engine_rad is not None:
                rows["he"].append(Y[2] / U)
                rows["ce"].append(coh[2])
                rows["se"].append(math.hypot(sig[2], sig[0]))
        has_e = data.engine_rad is not None
        arr = lambda k, dt=float: np.asarray(rows[k], dtype=dt)  # noqa: E731
        out.append(MeasuredResponse(ax, arr("f"), arr("A"), arr("hp", complex), arr("he", complex) if has_e else None,
                                    arr("cp"), arr("ce") if has_e else None, arr("sp"),
                                    arr("se") if has_e else None, "sine-dwell", data.engine_absolute,
                                    data.source, data.condition))
    return out


# -- H1 for sweeps and multisines -----------------------------------------------------------
def h1(u, y, fs_hz: float, nperseg: int, window="hann", noverlap=None):
    """H1 = S_uy / S_uu, coherence, the number of averages, and frequencies (scipy.signal)."""
    import scipy.signal as ss

    kw = dict(fs=fs_hz, nperseg=nperseg, window=window, detrend="constant", noverlap=noverlap)
    f, Puu = ss.welch(u, **kw)
    _, Pyy = ss.welch(y, **kw)
    _, Puy = ss.csd(u, y, **kw)
    H = Puy / np.where(Puu > 0, Puu, np.inf)
    coh = np.abs(Puy) ** 2 / np.maximum(Puu * Pyy, 1e-300)
    step = nperseg - (nperseg // 2 if noverlap is None else noverlap)
    nd = max(1, (len(u) - nperseg) // step + 1)
    return f, H, np.clip(coh, 0, 1), Puu, nd


def estimate_h1(data: TestData, axes=None, *, nperseg: int | None = None, window="hann", noverlap=None,
                freq_hz=None, excitation_threshold: float = 1e-2, band_hz=None) -> list[MeasuredResponse]:
    """H1 responses of each axis at its excited bins (see the module docstring).

    ``nperseg`` defaults to an eighth of the record (a power of two); ``freq_hz`` (list or
    dict axis -> list) picks the nearest bins instead of the excited ones. ``band_hz``: (f0, f1)
    [Hz] (or dict axis -> (f0, f1)), the excited band (a sweep's start and end frequencies): bins
    outside it are dropped, whatever the window's leakage puts there (a point below a sweep's start
    is not a measurement of the response there)."""
    axes = data.axes if axes is None else tuple(axes)
    fs = data.sample_rate_hz
    n = data.t_s.size
    nps = nperseg or int(2 ** max(4, math.floor(math.log2(max(16, n // 8)))))
    if nps > n:
        raise InputError(data.source, "nperseg", f"a segment no longer than the record ({n} samples)", got=str(nps))
    out = []
    for ax in axes:
        i = data.axis_index(ax)
        u = data.command_rad[i]
        f, Hp, cp, Puu, nd = h1(u, data.piston_m[i], fs, nps, window, noverlap)
        if freq_hz is not None:
            fl = freq_hz.get(ax, []) if isinstance(freq_hz, dict) else freq_hz
            idx = np.unique([int(np.argmin(np.abs(f - fk))) for fk in fl])
        else:
            idx = np.flatnonzero((Puu > excitation_threshold * Puu.max()) & (f > 0))
        band = band_hz.get(ax) if isinstance(band_hz, dict) else band_hz
        if band is not None and all(math.isfinite(x) for x in band):
            lo, hi = min(band), max(band)
            idx = idx[(f[idx] >= lo) & (f[idx] <= hi)]
            if not idx.size:
                raise InputError(data.source, f"{ax}_command", f"spectral bins within the excited band "
                                 f"{lo:.4g}-{hi:.4g} Hz (a longer record or a smaller nperseg)",
                                 got=f"none at {f[1] - f[0]:.4g} Hz resolution")
        He = ce = se = None
        if data.engine_rad is not None:
            _, He_, ce_, _, _ = h1(u, data.engine_rad[i], fs, nps, window, noverlap)
            He, ce = He_[idx], ce_[idx]
            se = np.sqrt((1 - ce) / (2 * nd * np.maximum(ce, 1e-12)))
        cpi = cp[idx]
        sp = np.sqrt((1 - cpi) / (2 * nd * np.maximum(cpi, 1e-12)))
        amp = np.sqrt(2.0 * Puu[idx] * (f[1] - f[0]))  # sine amplitude if the bin holds one line
        out.append(MeasuredResponse(ax, f[idx], amp, Hp[idx], He, cpi, ce, sp, se, "h1", data.engine_absolute,
                                    data.source, data.condition, meta={"nperseg": nps, "averages": nd}))
    return out


# -- mixed records: segment by segment ----------------------------------------------------
def _merge(rs: list, axis: str):
    """One MeasuredResponse of ``axis`` from per-segment responses (points in frequency order)."""
    order = np.argsort(np.concatenate([r.freq_hz for r in rs]), kind="stable")
    cat = lambda name, dt=float: np.concatenate([np.asarray(getattr(r, name), dt) for r in rs])[order]  # noqa: E731
    has_e = all(r.engine is not None for r in rs)
    r0 = rs[0]
    return MeasuredResponse(axis, cat("freq_hz"), cat("amplitude_rad"), cat("piston_m_per_rad", complex),
                            cat("engine", complex) if has_e else None, cat("coherence_piston"),
                            cat("coherence_engine") if has_e else None, cat("sigma_piston"),
                            cat("sigma_engine") if has_e else None, "+".join(sorted({r.method for r in rs})),
                            r0.engine_dc_observable, r0.source, r0.condition,
                            meta={k: v for r in rs for k, v in r.meta.items()}, segment_index=cat("segment_index", int))


def estimate_by_segment(data: TestData, axes=None, *, nperseg: int | None = None,
                        segments: dict | None = None) -> list[MeasuredResponse]:
    """Responses of each axis from its dwell, sweep and multisine segments
    (:mod:`taos.identify.segments`, whose docstring states the rules);
    each response's ``meta['segments']`` lists all the axis' segments (``used`` true for those
    estimated) and ``segment_index`` tags every point."""
    from taos.identify.segments import segment_record

    segs = segments if segments is not None else segment_record(data)
    axes = data.axes if axes is None else tuple(axes)
    dwell_runs = {ax: [s.dwell for s in ss if s.kind == "dwell"] for ax, ss in segs.items()}
    out = []
    for ax in axes:
        data.axis_index(ax)
        usable = [s for s in segs[ax] if s.method is not None]
        if not usable:
            found = "; ".join(f"{s.reason} (#{s.index} {s.kind} {s.t0_s:.2f}-{s.t1_s:.2f} s)" for s in segs[ax])
            raise InputError(data.source, f"{ax}_command", "a dwell, sweep or multisine segment on this axis (or "
                             "force --method dwell|h1)", got="unsure: " + found[:400])
        parts = []
        dw = [s for s in usable if s.kind == "dwell"]
        if dw:
            r = estimate_dwells(data, (ax,), segments={**dwell_runs, ax: [s.dwell for s in dw]})[0]
            idx = np.array([min(dw, key=lambda s: abs(s.dwell.freq_hz - f)).index for f in r.freq_hz], int)
            parts.append(replace(r, segment_index=idx))
        for s in usable:
            if s.method != "h1":
                continue
            sub = data.window(s.t0_s, s.t1_s)
            nps = nperseg
            if nps is not None and nps > sub.t_s.size:
                raise InputError("command line", "--nperseg", f"a segment length within the {sub.t_s.size} samples "
                                 f"of {ax} segment #{s.index} ({s.kind} {s.t0_s:.2f}-{s.t1_s:.2f} s)", got=str(nps))
            r = estimate_h1(sub, (ax,), nperseg=nps,   # a sweep's points lie within its start and end
                            band_hz=s.freq_range_hz if s.kind == "sweep" else None)[0]
            if s.kind == "sweep":  # the envelope is the amplitude the describing function sees
                r = replace(r, amplitude_rad=np.full(r.freq_hz.shape, s.amplitude_rad))
            parts.append(replace(r, segment_index=np.full(r.freq_hz.shape, s.index, int)))
        merged = _merge(parts, ax)
        used = {s.index for s in usable}
        out.append(replace(merged, meta={**merged.meta, "segments": [
            {**s.to_dict(), "used": s.index in used} for s in segs[ax]]}))
    return out


def choose_method(data: TestData, method: str = "auto") -> tuple[str, list[Excitation]]:
    """The estimator for a record and the per-axis evidence (:func:`classify_excitation`).

    ``method`` 'dwell' or 'h1' forces it (the evidence is still returned); 'auto' takes the
    classification and refuses (:class:`InputError`, naming the axis and the evidence) when an
    axis is 'unknown' or the axes call for different estimators."""
    if method not in ("auto", "dwell", "h1"):
        raise InputError("command line", "--method", "auto, dwell or h1", got=repr(method))
    exc = classify_record(data)
    if method != "auto":
        return method, exc
    for e in exc:
        if e.method is None:
            raise InputError(data.source, f"{e.axis}_command", "sine dwells, a sweep or a multisine (or force "
                             "--method dwell|h1)", got=f"unsure: {e.reason}")
    methods = {e.method for e in exc}
    if len(methods) > 1:
        raise InputError(data.source, "(commands)", "one kind of excitation on every axis (or force --method)",
                         got="; ".join(f"{e.axis}: {e.kind}" for e in exc))
    return methods.pop(), exc


def estimate(data: TestData, method: str = "auto", **kwargs: Any) -> list[MeasuredResponse]:
    """Responses of a record, one per axis.

    ``method`` 'auto' classifies each axis' command segment by segment
    (:func:`taos.identify.segments.segment_record`: dwells, sweeps, multisines, steps/ramps,
    quiet) and estimates every dwell, sweep and multisine segment with its own estimator
    (:func:`taos.identify.segments.estimate_by_segment`), so pitch dwells and a yaw sweep in one
    record are estimated in one call; ``meta['excitation']`` sums up what was found and why and
    ``meta['segments']`` lists the segments. 'dwell' or 'h1' forces one estimator over the whole
    record (the whole-record classification :func:`classify_record` is then the evidence).
    For a sweep the H1 points carry the sweep's envelope amplitude (the amplitude the
    describing function sees), not the bin's share of the power."""
    from taos.bounds import check_choice, check_instance

    check_instance(data, "data", TestData, "a TestData record (taos.load_test_data)")
    check_choice(method, "method", ("auto", "dwell", "h1"))
    extra = {"moment_arm_m": float(data.metadata["moment_arm_m"])} if "moment_arm_m" in data.metadata else {}
    if method == "auto":
        from taos.identify.segments import axis_excitation, segment_record

        unknown = set(kwargs) - {"axes", "nperseg"}
        if unknown:
            raise InputError("argument", ", ".join(sorted(unknown)), "with method='auto' only axes and nperseg",
                             got="other keyword arguments")
        segs = segment_record(data)
        out = estimate_by_segment(data, kwargs.get("axes"), nperseg=kwargs.get("nperseg"), segments=segs)
        return [replace(r, meta={**r.meta, "excitation": {**axis_excitation(segs[r.axis]),
                                                          "segments": r.meta["segments"]},
                                 "method_forced": False, **extra}) for r in out]
    chosen, exc = choose_method(data, method)
    by_axis = {e.axis: e for e in exc}
    if chosen == "h1" and "band_hz" not in kwargs and "freq_hz" not in kwargs:   # a sweep's excited band
        kwargs = {**kwargs, "band_hz": {e.axis: e.freq_range_hz for e in exc if e.kind == "sweep"}}
    out = estimate_dwells(data, **kwargs) if chosen == "dwell" else estimate_h1(data, **kwargs)
    res = []
    for r in out:
        e = by_axis[r.axis]
        if chosen == "h1" and e.kind == "sweep":
            r = replace(r, amplitude_rad=np.full(r.freq_hz.shape, e.amplitude_rad))
        res.append(replace(r, meta={**r.meta, "excitation": e.to_dict(), "method_forced": True, **extra}))
    return res
