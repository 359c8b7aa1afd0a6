"""The avionics command-path kernels (quantiser, then crossover-distortion gain), compiled by
numba: the single definition the integrators and :class:`taos.planar.avionics.Avionics` use.

``apply(c, p)``: command ``c`` [rad] -> c_out [rad]; ``p`` the packed parameters of
:meth:`taos.planar.avionics.Avionics.pack` (bits, LSB [rad], rounding 0/1, table length n, table
magnitudes [rad] (n), gains [-] (n)). Equations: :mod:`taos.planar.avionics`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def apply(c, p):
    """Command path for one value ``c`` [rad] with packed parameters ``p``."""
    lsb = p[1]
    if lsb > 0.0:
        q = c / lsb
        if p[2] > 0.5:
            q = math.floor(q + 0.5)
        else:
            q = float(int(q))  # truncation toward zero
        c = q * lsb
    n = int(p[3])
    if n == 0:
        return c
    a = abs(c)
    ia = 4          # amplitudes p[4 : 4+n], gains p[4+n : 4+2n]
    ig = 4 + n
    if a <= p[ia]:
        g = p[ig]
    elif a >= p[ia + n - 1]:
        g = p[ig + n - 1]
    else:
        i = 0
        while p[ia + i + 1] < a:
            i += 1
        w = (a - p[ia + i]) / (p[ia + i + 1] - p[ia + i])
        g = p[ig + i] + w * (p[ig + i + 1] - p[ig + i])
    return g * c


@njit(cache=True)
def apply_array(c, p):
    out = np.empty_like(c)
    for i in range(c.shape[0]):
        out[i] = apply(c[i], p)
    return out
