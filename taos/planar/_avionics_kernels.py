"""The avionics command-path kernels (quantiser, then crossover-distortion gain), compiled by
numba: the single definition the integrators and :class:`taos.planar.avionics.Avionics` use.

``apply(c, p)``: command ``c`` [rad] -> c_out [rad]; ``p`` the packed parameters of
:meth:`taos.planar.avionics.Avionics.pack`, read by its slots ``AV_*`` (bits, LSB [rad],
rounding 0/1, table length n, table magnitudes [rad] (n), gains [-] (n); the table in
:mod:`taos.planar.avionics`). Equations: :mod:`taos.planar.avionics`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._avionics_slots import AV_LSB, AV_NTAB, AV_ROUND, AV_TABLE


@njit(cache=True)
def apply(c, p):
    """Command path for one value ``c`` [rad] with packed parameters ``p``
    ((AV_TABLE + 2 n,) float64, :meth:`taos.planar.avionics.Avionics.pack`); returns c_out [rad]."""
    lsb = p[AV_LSB]
    if lsb > 0.0:
        q = c / lsb
        if p[AV_ROUND] > 0.5:
            q = math.floor(q + 0.5)
        else:
            q = float(int(q))  # truncation toward zero
        c = q * lsb
    n = int(p[AV_NTAB])
    if n == 0:
        return c
    a = abs(c)
    ia = AV_TABLE      # magnitudes p[AV_TABLE : AV_TABLE+n], gains p[AV_TABLE+n : AV_TABLE+2n]
    ig = AV_TABLE + n
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
    """:func:`apply` on every element of the command array ``c`` (n,) [rad]; returns (n,) [rad]."""
    out = np.empty_like(c)
    for i in range(c.shape[0]):
        out[i] = apply(c[i], p)
    return out
