"""Stability margins of a SISO loop: every gain and phase crossing (the one margin routine).

For a loop transfer L(j w) in the negative-feedback convention (the closed loop is unstable
when 1 + L = 0, the critical point is -1, i.e. 0 dB and -180 deg on a Nichols chart):

* a **phase crossover** w_pc is a frequency where L crosses the negative real axis
  (Im L = 0, Re L < 0, arg L = -180 deg mod 360); its gain margin is
  GM = -20 log10 |L(j w_pc)| [dB]. Positive: the loop gain may rise by GM before that
  crossing reaches -1; negative (|L| > 1, a conditionally stable loop): the gain may *fall*
  by -GM.
* a **gain crossover** w_gc is a frequency where |L| = 1; its phase margin is
  PM = 180 + arg L(j w_gc) [deg], wrapped to (-180, 180].

A loop can cross several times (a conditionally stable flight loop has a low-frequency
crossing below its gain crossover and more above it, e.g. past a notch filter), and the
smallest margin is not always at the first one, so :class:`LoopMargins` lists **every**
crossing. Two entry points, one result:

* :func:`loop_margins` of a numeric SISO :class:`taos.linear.StateSpace` uses python-control's
  exact polynomial method (``control.stability_margins(..., returnall=True)``);
* :func:`loop_margins` of a sampled response ``(freq_hz, L)`` (a describing-function loop
  L0 N(A, w), or a measured loop) finds each crossing between samples and interpolates
  linearly in log frequency (Re/Im of L for the axis crossings, log |L| for the unit-circle
  crossings); no python-control import, so the command line stays quick. Crossings closer
  together than the grid spacing, or a response through exactly zero, can only be seen as
  finely as the grid resolves them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.linear import StateSpace


@dataclass(frozen=True, eq=False)
class LoopMargins:
    """Every crossing of one SISO loop (see the module docstring for the conventions).

    ``phase_crossover_hz`` [Hz] ascending, with ``gain_margin_db`` [dB] at each;
    ``gain_crossover_hz`` [Hz] ascending, with ``phase_margin_deg`` [deg] at each;
    ``method`` "state-space (python-control)" or "sampled"."""

    phase_crossover_hz: np.ndarray
    gain_margin_db: np.ndarray
    gain_crossover_hz: np.ndarray
    phase_margin_deg: np.ndarray
    method: str = "sampled"

    # -- the margins that bind ----------------------------------------------------------------
    def _pick(self, sel) -> tuple[float | None, float | None]:
        idx = np.flatnonzero(sel)
        if not idx.size:
            return None, None
        k = idx[np.argmin(np.abs(self.gain_margin_db[idx]))]
        return float(self.gain_margin_db[k]), float(self.phase_crossover_hz[k])

    @property
    def upward(self) -> tuple[float | None, float | None]:
        """(margin [dB], frequency [Hz]) by which the gain may *rise*: the smallest GM >= 0."""
        return self._pick(self.gain_margin_db >= 0)

    @property
    def downward(self) -> tuple[float | None, float | None]:
        """(margin [dB] > 0, frequency [Hz]) by which the gain may *fall*: the smallest -GM over
        the crossings where |L| > 1 (a conditionally stable loop)."""
        gm, f = self._pick(self.gain_margin_db < 0)
        return (None if gm is None else -gm), f

    @property
    def min_gain_margin_db(self) -> float:
        """The smallest GM over all phase crossovers (inf if L never crosses the negative real
        axis); negative for a loop with a crossing where |L| > 1."""
        return float(self.gain_margin_db.min()) if self.gain_margin_db.size else math.inf

    @property
    def min_phase_margin(self) -> tuple[float, float | None]:
        """(smallest PM [deg], its gain crossover [Hz]); (inf, None) if |L| never reaches 1."""
        if not self.phase_margin_deg.size:
            return math.inf, None
        k = int(np.argmin(self.phase_margin_deg))
        return float(self.phase_margin_deg[k]), float(self.gain_crossover_hz[k])

    def to_dict(self) -> dict:
        """Every crossing, JSON-ready: ``phase_crossings`` [{freq_hz, gain_margin_db}] and
        ``gain_crossings`` [{freq_hz, phase_margin_deg}]."""
        return {"method": self.method,
                "phase_crossings": [{"freq_hz": float(f), "gain_margin_db": float(g)}
                                    for f, g in zip(self.phase_crossover_hz, self.gain_margin_db)],
                "gain_crossings": [{"freq_hz": float(f), "phase_margin_deg": float(p)}
                                   for f, p in zip(self.gain_crossover_hz, self.phase_margin_deg)]}


def _wrap_pm(arg_deg) -> np.ndarray:
    """180 + arg L wrapped to (-180, 180] [deg]."""
    m = np.remainder(np.asarray(arg_deg, float) + 180.0, 360.0)
    return np.where(m > 180.0, m - 360.0, m)


def _finite(m) -> bool:
    """A numeric matrix with every entry finite (not a CasADi expression)."""
    try:
        return bool(np.all(np.isfinite(np.asarray(m, float))))
    except (TypeError, ValueError, RuntimeError, NotImplementedError):
        return False


def check_sampled_loop(freq_hz, L, field: str = "freq_hz") -> tuple[np.ndarray, np.ndarray]:
    """(f [Hz], L) of a sampled loop, checked as the command line checks its values:
    ``freq_hz`` (named ``field``) at least two increasing finite frequencies in (0, 1e4] Hz;
    ``L`` finite numbers (complex or real, never text, booleans or None) of the same shape;
    :class:`~taos.errors.InputError` naming the argument otherwise."""
    from taos.bounds import RESPONSE_FREQ_HZ, check_grid
    from taos.errors import InputError

    f = check_grid(freq_hz, field, "Hz", 0.0, RESPONSE_FREQ_HZ[1])
    if f.size < 2 or np.any(np.diff(f) <= 0):
        raise InputError("argument", field, "at least two increasing frequencies in Hz", got=repr(freq_hz)[:60])
    try:
        raw = np.asarray(L)
    except (TypeError, ValueError):
        raw = np.asarray(None)
    if raw.dtype.kind not in "iufc" or raw.shape != f.shape or not np.all(np.isfinite(raw)):
        raise InputError("argument", "L", f"{f.size} finite numbers (the loop sampled at {field})",
                         got=f"{raw.dtype} of shape {raw.shape}")
    return f, raw.astype(complex)


def _sampled(freq_hz, L) -> LoopMargins:
    f, L = check_sampled_loop(freq_hz, L, "loop")
    lf = np.log10(f)
    pc, gm, gc, pm = [], [], [], []
    im = L.imag
    lm = np.log10(np.maximum(np.abs(L), 1e-300))
    # the intervals [i, i + 1] holding a crossing, found at once; each then interpolated alone
    # negative real axis: Im L changes sign (or touches zero at the left sample)
    for i in np.flatnonzero((im[:-1] == 0.0) | (im[:-1] * im[1:] < 0)):
        t = im[i] / (im[i] - im[i + 1]) if im[i] != im[i + 1] else 0.0
        Lx = L[i] + t * (L[i + 1] - L[i])
        if Lx.real < 0:
            pc.append(10 ** (lf[i] + t * (lf[i + 1] - lf[i])))
            gm.append(-20.0 * math.log10(-Lx.real))
    # unit circle: log |L| changes sign
    for i in np.flatnonzero(((lm[:-1] >= 0) & (lm[1:] < 0)) | ((lm[:-1] < 0) & (lm[1:] >= 0))):
        t = lm[i] / (lm[i] - lm[i + 1])
        Lx = L[i] + t * (L[i + 1] - L[i])
        gc.append(10 ** (lf[i] + t * (lf[i + 1] - lf[i])))
        pm.append(float(_wrap_pm(math.degrees(np.angle(Lx)))))
    return LoopMargins(np.asarray(pc), np.asarray(gm), np.asarray(gc), np.asarray(pm), "sampled")


def _exact(ss: StateSpace) -> LoopMargins:
    import control  # only here: python-control costs seconds to import

    if len(ss.inputs) != 1 or len(ss.outputs) != 1:
        raise ValueError(f"loop_margins: a SISO loop is needed, got {len(ss.outputs)}x{len(ss.inputs)}")
    sys = control.ss(np.asarray(ss.A, float), np.asarray(ss.B, float), np.asarray(ss.C, float),
                     np.asarray(ss.D, float))
    GM, PM, _SM, wpc, wgc, _wms = control.stability_margins(sys, returnall=True)
    with np.errstate(divide="ignore"):
        gm = 20.0 * np.log10(np.asarray(GM, float))
    pm = _wrap_pm(np.asarray(PM, float) + 180.0)  # python-control's PM is arg L mod 360 - 180
    return LoopMargins(np.asarray(wpc, float) / (2 * math.pi), gm, np.asarray(wgc, float) / (2 * math.pi),
                       pm, "state-space (python-control)")


def loop_margins(loop: StateSpace | np.typing.ArrayLike, L: np.typing.ArrayLike | None = None) -> LoopMargins:
    """Every gain and phase crossing of a SISO loop (negative feedback).

    ``loop_margins(ss)``: ``ss`` a numeric single-input single-output
    :class:`taos.linear.StateSpace` of the loop L(s); crossings exact (python-control).
    ``loop_margins(freq_hz, L)``: L [-] complex, sampled on increasing ``freq_hz`` [Hz];
    crossings interpolated between samples."""
    from taos.errors import InputError

    if isinstance(loop, StateSpace):
        if L is not None:
            raise InputError("argument", "L", "None with a StateSpace loop (its response is exact)", got=repr(L)[:40])
        if len(loop.inputs) != 1 or len(loop.outputs) != 1 or not all(_finite(m) for m in (loop.A, loop.B, loop.C, loop.D)):
            raise InputError("argument", "loop", "a numeric single-input single-output StateSpace with finite matrices",
                             got=f"{len(loop.outputs)}x{len(loop.inputs)} outputs x inputs")
        return _exact(loop)
    if L is None:
        raise InputError("argument", "loop", "a StateSpace, or freq_hz and the sampled loop L",
                         got=f"{type(loop).__name__} {repr(loop)[:30]}")
    return _sampled(loop, L)
