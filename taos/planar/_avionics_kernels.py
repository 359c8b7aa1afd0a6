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


@njit(cache=True, inline="always")
def apply_lanes(C, P, S, out):
    """:func:`apply` per lane, as element-wise loops over the lanes with the branches as selects
    (vectorised by LLVM; compiled without fast-math each lane gets :func:`apply`'s bits): ``C``
    (R,) commands [rad], ``P`` (AV_TABLE + 2 n, R) the lanes' packs by slot (``P[:, q]`` lane
    q's :meth:`taos.planar.avionics.Avionics.pack`, one table length n for all) -> ``out`` (R,)
    [rad]; ``S`` (2, R) scratch. The table search is :func:`apply`'s scan (the first segment
    whose upper magnitude reaches |c|), run over every segment with a found flag per lane."""
    nl = C.shape[0]
    n = (P.shape[0] - AV_TABLE) // 2
    for q in range(nl):
        c = C[q]
        lsb = P[AV_LSB, q]
        x = c / lsb
        # rounding, or truncation toward zero (+ 0.0: float(int(x)) gives +0.0 for -1 < x < 0)
        xq = math.floor(x + 0.5) if P[AV_ROUND, q] > 0.5 else np.trunc(x) + 0.0
        out[q] = (xq * lsb) if lsb > 0.0 else c
    if n == 0:
        return
    ia = AV_TABLE
    ig = AV_TABLE + n
    G = S[0]
    F = S[1]  # 1: the gain is found (outside the table, or its segment reached)
    for q in range(nl):
        a = abs(out[q])
        G[q] = P[ig, q] if a <= P[ia, q] else P[ig + n - 1, q]
        F[q] = 0.0 if (a > P[ia, q] and a < P[ia + n - 1, q]) else 1.0
    for i in range(n - 1):
        for q in range(nl):
            a = abs(out[q])
            lo = P[ia + i, q]
            hi = P[ia + i + 1, q]
            take = F[q] == 0.0 and hi >= a
            w = (a - lo) / (hi - lo)
            gi = P[ig + i, q] + w * (P[ig + i + 1, q] - P[ig + i, q])
            G[q] = gi if take else G[q]
            F[q] = 1.0 if take else F[q]
    for q in range(nl):
        out[q] = G[q] * out[q]
