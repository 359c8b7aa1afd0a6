"""Least-squares harmonic amplitudes of a sampled oscillation (used by the LCO measurement and
its verdict)."""

from __future__ import annotations

import math

import numpy as np


def harmonic_amplitudes(t, y, f):
    """Amplitudes of the harmonics 1 and 3 of frequency ``f`` [Hz] in ``y`` sampled at ``t`` [s],
    by least squares on sin/cos of both harmonics and an offset: (A1, A3) in y's unit."""
    w = 2 * math.pi * f
    M = np.column_stack([np.sin(w * t), np.cos(w * t), np.sin(3 * w * t), np.cos(3 * w * t), np.ones_like(t)])
    c = np.linalg.lstsq(M, y, rcond=None)[0]
    return math.hypot(c[0], c[1]), math.hypot(c[2], c[3])
