"""The bearing over one body step: variable-step BDF2 with its own step-size control.

The bearing slip phi (2) [rad] and the friction law's bristle state z (2) [rad] follow the
pose-demanded bearing angle psi = G e (:func:`taos.taos3d.dynamics.pose_psi`) through the
law's implicit bearing equation (:mod:`taos.friction._vector`)::

    w h + Kc T(w, z) = psi(t + h) - phi_hat,     phi = phi_hat + w h

with phi_hat, z_hat and the effective step h of the BDF2 formula. Over one body step [t_n,
t_n + dt] psi is interpolated linearly between its values at the step ends, and the bearing
is advanced in substeps h_b that its own error estimate chooses:

* variable-step BDF2: with omega = h_b / h_prev (h_prev the previous substep),
  y_hat = ((1 + omega)^2 y_n - omega^2 y_{n-1}) / (1 + 2 omega), h = h_b (1 + omega) / (1 + 2 omega)
  (omega = 1: the constant-step (4 y_n - y_{n-1}) / 3, 2 h_b / 3); omega <= 2 (zero-stable
  below 1 + sqrt 2);
* local error: the corrector minus the quadratic Hermite predictor through phi_{n-1}, phi_n
  and the slip rate w_n, phi_pred = phi_n + w_n h_b + c h_b^2; for constant steps the
  corrector's error is -2/9 h^3 phi''' and the predictor's h^3 phi''' / 3, so the corrector's
  error is about 2 |phi - phi_pred|;
* a substep whose error exceeds the tolerance (:func:`tolerance`: :data:`TOL_RAD` at a body
  step of :data:`TOL_STEP_S`, scaled with the body step cubed) is repeated at a shorter one,
  down to dt / :data:`MAX_SPLIT`; an accepted one lets the next grow at most 2x. The body
  step's own local error in the bearing coupling is third order (trapezoidal torque, linear
  psi), so a tolerance of that order keeps the bearing's share of the global error at the
  scheme's second order without splitting smooth steps: with a fixed 1e-8 rad (until issue
  28) the error estimate split half the body steps of the 60 s Green Run at 4e-4 s into 3-13
  substeps (3.0 a step, plus 1.2 rejected trials: two thirds of the
  run time) for no measurable accuracy (the 60 s engine angle 1.97e-5 deg from the 2.5e-5 s
  run at 4e-4 s, 1.82e-5 with the scaled tolerance, one substep in 99.9 % of the steps);
* where the law's fast mode is unstable (:func:`fast_time`, from the law's continuous-time
  vector kernels ``zdot3`` and ``torque3``) a substep is at most :data:`FAST_STEPS` of its
  time constant: an L-stable implicit step longer than that damps the instability away, and
  then no error estimate of the smooth (wrong) numerical solution can see it.

Where the bearing slides smoothly or sticks the first trial (h_b = dt) passes and the scheme
is the former constant-step BDF2 (to rounding): the smooth laws (Coulomb smooth and
switching, Dahl, whose torque never falls with the slip rate at fixed z) keep their errors.
What the control resolves is the law's own fast
dynamics: with massless gimbal halves the slip rate is algebraic (the chain compliance Kc in
series with the friction element), and a law whose torque falls with the slip rate at
fixed z (a Stribeck law with T_s > T_c; modified LuGre's vibration factor just below V_d when
the bristles oppose the slip) has an unstable fast mode there, rate
(1 + Kc sigma_0) / (Kc |dT/dw|): the massless bearing's relaxation oscillation (stick-slip
chatter, jumps of the slip rate where a branch of the implicit equation folds). A fixed body
step either smooths it away (h > Kc |dT/dw|: the implicit equation single-valued) or places
its jumps at the step's grid; the substeps place them to the tolerance.

The shipped LuGre laws keep the torque rising with the slip rate above V_d (the rational
bristle-damping decay, :class:`taos.friction.LuGre`), so the bearing equation has no impasse
points. Measured (two-axis Green Run, hot fire, modified LuGre; benchmarks/RESULTS.md,
tests/test_taos3d_step.py): over the whole 60 s the engine angle is within 1.8e-5 / 5.0e-6 /
1.1e-6 deg of a 2.5e-5 s run at 4e-4 / 2e-4 / 1e-4 s (second order). With the former
exponential decay the torque peaked at v_1 / sqrt 2 and fell back to sigma_0 z with no rising
branch, the slip jumped in one substep at impasse points, and no step converged (6-8e-3 deg
at every step; docs/theory/taos3d.md, why the bristle damping decays rationally).

The engine sees the bearing torque's mean over the step (trapezoid over the substeps), as the
velocity kick of :func:`taos.taos3d.dynamics.step`.
"""

from __future__ import annotations

import math

from numba import njit

from ._layout import BS_H, BS_PHI, BS_PHI_PREV, BS_SLIP, BS_T, BS_W, BS_Z, BS_Z_PREV

#: local error tolerance on the bearing slip per substep [rad] at a body step of TOL_STEP_S;
#: scaled with the body step cubed (:func:`tolerance`)
TOL_RAD = 1e-6
#: the body step [s] at which the local error tolerance is TOL_RAD
TOL_STEP_S = 5e-4
#: the shortest substep is the body step over this
MAX_SPLIT = 32.0
#: a substep at most this many fast-mode time constants where the fast mode is unstable
FAST_STEPS = 0.5


@njit(cache=True, error_model="numpy", inline="always")
def tolerance(dt):
    """Local error tolerance [rad] of a bearing substep within a body step ``dt`` [s]:
    TOL_RAD (dt / TOL_STEP_S)^3, the order of the body step's own local error in the bearing
    coupling (third order), so that the substeps' error falls with the step at the scheme's
    second order."""
    r = dt / TOL_STEP_S
    return TOL_RAD * r * r * r


@njit(cache=True, error_model="numpy")
def fast_time(zdot3, torque3, fp, Kc, w0, w1, z0, z1, t0, t1):
    """Time constant [s] of the bearing's fast mode where it is unstable, else +inf: with the
    slip rate w = s u and the bristle state z frozen, the law's torque along u,
    T_u(s) = u . torque3(s u, z, zdot3(s u, z)), and its slope g = dT_u/ds (central
    difference, 1e-4 s); the massless bearing's algebraic equation Kc T = psi - phi makes
    the slip rate relax at the rate -1 / (u^T Kc u g): unstable where g < 0, with the time
    constant u^T Kc u |g|. ``zdot3``, ``torque3`` the law's vector kernels, ``t0``, ``t1``
    the torque [N m] (the switching law's applied torque)."""
    s = math.sqrt(w0 * w0 + w1 * w1)
    if s <= 1e-12:
        return math.inf
    u0 = w0 / s
    u1 = w1 / s
    d = 1e-4 * s
    a0 = (s + d) * u0
    a1 = (s + d) * u1
    dz0, dz1 = zdot3(a0, a1, z0, z1, fp)
    ta0, ta1 = torque3(a0, a1, z0, z1, dz0, dz1, t0, t1, fp)
    b0 = (s - d) * u0
    b1 = (s - d) * u1
    dz0, dz1 = zdot3(b0, b1, z0, z1, fp)
    tb0, tb1 = torque3(b0, b1, z0, z1, dz0, dz1, t0, t1, fp)
    g = (u0 * (ta0 - tb0) + u1 * (ta1 - tb1)) / (2.0 * d)
    if g >= 0.0:
        return math.inf
    kuu = u0 * (Kc[0, 0] * u0 + Kc[0, 1] * u1) + u1 * (Kc[1, 0] * u0 + Kc[1, 1] * u1)
    return -kuu * g


@njit(cache=True, error_model="numpy", inline="always")
def _try(bs, fid, fp, Kc, hb, q0, q1):
    """One BDF2 substep of length ``hb`` [s] from the state ``bs`` to the pose-demanded bearing
    angle (q0, q1) [rad]; returns (phi0, phi1, z0, z1, w0, w1, t0, t1, err) without
    committing (err [rad] the local error estimate)."""
    hp = bs[BS_H]
    if hp > 0.0:
        om = hb / hp
    else:  # from rest: history y_{-1} = y_0
        om = 1.0
    den = 1.0 / (1.0 + 2.0 * om)
    a = (1.0 + om) * (1.0 + om) * den
    b = om * om * den
    he = hb * (1.0 + om) * den
    ph0 = a * bs[BS_PHI] - b * bs[BS_PHI_PREV]
    ph1 = a * bs[BS_PHI + 1] - b * bs[BS_PHI_PREV + 1]
    zh0 = a * bs[BS_Z] - b * bs[BS_Z_PREV]
    zh1 = a * bs[BS_Z + 1] - b * bs[BS_Z_PREV + 1]
    w0, w1, z0, z1, t0, t1 = fid(fp, Kc, q0 - ph0, q1 - ph1, zh0, zh1, he, bs[BS_SLIP])
    p0 = ph0 + w0 * he
    p1 = ph1 + w1 * he
    # quadratic Hermite predictor through phi_{n-1}, phi_n, w_n
    wn0, wn1 = bs[BS_W], bs[BS_W + 1]
    if hp > 0.0:
        c0 = (bs[BS_PHI_PREV] - bs[BS_PHI] + wn0 * hp) / (hp * hp)
        c1 = (bs[BS_PHI_PREV + 1] - bs[BS_PHI + 1] + wn1 * hp) / (hp * hp)
    else:
        c0 = 0.0
        c1 = 0.0
    e0 = p0 - (bs[BS_PHI] + hb * (wn0 + hb * c0))
    e1 = p1 - (bs[BS_PHI + 1] + hb * (wn1 + hb * c1))
    return p0, p1, z0, z1, w0, w1, t0, t1, 2.0 * math.sqrt(e0 * e0 + e1 * e1)


@njit(cache=True, error_model="numpy", inline="always")
def _commit(bs, hb, p0, p1, z0, z1, w0, w1, t0, t1):
    bs[BS_PHI_PREV] = bs[BS_PHI]
    bs[BS_PHI_PREV + 1] = bs[BS_PHI + 1]
    bs[BS_Z_PREV] = bs[BS_Z]
    bs[BS_Z_PREV + 1] = bs[BS_Z + 1]
    bs[BS_PHI] = p0
    bs[BS_PHI + 1] = p1
    bs[BS_Z] = z0
    bs[BS_Z + 1] = z1
    bs[BS_W] = w0
    bs[BS_W + 1] = w1
    bs[BS_SLIP] = math.sqrt(w0 * w0 + w1 * w1)  # the slip speed the next solve continues from
    bs[BS_T] = t0
    bs[BS_T + 1] = t1
    bs[BS_H] = hb


@njit(cache=True, error_model="numpy")
def advance(bs, fk, fp, Kc, dt, qa0, qa1, qb0, qb1, tol, max_split, fast_steps):
    """Advance the bearing state ``bs`` (``BS_*``) over a body step ``dt`` [s] in which the
    pose-demanded bearing angle moves linearly from (qa0, qa1) to (qb0, qb1) [rad] (module
    docstring); ``fk`` the law's (bearing_step, zdot3, torque3) and ``fp`` its packed
    parameters, ``Kc`` (2, 2) the chain compliance [rad/(N m)] (a C array), ``tol`` the local error tolerance [rad], ``max_split`` the
    body step over the shortest substep. Returns the bearing torque's mean over the step (2)
    [N m] and the number of substeps taken."""
    fid, zdot3, torque3 = fk
    hmin = dt / max_split
    hp = bs[BS_H]
    hb = dt if hp <= 0.0 else min(dt, 2.0 * hp)
    tb = 0.0
    m0 = 0.0
    m1 = 0.0
    n = 0
    tau = fast_time(zdot3, torque3, fp, Kc, bs[BS_W], bs[BS_W + 1], bs[BS_Z], bs[BS_Z + 1], bs[BS_T], bs[BS_T + 1])
    while True:
        rem = dt - tb
        hb = min(hb, max(fast_steps * tau, hmin))
        last = hb >= rem * (1.0 - 1e-9)
        if last:
            hb = rem
        elif hb > 0.5 * rem:
            hb = 0.5 * rem  # two even substeps rather than a sliver
        f = (tb + hb) / dt
        q0 = qa0 + f * (qb0 - qa0)
        q1 = qa1 + f * (qb1 - qa1)
        p0, p1, z0, z1, w0, w1, t0, t1, err = _try(bs, fid, fp, Kc, hb, q0, q1)
        if err > tol and hb > hmin * (1.0 + 1e-9):
            r = 0.9 * (tol / err) ** (1.0 / 3.0)
            hb = max(hb * max(r, 0.2), hmin)
            continue
        m0 += 0.5 * hb * (bs[BS_T] + t0)
        m1 += 0.5 * hb * (bs[BS_T + 1] + t1)
        _commit(bs, hb, p0, p1, z0, z1, w0, w1, t0, t1)
        n += 1
        if last or hb >= rem * (1.0 - 1e-9):
            break
        # the fast mode's time constant at the committed state (a rejected trial keeps it)
        tau = fast_time(zdot3, torque3, fp, Kc, w0, w1, z0, z1, t0, t1)
        tb += hb
        if err > 0.0:
            hb = hb * min(2.0, 0.9 * (tol / err) ** (1.0 / 3.0))
        else:
            hb = 2.0 * hb
        hb = max(min(hb, 2.0 * bs[BS_H]), hmin)
    return m0 / dt, m1 / dt, n
