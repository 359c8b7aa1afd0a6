"""Spherical-bearing friction: the vector forms of the planar laws, and the bearing step.

The two gimbal halves turn relative to each other about the bearing's pitch and yaw axes
(roll is held by the gimbal cross), so the relative rate ``w`` [rad/s], the bristle state
``z`` [rad] and the friction torque ``T`` [N m] are 2-vectors in the bearing's tangent plane
(components: pitch, yaw). Every law is the isotropic extension of its planar kernel in
:mod:`._kernels`, reusing that module's packed parameter vector (``SLOT_*``) and its scalar
functions (Stribeck curve ``_stribeck``, vibration factor ``_abs_v_over_h``, decaying
bristle damping ``_sigma1``); with ``w = (v, 0)``, ``z = (z, 0)`` every vector law reduces
to the planar law (``tests/test_taos3d_friction.py``). With s = |w| and u = w / s::

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

Massless gimbal halves make the bearing a series connection of the chain compliance
``Kc`` (2x2, [rad/(N m)]) and the friction element, which is stiff or purely algebraic
(the bristle damping sigma_1(s) vanishes while sliding). The bearing is therefore advanced
by one backward-Euler step, solved exactly (:func:`coeff_bearing_step` for every law whose
torque is T = a(|w|) w + b(|w|) z_n, :func:`switching_bearing_step` for the stick-slip law).
The 3-D model's normal-load scaling of the torque levels is
:meth:`taos.friction.FrictionLaw.scaled`.

Well-posedness of that series connection needs the torque at a frozen bristle state not to
fall with the slip rate, dT_u/ds >= 0 (beyond the law's passivity): for LuGre above V_d,
(1 - sigma_0 z.u / g) d(s sigma_1(s))/ds + sigma_2 >= 0. The rational decay of sigma_1
(:func:`._kernels._sigma1`, sigma_1 v_1 / (v_1 + s)) meets it at every slip rate; the
exponential decay of Canudas de Wit et al. (1995) broke it above v_1 / sqrt 2, where the
torque peaked and fell back to sigma_0 z, and the bearing equation had impasse points (the
slip jumped; docs/theory/taos3d.md, :class:`taos.friction.LuGre`).
:func:`bristle_coeffs` and :func:`bristle_torque3` take the damping's value, so a reference
decay law reuses them (benchmarks/bench_taos3d.py keeps the exponential that way).
"""

from __future__ import annotations

import math

from numba import njit

from ._kernels import (
    SLOT_ALPHA,
    SLOT_CSTICK,
    SLOT_SIGMA0,
    SLOT_SIGMA2,
    SLOT_TC,
    SLOT_TS,
    SLOT_VD,
    SLOT_VEPS,
    _abs_v_over_h,
    _sigma1,
    _stribeck,
)


# -- bristle relaxation rates rho(s) [1/s]: z' = kappa (w - rho z) ---------------------------
@njit(cache=True, inline="always")
def dahl_rho(s, p):
    return p[SLOT_SIGMA0] * s / p[SLOT_TC]


@njit(cache=True, inline="always")
def lugre_rho(s, p):
    return p[SLOT_SIGMA0] * _abs_v_over_h(s, p[SLOT_VD]) / _stribeck(s, p)


@njit(cache=True, inline="always")
def dahl_kappa(w0, w1, z0, z1, p):
    """Dahl shape factor |1 - sigma_0 (z . u) / T_c|^(alpha - 1) (1 for alpha = 1)."""
    a = p[SLOT_ALPHA]
    if a == 1.0:
        return 1.0
    s = math.sqrt(w0 * w0 + w1 * w1)
    if s == 0.0:
        return 1.0
    d = 1.0 - p[SLOT_SIGMA0] * (z0 * w0 + z1 * w1) / (s * p[SLOT_TC])
    return abs(d) ** (a - 1.0)


# -- vector laws ---------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def dahl_zdot3(w0, w1, z0, z1, p):
    s = math.sqrt(w0 * w0 + w1 * w1)
    rho = dahl_rho(s, p)
    k = dahl_kappa(w0, w1, z0, z1, p)
    return k * (w0 - rho * z0), k * (w1 - rho * z1)


@njit(cache=True, inline="always")
def lugre_zdot3(w0, w1, z0, z1, p):
    s = math.sqrt(w0 * w0 + w1 * w1)
    rho = lugre_rho(s, p)
    return 1.0 * (w0 - rho * z0), 1.0 * (w1 - rho * z1)


@njit(cache=True, inline="always")
def switching_torque3(w0, w1, t0, t1, p):
    s = math.sqrt(w0 * w0 + w1 * w1)
    if s < p[SLOT_VEPS]:
        a0 = t0 + p[SLOT_CSTICK] * w0
        a1 = t1 + p[SLOT_CSTICK] * w1
        ts = max(p[SLOT_TS], p[SLOT_TC])
        m = math.sqrt(a0 * a0 + a1 * a1)
        if m > ts:
            return a0 * ts / m, a1 * ts / m
        return a0, a1
    return p[SLOT_TC] * w0 / s, p[SLOT_TC] * w1 / s


@njit(cache=True, inline="always")
def smooth_torque3(w0, w1, p):
    s = math.sqrt(w0 * w0 + w1 * w1)
    e = p[SLOT_VEPS]
    c = p[SLOT_TC] / math.sqrt(s * s + e * e)
    return c * w0, c * w1


@njit(cache=True, inline="always")
def bristle_torque3(w0, w1, z0, z1, dz0, dz1, s1, p):
    """T = sigma_0 z + s1 z' + sigma_2 w with the bristle damping's value ``s1`` [N m s/rad]
    at the slip speed (the LuGre torque for any decay law of sigma_1)."""
    s0 = p[SLOT_SIGMA0]
    s2 = p[SLOT_SIGMA2]
    return s0 * z0 + s1 * dz0 + s2 * w0, s0 * z1 + s1 * dz1 + s2 * w1


@njit(cache=True, inline="always")
def lugre_torque3(w0, w1, z0, z1, dz0, dz1, p):
    s = math.sqrt(w0 * w0 + w1 * w1)
    return bristle_torque3(w0, w1, z0, z1, dz0, dz1, _sigma1(s, p), p)


# -- implicit-step coefficients: T = a w + b z_n, z_new = (z_n + dt kappa w) / (1 + dt kappa rho) ------
@njit(cache=True, inline="always")
def smooth_coeffs(s, p, dt, kappa):
    e = p[SLOT_VEPS]
    return p[SLOT_TC] / math.sqrt(s * s + e * e), 0.0


@njit(cache=True, inline="always")
def dahl_coeffs(s, p, dt, kappa):
    rho = dahl_rho(s, p)
    hk = dt * kappa
    den = 1.0 + hk * rho
    return p[SLOT_SIGMA0] * hk / den, p[SLOT_SIGMA0] / den


@njit(cache=True, inline="always")
def bristle_coeffs(s, p, dt, kappa, s1):
    """(a, b) of the LuGre torque over an implicit step at slip speed ``s`` with the bristle
    damping's value ``s1`` [N m s/rad] there (any decay law of sigma_1)."""
    rho = lugre_rho(s, p)
    hk = dt * kappa
    den = 1.0 + hk * rho
    s0 = p[SLOT_SIGMA0]
    return (s0 * hk + s1) / den + p[SLOT_SIGMA2], (s0 - s1 * rho) / den


@njit(cache=True, inline="always")
def lugre_coeffs(s, p, dt, kappa):
    return bristle_coeffs(s, p, dt, kappa, _sigma1(s, p))


# -- the bearing step ------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def slip_rate(a, b, dt, Kc, d0, d1, z0, z1):
    """w solving (dt I + a Kc) w = d - b Kc z (2x2, explicit inverse)."""
    r0 = d0 - b * (Kc[0, 0] * z0 + Kc[0, 1] * z1)
    r1 = d1 - b * (Kc[1, 0] * z0 + Kc[1, 1] * z1)
    m00 = dt + a * Kc[0, 0]
    m01 = a * Kc[0, 1]
    m10 = a * Kc[1, 0]
    m11 = dt + a * Kc[1, 1]
    det = m00 * m11 - m01 * m10
    return (m11 * r0 - m01 * r1) / det, (m00 * r1 - m10 * r0) / det


@njit(inline="always")
def coeff_residual(coeffs, s, p, dt, kappa, Kc, d0, d1, z0, z1):
    """|w(s)| - s with w(s) = (dt I + a Kc)^-1 (d - b Kc z), (a, b) = coeffs(s, p, dt, kappa);
    returns (residual, w0, w1)."""
    a, b = coeffs(s, p, dt, kappa)
    w0, w1 = slip_rate(a, b, dt, Kc, d0, d1, z0, z1)
    return math.sqrt(w0 * w0 + w1 * w1) - s, w0, w1


@njit(inline="always")
def switching_residual(coeffs, s, p, dt, kappa, Kc, d0, d1, z0, z1):
    """Coulomb switching (sliding): |(s dt I + T_c Kc)^-1 d| - 1 (w = s times that vector)."""
    u0, u1 = slip_rate(p[SLOT_TC], 0.0, s * dt, Kc, d0, d1, z0, z1)
    return math.sqrt(u0 * u0 + u1 * u1) - 1.0, s * u0, s * u1


#: relative size of the last slip-speed correction at which :func:`solve_slip` stops
SLIP_RTOL = 1e-13


@njit(inline="always")
def _secant_step(s_prev, h_prev, s, h, step):
    """Next bracket-search step [rad/s] from (s, h) away from s_prev: the distance to the
    secant's root estimate through (s_prev, h_prev) and (s, h) while the residual's magnitude
    falls, else twice ``step``."""
    if abs(h) < abs(h_prev):
        return abs(h * (s - s_prev) / (h_prev - h))
    return 2.0 * step


@njit(inline="always")
def solve_slip(resid, coeffs, p, dt, kappa, Kc, d0, d1, z0, z1, s0):
    """Slip rate (w0, w1) [rad/s] solving the scalar consistency resid(s) = 0, continued from
    the previous step's slip speed ``s0`` [rad/s]: the residual's sign at s0 says which way the
    slip speed moves (up while |w(s)| > s); the search moves from s0 that way only, first to
    the fixed-point image |w(s0)|, then by secant steps (doubling while the residual does not
    fall; :func:`_secant_step`), until the sign changes (resid(0) >= 0, so downwards it ends
    at s = 0 at the latest), then bracketed Illinois regula falsi on it; it stops when the
    next correction is below :data:`SLIP_RTOL` of the slip speed (returning the rate at the
    last evaluated speed). Where the backward-Euler equation has several roots (Stribeck
    friction falling with the slip speed faster than dt / Kc) this keeps the branch the
    bearing is on while that branch exists (stick-slip hysteresis: the limit of a vanishing
    bearing inertia relaxing the slip speed from s0)."""
    s_a = max(s0, 0.0)
    h_a, w0, w1 = resid(coeffs, s_a, p, dt, kappa, Kc, d0, d1, z0, z1)
    if h_a == 0.0:
        return w0, w1
    if h_a > 0.0:  # the root lies above s0
        s_lo, h_lo = s_a, h_a
        step = h_a + 1e-300  # the first trial is the fixed-point image |w(s0)|
        s_hi, h_hi = s_lo, h_lo
        for _ in range(2000):
            s_hi = s_lo + step
            h_hi, w0, w1 = resid(coeffs, s_hi, p, dt, kappa, Kc, d0, d1, z0, z1)
            if h_hi <= 0.0:
                break
            step = _secant_step(s_lo, h_lo, s_hi, h_hi, step)
            if step <= SLIP_RTOL * s_hi:
                return w0, w1
            s_lo, h_lo = s_hi, h_hi
        if h_hi == 0.0:
            return w0, w1
        s_k = s_hi
    else:  # below s0, at s = 0 at the latest
        s_hi, h_hi = s_a, h_a
        step = -h_a
        s_lo, h_lo = s_hi, h_hi
        for _ in range(2000):
            s_lo = max(s_hi - step, 0.0)
            h_lo, w0, w1 = resid(coeffs, s_lo, p, dt, kappa, Kc, d0, d1, z0, z1)
            if h_lo >= 0.0:
                break
            step = _secant_step(s_hi, h_hi, s_lo, h_lo, step)
            if step <= SLIP_RTOL * s_lo:
                return w0, w1
            s_hi, h_hi = s_lo, h_lo
        if h_lo == 0.0:
            return w0, w1
        s_k = s_lo
    side = 0
    for _ in range(200):
        s = (s_lo * h_hi - s_hi * h_lo) / (h_hi - h_lo)
        if abs(s - s_k) <= SLIP_RTOL * s_k:
            break  # the rate at s_k (the last evaluated speed) is converged
        h, w0, w1 = resid(coeffs, s, p, dt, kappa, Kc, d0, d1, z0, z1)
        s_k = s
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
    return w0, w1


@njit(inline="always")
def coeff_bearing_step(coeffs, rho, stateful, kappa, p, Kc, d0, d1, z0, z1, dt, s0):
    """One backward-Euler step of the bearing: massless halves in series with friction.

    Unknown slip rate w over the step; the slip increment w dt plus the chain's elastic
    rotation Kc T equals the trial increment ``d`` = psi_{n+1} - phi_n (the bearing rotation
    the engine pose demands with no friction, minus the bearing angle at the step start)::

        w dt + Kc T(w) = d,   T(w) = a(|w|) w + b(|w|) z_n,
        z_{n+1} = (z_n + dt kappa w) / (1 + dt kappa rho(|w|))

    (coefficients a >= 0, b from the law's ``coeffs(s, p, dt, kappa)``, bristle rate
    ``rho(s, p)``; ``stateful`` False for memoryless laws, whose state stays 0). For a trial
    speed s, w(s) = (dt I + a Kc)^-1 (d - b Kc z_n), and |w(s)| = s is solved by
    :func:`solve_slip` (s_max exists because a >= 0 and b is bounded). The Dahl exponent
    factor ``kappa`` is frozen at the step start (exact for alpha = 1).

    Parameters: ``p`` packed (scaled) friction vector; ``Kc`` (2, 2) chain pitch/yaw
    compliance [rad/(N m)]; ``d`` [rad]; ``z`` [rad]; ``dt`` [s]; ``s0`` the previous step's
    slip speed [rad/s], where the solve starts (:func:`solve_slip`: with several roots it
    keeps the branch the bearing is on).
    Returns (w0, w1, z0, z1, T0, T1): slip rate [rad/s], new bristle state [rad], friction
    torque carried by the bearing [N m].
    """
    w0, w1 = solve_slip(coeff_residual, coeffs, p, dt, kappa, Kc, d0, d1, z0, z1, s0)
    s = math.sqrt(w0 * w0 + w1 * w1)
    a, b = coeffs(s, p, dt, kappa)
    t0 = a * w0 + b * z0
    t1 = a * w1 + b * z1
    if not stateful:
        return w0, w1, 0.0, 0.0, t0, t1
    den = 1.0 + dt * kappa * rho(s, p)
    return w0, w1, (z0 + dt * kappa * w0) / den, (z1 + dt * kappa * w1) / den, t0, t1


@njit(inline="always")
def _no_coeffs(s, p, dt, kappa):
    return 0.0, 0.0


@njit(cache=True)
def switching_bearing_step(p, Kc, d0, d1, z0, z1, dt, s0):
    """Coulomb switching, the elastic-plastic return map: stick (w = 0, T = Kc^-1 d) while
    |T| <= max(T_s, T_c), else slide with |T| = T_c along the slip (arguments and returns as
    :func:`coeff_bearing_step`)."""
    det = Kc[0, 0] * Kc[1, 1] - Kc[0, 1] * Kc[1, 0]
    t0 = (Kc[1, 1] * d0 - Kc[0, 1] * d1) / det
    t1 = (Kc[0, 0] * d1 - Kc[1, 0] * d0) / det
    if math.sqrt(t0 * t0 + t1 * t1) <= max(p[SLOT_TS], p[SLOT_TC]):
        return 0.0, 0.0, 0.0, 0.0, t0, t1
    w0, w1 = solve_slip(switching_residual, _no_coeffs, p, dt, 1.0, Kc, d0, d1, z0, z1, s0)
    s = math.sqrt(w0 * w0 + w1 * w1)
    return w0, w1, 0.0, 0.0, p[SLOT_TC] * w0 / s, p[SLOT_TC] * w1 / s
