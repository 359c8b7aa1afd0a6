"""The one least-squares sine fit: phasors of known frequencies in a sampled signal.

For samples y(t_k) [any unit] at times t_k [s] and frequencies f_i [Hz] (w_i = 2 pi f_i), the
fit solves, in the least-squares sense,

    y(t) ~ sum_i ( a_i sin(w_i t) + b_i cos(w_i t) ) + c0 [+ c1 (t - mean(t))]

and reports each component as the phasor a_i + j b_i, i.e. relative to sin(w_i t): a signal
A sin(w t + phi) gives the phasor A exp(j phi). The optional trend column absorbs a slow drift
(an engine wandering under friction, a settling offset) so it does not leak into the phasors.
This is the estimator of a sine-dwell test (Pintelon and Schoukens, *System Identification: A
Frequency Domain Approach*, 2nd ed., sec. 2.2: the linear least-squares "sine fit" of
IEEE Std 1057 with known frequency), used by the Green Run report's run responses, the
test-record estimator, the ascent analysis and the limit-cycle measurements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SineFit:
    """Result of :func:`fit_sines`.

    Attributes
    ----------
    phasor : ndarray, complex, shape (n_rows, n_freqs)
        a + j b per row of y and frequency [y's unit].
    offset : ndarray, shape (n_rows,)
        c0 [y's unit] (the mean of the fit over the window when a trend is fitted).
    slope : ndarray, shape (n_rows,)
        c1 [y's unit / s]; zeros when no trend was fitted.
    residual_rms : ndarray, shape (n_rows,)
        RMS of the residual with the fit's degrees of freedom [y's unit].
    """

    phasor: np.ndarray
    offset: np.ndarray
    slope: np.ndarray
    residual_rms: np.ndarray

    def amplitude(self) -> np.ndarray:
        """|a + j b| per row and frequency [y's unit]."""
        return np.abs(self.phasor)


def fit_sines(t_s, y, freqs_hz, *, trend: bool = False) -> SineFit:
    """Least-squares phasors of ``freqs_hz`` [Hz] in ``y`` sampled at ``t_s`` [s].

    Parameters
    ----------
    t_s : array_like, shape (n,)
        Sample times [s].
    y : array_like, shape (n,) or (n_rows, n)
        One signal or several sampled at the same times [any unit].
    freqs_hz : float or sequence of float
        Known frequencies [Hz] (harmonics are given as their own frequencies, e.g. (f, 3 f)).
    trend : bool
        Fit a linear drift c1 (t - mean(t)) as well as the offset.

    Returns
    -------
    SineFit
        Phasors of shape (n_rows, n_freqs) (n_rows = 1 for a single signal).
    """
    t = np.asarray(t_s, dtype=float)
    ys = np.atleast_2d(np.asarray(y, dtype=float))
    freqs = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    cols = []
    for f in freqs:
        w = 2 * np.pi * f
        cols += [np.sin(w * t), np.cos(w * t)]
    cols.append(np.ones_like(t))
    if trend:
        cols.append(t - t.mean())
    X = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(X, ys.T, rcond=None)
    res = ys.T - X @ coef
    dof = max(1, t.size - X.shape[1])
    k = 2 * freqs.size
    phasor = (coef[0:k:2] + 1j * coef[1:k:2]).T
    slope = coef[k + 1] if trend else np.zeros(ys.shape[0])
    return SineFit(phasor=phasor, offset=coef[k], slope=slope,
                   residual_rms=np.sqrt(np.sum(res ** 2, axis=0) / dof))


def harmonic_amplitudes(t_s, y, freq_hz: float) -> tuple[float, float]:
    """Amplitudes of the harmonics 1 and 3 of ``freq_hz`` [Hz] in one signal ``y`` sampled at
    ``t_s`` [s] (with an offset), by :func:`fit_sines`: (A1, A3) in y's unit. A limit cycle's
    size and its distortion (a Coulomb cycle is nearly square: A3 / A1 near 1/3)."""
    a = fit_sines(t_s, y, (freq_hz, 3 * freq_hz)).amplitude()[0]
    return float(a[0]), float(a[1])
