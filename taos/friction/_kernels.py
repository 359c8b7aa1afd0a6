"""Scalar friction kernels: the single definition of every friction law.

Each law is two numba-compiled scalar functions over SI floats (the branches and ``math``
calls make them numeric only; fits use describing functions of these laws instead):

* ``zdot(v, z, p)`` -> dz/dt [rad/s];
* ``torque(v, z, dz, t_app, p)`` -> friction torque T_f [N m] opposing relative rate ``v``
  [rad/s], given the internal state ``z`` [rad], its derivative ``dz`` (from ``zdot``, so it
  is computed once) and the applied (non-friction) torque ``t_app`` [N m] (used only by the
  stick-slip law).

``p`` is the packed parameter vector (float64, :data:`NPARAM` slots, see ``SLOT_*``).
Each law's entry in :mod:`taos.friction.registry` wraps these as one C callback
``rates(v, z, t_app, p) -> (dz/dt, T_f)`` (:mod:`taos.friction._builtin`), which the
integrators take as an argument.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._slots import (  # noqa: F401  (the packed parameter slots, re-exported)
    SLOT_TC,
    SLOT_TS,
    SLOT_VS,
    SLOT_DELTA,
    SLOT_SIGMA0,
    SLOT_SIGMA1,
    SLOT_SIGMA2,
    SLOT_VD,
    SLOT_VEPS,
    SLOT_ALPHA,
    SLOT_V1,
    SLOT_CSTICK,
    NPARAM,
)



@njit(cache=True, inline="always")
def _sign(x):
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


# --- Coulomb, stick-slip switching (Karnopp 1985) -------------------------------------
@njit(cache=True, inline="always")
def coulomb_switching_torque(v, t_app, p):
    """Karnopp: inside |v| < v_eps the joint sticks and friction balances the applied torque
    (plus a stick damping c_stick*v that bleeds off the residual rate), up to T_s;
    outside it slides with T_c sign(v)."""
    if abs(v) < p[SLOT_VEPS]:
        t = t_app + p[SLOT_CSTICK] * v
        ts = max(p[SLOT_TS], p[SLOT_TC])
        if t > ts:
            return ts
        if t < -ts:
            return -ts
        return t
    return p[SLOT_TC] * _sign(v)


# --- Coulomb, smooth regularised ------------------------------------------------------
@njit(cache=True, inline="always")
def coulomb_smooth_torque(v, p):
    """T_f = T_c v / sqrt(v^2 + v_eps^2): algebraic regularisation, C-infinity, slope
    T_c / v_eps at v = 0."""
    e = p[SLOT_VEPS]
    return p[SLOT_TC] * v / math.sqrt(v * v + e * e)


# --- Dahl (1968) ----------------------------------------------------------------------
@njit(cache=True, inline="always")
def dahl_zdot(v, z, p):
    """dz/dt = v * |1 - s|^alpha * sign(1 - s),  s = sigma_0 z sign(v) / T_c.

    alpha = 1 (the usual choice) skips the power: |1 - s|^1 is |1 - s| exactly (IEEE pow is
    exact where the result is representable), the same bits at a fraction of the cost."""
    s = p[SLOT_SIGMA0] * z * _sign(v) / p[SLOT_TC]
    d = 1.0 - s
    a = p[SLOT_ALPHA]
    ad = abs(d)
    return v * (ad if a == 1.0 else ad ** a) * _sign(d)


@njit(cache=True, inline="always")
def dahl_torque(z, p):
    """T_f = sigma_0 z."""
    return p[SLOT_SIGMA0] * z


# --- LuGre (Canudas de Wit et al. 1995) and the modified LuGre --------------------------
@njit(cache=True, inline="always")
def _stribeck(v, p):
    """G(v) = T_c + (T_s - T_c) exp(-|v/v_s|^delta)."""
    u = abs(v / p[SLOT_VS])
    d = p[SLOT_DELTA]
    e = u * u if d == 2.0 else u ** d
    return p[SLOT_TC] + (p[SLOT_TS] - p[SLOT_TC]) * math.exp(-e)


@njit(cache=True, inline="always")
def _abs_v_over_h(v, vd):
    """|v| / h(v) with h(v) = (2/pi) asin(min(1, |v|/V_d)); equals |v| when V_d = 0.

    Finite at v = 0: the limit is V_d pi / 2."""
    av = abs(v)
    if vd <= 0.0 or av >= vd:
        return av
    u = av / vd
    if u < 1e-8:
        return vd * 0.5 * math.pi  # u / asin(u) -> 1
    return vd * 0.5 * math.pi * u / math.asin(u)


@njit(cache=True, inline="always")
def lugre_zdot(v, z, p):
    """dz/dt = v - sigma_0 z |v| / g(v),  g(v) = G(v) h(v)  (h = 1 for plain LuGre)."""
    return v - p[SLOT_SIGMA0] * z * _abs_v_over_h(v, p[SLOT_VD]) / _stribeck(v, p)


@njit(cache=True, inline="always")
def _sigma1(v, p):
    """Bristle damping sigma_1(v) = sigma_1 v_1 / (v_1 + |v|) [N m s/rad], constant when
    v_1 = 0: |v| sigma_1(v) rises monotonically to sigma_1 v_1, so the torque at a frozen
    bristle state never falls with the rate (this project's decay law, in place of the
    exponential of Canudas de Wit et al. 1995: :class:`taos.friction.LuGre`)."""
    v1 = p[SLOT_V1]
    if v1 > 0.0:
        return p[SLOT_SIGMA1] * v1 / (v1 + abs(v))
    return p[SLOT_SIGMA1]


@njit(cache=True, inline="always")
def lugre_torque(v, z, dz, p):
    """T_f = sigma_0 z + sigma_1(v) dz/dt + sigma_2 v."""
    return p[SLOT_SIGMA0] * z + _sigma1(v, p) * dz + p[SLOT_SIGMA2] * v


# --- prescribed rate ---------------------------------------------------------------------
@njit(cache=True)
def prescribed_rate_response(rates, p, v, dt, z0):
    """Torque history for a prescribed relative-rate history ``v`` sampled every ``dt``, for
    the law whose scalar kernel is ``rates`` (its registry entry's): (torque[n], z[n]) of
    :func:`prescribed_rate_fill`."""
    n = v.shape[0]
    tq = np.empty(n)
    zs = np.empty(n)
    prescribed_rate_fill(rates, p, v, dt, z0, tq, zs)
    return tq, zs


@njit(cache=True)
def prescribed_rate_fill(rates, p, v, dt, z0, tq, zs):
    """:func:`prescribed_rate_response` into ``tq`` [N m] and ``zs`` [rad] (n,): the state is
    advanced by classical RK4 with ``v`` [rad/s] linearly interpolated at the half-step ``dt``
    [s], from ``z0`` [rad]."""
    n = v.shape[0]
    z = z0
    for k in range(n):
        zs[k] = z
        k1, tq[k] = rates(v[k], z, 0.0, p)
        if k + 1 < n:
            vm = 0.5 * (v[k] + v[k + 1])
            k2 = rates(vm, z + 0.5 * dt * k1, 0.0, p)[0]
            k3 = rates(vm, z + 0.5 * dt * k2, 0.0, p)[0]
            k4 = rates(v[k + 1], z + dt * k3, 0.0, p)[0]
            z = z + dt * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
