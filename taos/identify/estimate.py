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

import numpy as np

from taos.identify.data import TestData
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

    def __len__(self) -> int:
        return int(self.freq_hz.size)

    def select(self, mask) -> "MeasuredResponse":
        """The points where ``mask`` is true."""
        m = np.asarray(mask, bool)
        opt = lambda a: None if a is None else np.asarray(a)[m]  # noqa: E731
        return replace(self, freq_hz=self.freq_hz[m], amplitude_rad=self.amplitude_rad[m],
                       piston_m_per_rad=self.piston_m_per_rad[m], engine=opt(self.engine),
                       coherence_piston=self.coherence_piston[m], coherence_engine=opt(self.coherence_engine),
                       sigma_piston=self.sigma_piston[m], sigma_engine=opt(self.sigma_engine))

    def to_freqresp(self, moment_arm_m: float):
        """As a :class:`~taos.freqresp.FrequencyResponse` (piston x_p / (R theta_c)) for plots."""
        from taos.freqresp import FrequencyResponse
        amps = self.amplitude_rad[np.isfinite(self.amplitude_rad)]
        amp = float(np.median(amps)) if amps.size else None
        eng = self.engine if self.engine is not None else np.full(self.freq_hz.shape, np.nan + 0j)
        return FrequencyResponse(self.freq_hz, self.piston_m_per_rad / moment_arm_m, eng, amp, self.axis,
                                 friction_model="data", provenance={"source": self.source, "method": self.method})

    def to_dict(self) -> dict:
        def gp(h):
            return None if h is None else {"gain_db": gain_db(h).tolist(),
                                           "phase_deg": np.degrees(np.angle(h)).tolist()}
        return {"axis": self.axis, "method": self.method, "source": self.source, "condition": self.condition,
                "freq_hz": self.freq_hz.tolist(), "amplitude_deg": np.degrees(self.amplitude_rad).tolist(),
                "piston_in_per_deg": gp(self.piston_m_per_rad * from_si(1.0, "m/rad", "in/deg")),
                "engine": gp(self.engine), "coherence_piston": self.coherence_piston.tolist(),
                "coherence_engine": None if self.coherence_engine is None else self.coherence_engine.tolist(),
                "engine_dc_observable": self.engine_dc_observable}


@dataclass(frozen=True)
class DwellSegment:
    """A sine-dwell segment of one axis' command: [t0_s, t1_s] holding ``cycles`` whole cycles."""

    t0_s: float
    t1_s: float
    freq_hz: float
    cycles: int


# -- sine dwells --------------------------------------------------------------------------
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
    period (within ``period_tol``), at least ``min_cycles`` cycles."""
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
        if k == P.size or abs(P[k] / P[k - 1] - 1.0) > period_tol:
            ncyc = k - start
            if ncyc >= min_cycles:
                t0, t1 = tc[start], tc[k]
                segs.append(DwellSegment(float(t0), float(t1), float(ncyc / (t1 - t0)), int(ncyc)))
            start = k
    return segs


def _lsq_harmonics(t, ys, freqs):
    """Least squares of each row of ys on [sin, cos] at each of ``freqs`` plus c0 + c1 t.

    Returns (coefficients (n_rows, 2 len(freqs) + 2), residual RMS per row)."""
    tm = t - t.mean()
    cols = []
    for f in freqs:
        w = 2 * np.pi * f
        cols += [np.sin(w * t), np.cos(w * t)]
    cols += [np.ones_like(t), tm]
    X = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(X, np.asarray(ys).T, rcond=None)
    res = np.asarray(ys).T - X @ coef
    dof = max(1, t.size - X.shape[1])
    return coef.T, np.sqrt(np.sum(res ** 2, axis=0) / dof)


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
            coef, rms = _lsq_harmonics(t[m], ys, freqs)
            Y = coef[:, 0] + 1j * coef[:, 1]
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
                freq_hz=None, excitation_threshold: float = 1e-2) -> list[MeasuredResponse]:
    """H1 responses of each axis at its excited bins (see the module docstring).

    ``nperseg`` defaults to an eighth of the record (a power of two); ``freq_hz`` (list or
    dict axis -> list) picks the nearest bins instead of the excited ones."""
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


def estimate(data: TestData, method: str = "auto", **kwargs) -> list[MeasuredResponse]:
    """Dwell estimate where the commands are sine dwells, else H1 (``method`` 'dwell', 'h1'
    or 'auto')."""
    if method == "dwell" or (method == "auto" and all(detect_dwells(data.t_s, c) for c in data.command_rad)):
        return estimate_dwells(data, **kwargs)
    if method in ("h1", "auto"):
        return estimate_h1(data, **kwargs)
    raise InputError("command line", "--method", "auto, dwell or h1", got=repr(method))
