"""Spherical-bearing friction: vector forms of every planar friction law.

The two gimbal halves turn relative to each other about the bearing's pitch and yaw axes
(roll is held by the gimbal cross), so the relative rate ``w`` [rad/s], the bristle state
``z`` [rad] and the friction torque ``T`` [N m] are 2-vectors in the bearing's tangent plane
(components: pitch, yaw). Every law is the isotropic extension of its planar kernel in
:mod:`taos.friction._kernels`, reusing that module's packed parameter vector (``SLOT_*``)
and its scalar functions (Stribeck curve ``_stribeck``, vibration factor ``_abs_v_over_h``,
decaying bristle damping ``_sigma1``); with ``w = (v, 0)``, ``z = (z, 0)`` every vector law
reduces to the planar law (``tests/test_taos3d_friction.py``). With s = |w| and
u = w / s::

    none               T = 0
    coulomb-smooth     T = T_c w / sqrt(s^2 + v_eps^2)
    coulomb-switching  s <  v_stick: T = sat_|.|(T_app + c_stick w, max(T_s, T_c)) (stuck)
                       s >= v_stick: T = T_c u                                  (sliding)
    dahl               z' = kappa (w - rho z),  rho = sigma_0 s / T_c,
                       kappa = |1 - sigma_0 (z . u) / T_c|^(alpha - 1),  T = sigma_0 z
    lugre, modified    z' = w - rho z,  rho = sigma_0 |s| / (G(s) h(s)),
                       T = sigma_0 z + sigma_1(s) z' + sigma_2 w

(``sat_|.|`` saturates the vector's length.) The torque opposes the relative rotation: its
sliding direction is u, and the bristle state relaxes along z towards g(s) u / sigma_0.

Magnitude: the planar parameter vector holds the file's torque levels; the bearing scales
every torque-like slot (T_c, T_s, sigma_0, sigma_1, sigma_2, c_stick) by
lambda = mu N r_b / T_c,file (:func:`scale_params`), i.e. friction proportional to the
bearing normal load N with the pre-sliding angle T_c / sigma_0 unchanged. Every law is
homogeneous of degree one in those slots, so this scales the torque and nothing else.

Massless gimbal halves make the bearing a series connection of the chain compliance
``Kc`` (2x2, [rad/(N m)]) and the friction element, which is stiff or purely algebraic
(the bristle damping sigma_1(s) vanishes while sliding). :func:`bearing_step` therefore
advances the bearing by one backward-Euler step, solved exactly: see its docstring.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..friction._kernels import (
    ID_COULOMB_SMOOTH,
    ID_COULOMB_SWITCHING,
    ID_DAHL,
    ID_LUGRE,
    ID_MODIFIED_LUGRE,
    ID_NONE,
    SLOT_ALPHA,
    SLOT_CSTICK,
    SLOT_SIGMA0,
    SLOT_SIGMA1,
    SLOT_SIGMA2,
    SLOT_TC,
    SLOT_TS,
    SLOT_VD,
    SLOT_VEPS,
    _abs_v_over_h,
    _sigma1,
    _stribeck,
)

#: packed slots holding a torque or a torque per unit angle / rate (scaled by normal load)
TORQUE_SLOTS = (SLOT_TC, SLOT_TS, SLOT_SIGMA0, SLOT_SIGMA1, SLOT_SIGMA2, SLOT_CSTICK)


def scale_params(p: np.ndarray, factor: float) -> np.ndarray:
    """Copy of the packed planar vector ``p`` with every torque-like slot times ``factor``."""
    q = np.array(p, dtype=np.float64, copy=True)
    for s in TORQUE_SLOTS:
        q[s] *= factor
    return q


@njit(cache=True, inline="always")
def bristle_rate(fid, s, p):
    """rho(s) [1/s]: the bristle relaxation rate, z' = w - rho z (LuGre family, Dahl)."""
    if fid == ID_DAHL:
        return p[SLOT_SIGMA0] * s / p[SLOT_TC]
    if fid == ID_LUGRE or fid == ID_MODIFIED_LUGRE:
        return p[SLOT_SIGMA0] * _abs_v_over_h(s, p[SLOT_VD]) / _stribeck(s, p)
    return 0.0


@njit(cache=True, inline="always")
def _dahl_kappa(w0, w1, z0, z1, p):
    """Dahl shape factor |1 - sigma_0 (z . u) / T_c|^(alpha - 1) (1 for alpha = 1)."""
    a = p[SLOT_ALPHA]
    if a == 1.0:
        return 1.0
    s = math.sqrt(w0 * w0 + w1 * w1)
    if s == 0.0:
        return 1.0
    d = 1.0 - p[SLOT_SIGMA0] * (z0 * w0 + z1 * w1) / (s * p[SLOT_TC])
    return abs(d) ** (a - 1.0)


@njit(cache=True)
def zdot3(fid, w0, w1, z0, z1, p):
    """Bristle-state derivative (dz0, dz1) [rad/s] of law ``fid`` (zero for memoryless laws)."""
    if fid == ID_DAHL or fid == ID_LUGRE or fid == ID_MODIFIED_LUGRE:
        s = math.sqrt(w0 * w0 + w1 * w1)
        rho = bristle_rate(fid, s, p)
        k = _dahl_kappa(w0, w1, z0, z1, p) if fid == ID_DAHL else 1.0
        return k * (w0 - rho * z0), k * (w1 - rho * z1)
    return 0.0, 0.0


@njit(cache=True)
def torque3(fid, w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    """Friction torque (T0, T1) [N m] of law ``fid`` at relative rate ``w``, bristle state
    ``z`` and its derivative ``dz`` (from :func:`zdot3`), applied torque ``t`` (switching law)."""
    if fid == ID_NONE:
        return 0.0, 0.0
    s = math.sqrt(w0 * w0 + w1 * w1)
    if fid == ID_COULOMB_SWITCHING:
        if s < p[SLOT_VEPS]:
            a0 = t0 + p[SLOT_CSTICK] * w0
            a1 = t1 + p[SLOT_CSTICK] * w1
            ts = max(p[SLOT_TS], p[SLOT_TC])
            m = math.sqrt(a0 * a0 + a1 * a1)
            if m > ts:
                return a0 * ts / m, a1 * ts / m
            return a0, a1
        return p[SLOT_TC] * w0 / s, p[SLOT_TC] * w1 / s
    if fid == ID_COULOMB_SMOOTH:
        e = p[SLOT_VEPS]
        c = p[SLOT_TC] / math.sqrt(s * s + e * e)
        return c * w0, c * w1
    if fid == ID_DAHL:
        return p[SLOT_SIGMA0] * z0, p[SLOT_SIGMA0] * z1
    s1 = _sigma1(s, p)
    s0 = p[SLOT_SIGMA0]
    s2 = p[SLOT_SIGMA2]
    return s0 * z0 + s1 * dz0 + s2 * w0, s0 * z1 + s1 * dz1 + s2 * w1


# -- implicit bearing step ---------------------------------------------------------------
@njit(cache=True, inline="always")
def _coeffs(fid, s, p, dt, kappa):
    """(a, b) with T = a w + b z_n and z_new = (z_n + dt kappa w) / (1 + dt kappa rho)
    for a trial slip speed s = |w| (backward Euler of z' = kappa (w - rho z))."""
    if fid == ID_NONE:
        return 0.0, 0.0
    if fid == ID_COULOMB_SMOOTH:
        e = p[SLOT_VEPS]
        return p[SLOT_TC] / math.sqrt(s * s + e * e), 0.0
    if fid == ID_COULOMB_SWITCHING:
        return p[SLOT_TC] / max(s, 1e-300), 0.0
    rho = bristle_rate(fid, s, p)
    hk = dt * kappa
    den = 1.0 + hk * rho
    if fid == ID_DAHL:
        return p[SLOT_SIGMA0] * hk / den, p[SLOT_SIGMA0] / den
    s1 = _sigma1(s, p)
    s0 = p[SLOT_SIGMA0]
    return (s0 * hk + s1) / den + p[SLOT_SIGMA2], (s0 - s1 * rho) / den


@njit(cache=True, inline="always")
def _slip(a, b, dt, Kc, d0, d1, z0, z1):
    """w solving (dt I + a Kc) w = d - b Kc z (2x2, explicit inverse)."""
    r0 = d0 - b * (Kc[0, 0] * z0 + Kc[0, 1] * z1)
    r1 = d1 - b * (Kc[1, 0] * z0 + Kc[1, 1] * z1)
    m00 = dt + a * Kc[0, 0]
    m01 = a * Kc[0, 1]
    m10 = a * Kc[1, 0]
    m11 = dt + a * Kc[1, 1]
    det = m00 * m11 - m01 * m10
    return (m11 * r0 - m01 * r1) / det, (m00 * r1 - m10 * r0) / det


@njit(cache=True, inline="always")
def _h(fid, s, p, dt, kappa, Kc, d0, d1, z0, z1):
    """Consistency residual at trial slip speed s and the slip rate w(s) it implies.

    Coulomb switching (sliding): |(s dt I + T_c Kc)^-1 d| - 1 (w = s times that vector);
    other laws: |w(s)| - s with w(s) = (dt I + a Kc)^-1 (d - b Kc z)."""
    if fid == ID_COULOMB_SWITCHING:
        u0, u1 = _slip(p[SLOT_TC], 0.0, s * dt, Kc, d0, d1, z0, z1)
        return math.sqrt(u0 * u0 + u1 * u1) - 1.0, s * u0, s * u1
    a, b = _coeffs(fid, s, p, dt, kappa)
    w0, w1 = _slip(a, b, dt, Kc, d0, d1, z0, z1)
    return math.sqrt(w0 * w0 + w1 * w1) - s, w0, w1


@njit(cache=True)
def bearing_step(fid, p, Kc, d0, d1, z0, z1, dt):
    """One backward-Euler step of the bearing: massless halves in series with friction.

    Unknown slip rate w over the step; the slip increment w dt plus the chain's elastic
    rotation Kc T equals the trial increment ``d`` = psi_{n+1} - phi_n (the bearing rotation
    the engine pose demands with no friction, minus the bearing angle at the step start)::

        w dt + Kc T(w) = d,   T(w) = a(|w|) w + b(|w|) z_n,
        z_{n+1} = (z_n + dt kappa w) / (1 + dt kappa rho(|w|))

    (coefficients a >= 0, b from the law, :func:`_coeffs`). For a trial speed s,
    w(s) = (dt I + a Kc)^-1 (d - b Kc z_n), and the scalar consistency |w(s)| = s is solved
    by bracketed Illinois regula falsi on [0, s_max] (h(0) >= 0 > h(s_max); s_max exists
    because a >= 0 and b is bounded). Coulomb switching is the elastic-plastic return map:
    stick (w = 0, T = Kc^-1 d) while |T| <= max(T_s, T_c), else slide with |T| = T_c along
    the slip. The Dahl exponent factor kappa is frozen at the step start (exact for
    alpha = 1).

    Parameters: ``p`` packed (scaled) friction vector; ``Kc`` (2, 2) chain pitch/yaw
    compliance [rad/(N m)]; ``d`` [rad]; ``z`` [rad]; ``dt`` [s].
    Returns (w0, w1, z0, z1, T0, T1): slip rate [rad/s], new bristle state [rad], friction
    torque carried by the bearing [N m].
    """
    if fid == ID_NONE:
        return d0 / dt, d1 / dt, 0.0, 0.0, 0.0, 0.0
    if fid == ID_COULOMB_SWITCHING:
        det = Kc[0, 0] * Kc[1, 1] - Kc[0, 1] * Kc[1, 0]
        t0 = (Kc[1, 1] * d0 - Kc[0, 1] * d1) / det
        t1 = (Kc[0, 0] * d1 - Kc[1, 0] * d0) / det
        if math.sqrt(t0 * t0 + t1 * t1) <= max(p[SLOT_TS], p[SLOT_TC]):
            return 0.0, 0.0, 0.0, 0.0, t0, t1
    kappa = 1.0
    if fid == ID_DAHL:
        kappa = _dahl_kappa(d0, d1, z0, z1, p)
    s_lo = 0.0
    h_lo, w0, w1 = _h(fid, 0.0, p, dt, kappa, Kc, d0, d1, z0, z1)
    if h_lo > 0.0:
        s_hi = 2.0 * math.sqrt(d0 * d0 + d1 * d1) / dt + h_lo + 1e-300
        h_hi = 0.0
        for _ in range(400):
            h_hi, w0, w1 = _h(fid, s_hi, p, dt, kappa, Kc, d0, d1, z0, z1)
            if h_hi < 0.0:
                break
            s_hi *= 2.0
        side = 0
        for _ in range(200):
            s = (s_lo * h_hi - s_hi * h_lo) / (h_hi - h_lo)
            h, w0, w1 = _h(fid, s, p, dt, kappa, Kc, d0, d1, z0, z1)
            if h > 0.0:
                s_lo, h_lo = s, h
                if side == 1:
                    h_hi *= 0.5
                side = 1
            else:
                s_hi, h_hi = s, h
                if side == -1:
                    h_lo *= 0.5
                side = -1
            if s_hi - s_lo <= 1e-14 * s_hi or h == 0.0:
                break
    s = math.sqrt(w0 * w0 + w1 * w1)
    if fid == ID_COULOMB_SWITCHING:
        return w0, w1, 0.0, 0.0, p[SLOT_TC] * w0 / s, p[SLOT_TC] * w1 / s
    a, b = _coeffs(fid, s, p, dt, kappa)
    t0 = a * w0 + b * z0
    t1 = a * w1 + b * z1
    if fid == ID_COULOMB_SMOOTH:
        return w0, w1, 0.0, 0.0, t0, t1
    den = 1.0 + dt * kappa * bristle_rate(fid, s, p)
    return w0, w1, (z0 + dt * kappa * w0) / den, (z1 + dt * kappa * w1) / den, t0, t1
