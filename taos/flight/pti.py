"""What flight shows (seed paper sec. 5): the TVC and flight-control responses a flight's PTIs give.

The Artemis I flight injected programmed test inputs (PTIs: multisines and sweeps) on both axes
during quiescent flight; from them the TVC command-to-piston response and the flight-control open
loop were reconstructed, and the loop showed a gain reduction consistent with gimbal friction.
:func:`analyse_ptis` does this for a flight record (:mod:`taos.flight.pti_record`: the PTI r, the
TVC command u, the piston, optionally the engine angle) and the ascent file that defines the PTIs.

**The loop broken at the PTI.** The PTI is added to the flight-control output,
u = u_fcs + r (:mod:`taos.flight.pti_model`), so with the loop input u and its output u_fcs,
u_fcs = -L u, and the closed loop gives U = R / (1 + L), U_fcs = -L R / (1 + L). The
reconstruction is the ratio of the measured phasors (the "joint input-output" estimate: both
outputs referred to the known injection r, so noise uncorrelated with r, the wind and any limit
cycle, averages out rather than biasing L)::

    L(f) = -U_fcs(f) / U(f),   U_fcs = U - R;    G_piston(f) = X_p(f) / U(f);   G_engine = Theta / U.

**Phasors at the PTI's own lines, no bin loss.** Every phasor is the Fourier transform of the
signal over the analysis window [t0, t1 + tail] (the PTI window and a tail, default 20 s, in which
the closed loop's response to the PTI dies out), evaluated exactly at the wanted frequencies,
X(f) = sum_k x(t_k) exp(-j 2 pi f t_k) dt, after removing a straight baseline through the
signal's means over 1 s before t0 and 1 s at the end of the tail. For a linear loop starting from
its quiescent state this is exact at any frequency, whatever the window length (the whole
transient is in the window: Y(f) = H(f) R(f) for the zero-state response; Pintelon & Schoukens,
*System Identification*, 2nd ed., ch. 6, transient/leakage term); a multisine is evaluated at its
lines (:meth:`taos.flight.ascent.Pti.signal`: 0.1 to 3 Hz geometric, not on any DFT bin grid),
a sweep on a geometric grid of 8 points per octave over its band. A single window of the whole
response is H1 = S_ry / S_rr with one average.

**Uncertainty and coherence.** The noise at a line is the same transform over the stretches
before the window and after the tail (each used when at least 5 s long, at most as long as the
window; the two averaged), averaged over the 7 frequencies f + k / T_n (k = -3..3) and scaled by
the length ratio: var N(f) = mean |N(f_k)|^2 T / T_n. It is the noise (wind response, limit
cycle) only: a time-varying vehicle over the window or a response outlasting the tail is not in it.
The 1-sigma relative errors are then sigma_U / |U| for U and, since R is known exactly,
sigma_L / |L| = sigma_U |R| / (|U_fcs| |U|), sigma_Gp^2 / |Gp|^2 = var_Xp / |Xp|^2 + var_U / |U|^2.
Coherence gamma^2 = max(0, 1 - var_Y / |Y|^2) (the share of the output at the line explained by
the PTI). Without a noise stretch they are NaN (null in JSON).

**Friction verdict.** Over the lines at or below ``low_band_hz`` (default 0.5 Hz), the
inverse-variance weighted mean of 20 log10 |L_meas / L_model| [dB] and its 1-sigma: friction is
*visible* when the mean lies more than 2 sigma (and at least 0.2 dB) below the linear model.
The friction-degraded model L_DF (the TVC's describing function at the window's command amplitude
A = sqrt(2) RMS(u - baseline), a sine of the same power) is overlaid and its low-band gain quoted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from taos.errors import InputError
from taos.flight.pti_model import LoopPrediction, describing_engine, predict_loop
from taos.flight.pti_record import FlightRecord, record_window
from taos.results import model_provenance, package_version

TAIL_S = 20.0
BASE_S = 1.0
LOW_BAND_HZ = 0.5
MIN_NOISE_S = 5.0


def transform(t_s: np.ndarray, x: np.ndarray, freq_hz: np.ndarray) -> np.ndarray:
    """X(f) = sum_k x_k exp(-j 2 pi f t_k) dt over the samples given (uniform ``t_s`` [s]),
    relative to the first sample's time, at ``freq_hz`` [Hz]; [x's unit * s]."""
    dt = float(t_s[1] - t_s[0])
    tt = t_s - t_s[0]
    return (np.exp(-2j * np.pi * np.outer(freq_hz, tt)) @ x) * dt


def _detrended(t: np.ndarray, x: np.ndarray, n_base: int) -> np.ndarray:
    """``x`` less the straight line through its means over the first and the last ``n_base`` samples."""
    a, b = float(np.mean(x[:n_base])), float(np.mean(x[-n_base:]))
    ta, tb = float(np.mean(t[:n_base])), float(np.mean(t[-n_base:]))
    return x - (a + (b - a) * (t - ta) / (tb - ta))


@dataclass(frozen=True)
class Phasors:
    """Transforms of one analysis window at ``freq_hz``: the PTI ``r``, the command ``u``, the
    piston ``xp`` and the engine ``th`` (None if not recorded) [unit s], and their noise
    variances (NaN without a noise stretch); the window [t0, t1] [s], the equivalent command
    amplitude [rad] (sqrt(2) RMS of the detrended u over the PTI) and the noise stretches used [s]."""

    freq_hz: np.ndarray
    r: np.ndarray
    u: np.ndarray
    xp: np.ndarray
    th: np.ndarray | None
    var_u: np.ndarray
    var_xp: np.ndarray
    var_th: np.ndarray | None
    t0_s: float
    t1_s: float
    amplitude_rad: float
    noise_s: tuple


def window_phasors(rec: FlightRecord, axis: str, t0_s: float, t1_s: float, freq_hz, tail_s: float = TAIL_S) -> Phasors:
    """The phasors of the PTI window [t0, t1] [s] of ``axis`` with its ``tail_s`` [s] (module docstring)."""
    f = np.atleast_1d(np.asarray(freq_hz, float))
    dt = rec.dt_s
    nb = max(2, int(round(BASE_S / dt)))
    w = record_window(rec, t0_s - BASE_S, t1_s + tail_s)
    if w.stop - w.start < 4 * nb or rec.t_s[w.start] > t0_s + dt or rec.t_s[w.stop - 1] < t1_s:
        raise InputError(rec.source, f"{axis} PTI window {t0_s:g}-{t1_s:g} s",
                         f"a record covering it from {t0_s - BASE_S:g} s to {t1_s + tail_s:g} s (with its tail)",
                         got=f"{rec.t_s[0]:g}-{rec.t_s[-1]:g} s")
    t = rec.t_s[w]
    names = ("pti_rad", "command_rad", "piston_m", "engine_rad")
    sig = {k: rec.signal(k, axis) for k in names}
    out = {k: None if s is None else transform(t, _detrended(t, s[w], nb), f) for k, s in sig.items()}
    out["pti_rad"] = transform(t, sig["pti_rad"][w], f)      # known exactly, zero outside the PTI
    T = t[-1] - t[0]
    # the noise stretch: before the window, else after it
    pre = record_window(rec, rec.t_s[0], t[0] - dt)
    post = record_window(rec, t[-1] + dt, rec.t_s[-1])
    var = {k: None if sig[k] is None else np.full(f.size, np.nan) for k in names[1:]}
    noise = []
    for s in (pre, post):
        if (s.stop - s.start) * dt < MIN_NOISE_S:
            continue
        n = min(s.stop - s.start, w.stop - w.start)
        s = slice(s.stop - n, s.stop) if s is pre else slice(s.start, s.start + n)
        tn = rec.t_s[s]
        Tn = tn[-1] - tn[0]
        fk = (f[:, None] + np.arange(-3, 4)[None, :] / Tn).ravel()
        for k in names[1:]:
            if sig[k] is not None:
                N = transform(tn, _detrended(tn, sig[k][s], nb), np.abs(fk)).reshape(f.size, 7)
                v = np.mean(np.abs(N) ** 2, axis=1) * T / Tn
                var[k] = v if not noise else 0.5 * (var[k] + v)
        noise.append((float(tn[0]), float(tn[-1])))
    sel = (t >= t0_s) & (t <= t1_s)
    ud = _detrended(t, sig["command_rad"][w], nb)[sel]
    amp = math.sqrt(2.0) * float(np.sqrt(np.mean(ud ** 2)))
    return Phasors(f, out["pti_rad"], out["command_rad"], out["piston_m"], out["engine_rad"], var["command_rad"],
                   var["piston_m"], var["engine_rad"], float(t0_s), float(t1_s), amp, tuple(noise))


def _coh(var, y):
    return np.clip(1.0 - var / np.maximum(np.abs(y) ** 2, 1e-300), 0.0, 1.0)


@dataclass(frozen=True, eq=False)
class PtiMeasurement:
    """What one PTI window of one axis shows, at its lines ``freq_hz`` [Hz] (complex arrays):
    the open loop broken at the PTI injection ``loop`` (L, module docstring) with 1-sigma
    relative error ``loop_sigma`` and ``loop_coherence``; the TVC command-to-piston ``piston``
    [m/rad] and command-to-engine ``engine`` [-] (None without engine angles) with theirs; the
    window's equivalent command amplitude [rad] and the noise stretches used [s]."""

    axis: str
    kind: str
    start_s: float
    end_s: float
    amplitude_rad: float
    freq_hz: np.ndarray
    loop: np.ndarray
    loop_sigma: np.ndarray
    loop_coherence: np.ndarray
    piston: np.ndarray
    piston_sigma: np.ndarray
    piston_coherence: np.ndarray
    engine: np.ndarray | None
    engine_sigma: np.ndarray | None
    noise_s: tuple = ()


def measure_pti(rec: FlightRecord, axis: str, pti, tail_s: float = TAIL_S) -> PtiMeasurement:
    """Reconstruct the loop and the TVC responses of one PTI window (``pti``, a
    :class:`taos.flight.ascent.Pti`) of ``axis`` from the record alone (module docstring)."""
    f = pti_lines(pti)
    ph = window_phasors(rec, axis, pti.start_s, pti.end_s, f, tail_s)
    ufcs = ph.u - ph.r
    su = np.sqrt(ph.var_u)
    Ge = Ge_sig = None
    if ph.th is not None:
        Ge = ph.th / ph.u
        Ge_sig = np.sqrt(ph.var_th / np.abs(ph.th) ** 2 + ph.var_u / np.abs(ph.u) ** 2)
    return PtiMeasurement(axis, pti.kind, pti.start_s, pti.end_s, ph.amplitude_rad, f, -ufcs / ph.u,
                          su * np.abs(ph.r) / np.maximum(np.abs(ufcs) * np.abs(ph.u), 1e-300), _coh(ph.var_u, ufcs),
                          ph.xp / ph.u, np.sqrt(ph.var_xp / np.abs(ph.xp) ** 2 + ph.var_u / np.abs(ph.u) ** 2),
                          _coh(ph.var_xp, ph.xp), Ge, Ge_sig, ph.noise_s)


@dataclass(frozen=True, eq=False)
class PtiResponse:
    """One PTI window: the reconstruction ``measured`` (:class:`PtiMeasurement`), the model's
    linear prediction ``model`` (:class:`~taos.flight.pti_model.LoopPrediction`) and its
    friction-degraded loop ``model_loop_df`` / piston ``model_piston_df`` [m/rad] at the window's
    command amplitude (None when not computed); the friction verdict (:meth:`friction`)."""

    measured: PtiMeasurement
    model: LoopPrediction
    model_loop_df: np.ndarray | None = None
    model_piston_df: np.ndarray | None = None
    low_band_hz: float = LOW_BAND_HZ

    def __getattr__(self, name):      # the measurement's fields read through (r.loop, r.freq_hz, ...)
        if name.startswith("__") or name == "measured":
            raise AttributeError(name)
        return getattr(self.measured, name)

    def gain_difference_db(self) -> tuple[np.ndarray, np.ndarray]:
        """(20 log10 |L / L_model| [dB], its 1-sigma [dB]) per line."""
        d = 20 * np.log10(np.abs(self.loop) / np.abs(self.model.loop))
        return d, 20 / math.log(10) * self.loop_sigma

    def friction(self) -> dict:
        """The verdict (module docstring): ``low_band_gain_db`` (weighted mean of the gain
        difference against the linear model over the lines <= ``low_band_hz``), ``sigma_db``,
        ``df_low_band_gain_db`` (the describing-function model's, None if not computed),
        ``visible`` and a sentence."""
        d, s = self.gain_difference_db()
        m = self.freq_hz <= self.low_band_hz
        if not m.any():
            m = self.freq_hz == self.freq_hz.min()
        ok = m & np.isfinite(s) & (s > 0)
        if ok.any():
            w = 1.0 / s[ok] ** 2
            mean, sig = float(np.sum(w * d[ok]) / np.sum(w)), float(1.0 / math.sqrt(np.sum(w)))
        else:
            mean, sig = float(np.mean(d[m])), float("nan")
        df = None
        if self.model_loop_df is not None:
            df = float(np.mean(20 * np.log10(np.abs(self.model_loop_df[m]) / np.abs(self.model.loop[m]))))
        visible = bool(mean <= -0.2 and (not math.isfinite(sig) or mean < -2 * sig))
        if visible:
            text = (f"friction visible: low-frequency loop gain {mean:+.2f} dB (1-sigma {sig:.2f} dB) against the "
                    f"linear model at {self.amplitude_deg:.3f} deg command")
        else:
            text = (f"friction not visible: low-frequency loop gain {mean:+.2f} dB (1-sigma {sig:.2f} dB) against the "
                    "linear model")
        if df is not None:
            text += f"; the describing-function model predicts {df:+.2f} dB"
        return {"low_band_hz": self.low_band_hz, "low_band_gain_db": mean, "sigma_db": sig if math.isfinite(sig) else None,
                "df_low_band_gain_db": df, "visible": visible, "verdict": text}

    @property
    def amplitude_deg(self) -> float:
        return math.degrees(self.amplitude_rad)

    def to_dict(self) -> dict:
        """JSON form: gains [dB], phases [deg] (continuous from the lowest line), sigmas as
        relative errors, NaN as null."""
        from taos.linear import gain_db, phase_deg_continuous

        def num(a):
            return [None if not math.isfinite(v) else float(v) for v in np.asarray(a, float)]

        def gp(h, sig=None, coh=None):
            if h is None:
                return None
            d = {"gain_db": num(gain_db(h)), "phase_deg": num(phase_deg_continuous(self.freq_hz, h))}
            if sig is not None:
                d["sigma_relative"] = num(sig)
            if coh is not None:
                d["coherence"] = num(coh)
            return d
        return {"axis": self.axis, "kind": self.kind, "start_s": self.start_s, "end_s": self.end_s,
                "command_amplitude_deg": self.amplitude_deg, "freq_hz": num(self.freq_hz),
                "loop": gp(self.loop, self.loop_sigma, self.loop_coherence),
                "piston_m_per_rad": gp(self.piston, self.piston_sigma, self.piston_coherence),
                "engine": gp(self.engine, self.engine_sigma),
                "model": {"t_s": self.model.t_s, "avionics_gain": self.model.avionics_gain,
                          "loop": gp(self.model.loop), "piston_m_per_rad": gp(self.model.piston),
                          "engine": gp(self.model.engine), "loop_describing_function": gp(self.model_loop_df),
                          "piston_describing_function_m_per_rad": gp(self.model_piston_df)},
                "friction": self.friction()}


@dataclass(frozen=True, eq=False)
class PtiAnalysis:
    """Every PTI window of a record (:func:`analyse_ptis`): ``responses`` in time order; the
    record's and the ascent's sources; provenance (model, record, settings). Drawn by
    :func:`taos.plotting.pti.plot_pti` (analysis never imports the plotting layer)."""

    responses: tuple[PtiResponse, ...]
    record_source: str
    ascent_source: str
    provenance: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"record": self.record_source, "ascent_file": self.ascent_source,
                "windows": [r.to_dict() for r in self.responses], "provenance": self.provenance}

    summary = to_dict


def pti_lines(pti) -> np.ndarray:
    """The frequencies a PTI is read at [Hz]: a multisine's own lines, a sweep's band on a
    geometric grid of 8 points per octave."""
    if pti.kind == "multisine":
        return np.asarray(pti.signal().freqs_hz, float)
    n = max(2, int(math.ceil(8 * math.log2(pti.high_frequency_hz / pti.low_frequency_hz))) + 1)
    return np.geomspace(pti.low_frequency_hz, pti.high_frequency_hz, n)


def analyse_window(rec: FlightRecord, ascent, model, axis: str, pti, *, tail_s: float = TAIL_S,
                   describing: bool = True, low_band_hz: float = LOW_BAND_HZ) -> PtiResponse:
    """One PTI window (``pti``, a :class:`taos.flight.ascent.Pti`) of ``axis``: the reconstruction
    (:func:`measure_pti`), the model's prediction frozen at the window's middle
    (:func:`taos.flight.pti_model.predict_loop`) and, with ``describing`` and a model with
    friction, its friction-degraded loop (:func:`taos.flight.pti_model.describing_engine` at the
    window's command amplitude)."""
    m = measure_pti(rec, axis, pti, tail_s)
    pred = predict_loop(ascent, model, axis, 0.5 * (pti.start_s + pti.end_s), m.freq_hz, m.amplitude_rad)
    Ldf = Pdf = None
    if describing and model.friction.name != "none":
        N, P, _ = describing_engine(model, axis, m.amplitude_rad, m.freq_hz)
        Ldf, Pdf = pred.degraded(N), P
    return PtiResponse(m, pred, Ldf, Pdf, low_band_hz)


def analyse_ptis(rec: FlightRecord, ascent, model, *, axes=None, tail_s: float = TAIL_S, describing: bool = True,
                 low_band_hz: float = LOW_BAND_HZ) -> PtiAnalysis:
    """Every PTI of ``ascent`` on ``axes`` (default the record's) that the record covers with its
    tail: :func:`analyse_window` each. ``model`` the TVC model (its friction law gives the
    describing-function overlay; fly it with the avionics the record was flown with). Raises
    :class:`InputError` when the record covers no PTI window."""
    axes = rec.axes if axes is None else tuple(axes)
    for ax in axes:
        if ax not in rec.axes:
            raise InputError(rec.source, ax, "an axis of the record: " + ", ".join(rec.axes), got="not recorded")
    out = []
    for p in ascent.ptis:
        for ax in axes:
            if ax in p.axes and rec.t_s[0] <= p.start_s - BASE_S and rec.t_s[-1] >= p.end_s + tail_s:
                out.append(analyse_window(rec, ascent, model, ax, p, tail_s=tail_s, describing=describing,
                                          low_band_hz=low_band_hz))
    if not out:
        raise InputError(rec.source, "t_s", f"a record covering a PTI window of the ascent (with {BASE_S:g} s before "
                         f"and a {tail_s:g} s tail): " + ", ".join(f"{p.start_s:g}-{p.end_s:g} s" for p in ascent.ptis),
                         got=f"{rec.t_s[0]:g}-{rec.t_s[-1]:g} s")
    prov = {**model_provenance(model), "package_version": package_version(), "record": rec.source,
            "record_provenance": rec.provenance, "ascent_file": ascent.source, "ascent_sha256": ascent.sha256,
            "method": "Fourier transform of the whole PTI response at the PTI lines, joint input-output (taos.flight.pti)",
            "tail_s": tail_s, "low_band_hz": low_band_hz, "describing_function": bool(describing)}
    return PtiAnalysis(tuple(sorted(out, key=lambda r: (r.start_s, r.axis))), rec.source, ascent.source, prov)
