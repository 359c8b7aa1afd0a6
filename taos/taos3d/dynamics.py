"""TAOS equations of motion and their compiled fixed-step integrator.

Formulation (quasi-static condensation of the massless gimbal halves)::

    engine       rigid body, free-flyer at O: q = (p [m], quaternion xyzw), body twist
                 v = (v_lin [m/s], omega [rad/s]); Y a + v x* (Y v) = f_body
                 (Y: 6x6 spatial inertia from Pinocchio; x*: spatial force cross product)
    pose         e = (p, r), r = log3(R) the engine rotation vector [rad]
    chain        halves in series K_s = (K_u^-1 + K_l^-1)^-1 at O; bearing slip phi (2) about
                 the pitch/yaw axes S (6x2): chain deflection d = e - S phi, wrench W = K_s d.
                 With the bearing torque T (2) the slip is algebraic:
                 S^T W = T  <=>  phi = G e - Kc T,  G = Kc S^T K_s,  Kc = (S^T K_s S)^-1
    engine loads force -W[:3] at p; generalized torque on r: g = -W[3:] - K_n P r (K_n the
                 planar feedline/gravity spring on pitch/yaw, P the pitch/yaw projector),
                 applied as the world torque Jl(r)^-T g (Jl the SO(3) left Jacobian, so the
                 springs are exactly conservative); each actuator i pulls along its line u_i
                 = (E_i - S_i)/L_i with F_L,i = K_L (x_p,i - (L_i - L0_i)) + c_L (v_p,i - L_i') at E_i
                 (c_L the load path's structural damping, taos.model.Structure)
    actuators    the one linear actuator model (taos.actuator), x_c,i = R avionics(theta_c,i),
                 load input F_L,i
    bearing      (phi, z, T) advanced once per step by the friction law's backward-Euler
                 bearing solve (its registry entry's ``bearing_step``, passed to the kernels
                 as the first-class function ``fid``; :mod:`taos.friction._vector`), given
                 the pose at the step end

Time stepping: classical RK4 for (q, v, actuators) with T held over the step, then the
implicit bearing update (a first-order split in T only; T is bounded by the friction level,
so holding it for a step costs O(dt T_dot), never the stiff chain spring). The stiff
chain-rotation / bristle-damping time constant (Kc (sigma_1 + sigma_2), ~1e-4 s or less)
never enters the explicit part, so the step is set by the oil column and the engine's
translational modes on the chain (omega dt < 2.8 for RK4). Quaternions are renormalised
after each step. With friction off (T = 0) the scheme is plain RK4.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .. import _avionics_kernels as _av
from .. import actuator_limits as _lim

_FM = {"reassoc", "contract", "arcp", "nsz"}
N_BODY = 13  # p (3), quaternion (4), v (6)
#: recorded columns of :func:`integrate`
REC = ("theta_pitch", "theta_yaw", "xp_pitch", "xp_yaw", "fl_pitch", "fl_yaw", "tf_pitch", "tf_yaw",
       "z_pitch", "z_yaw", "phi_pitch", "phi_yaw", "u_pitch", "u_yaw",
       "w_fx", "w_fy", "w_fz", "w_mx", "w_my", "w_mz", "px", "py", "pz")


@njit(cache=True, fastmath=_FM, inline="always")
def _rot(q, Rm):
    x, y, z, w = q[0], q[1], q[2], q[3]
    Rm[0, 0] = 1 - 2 * (y * y + z * z)
    Rm[0, 1] = 2 * (x * y - z * w)
    Rm[0, 2] = 2 * (x * z + y * w)
    Rm[1, 0] = 2 * (x * y + z * w)
    Rm[1, 1] = 1 - 2 * (x * x + z * z)
    Rm[1, 2] = 2 * (y * z - x * w)
    Rm[2, 0] = 2 * (x * z - y * w)
    Rm[2, 1] = 2 * (y * z + x * w)
    Rm[2, 2] = 1 - 2 * (x * x + y * y)


@njit(cache=True, fastmath=_FM, inline="always")
def _logq(q, r):
    """Rotation vector of the unit quaternion q (xyzw) into r; returns the angle."""
    s = 1.0 if q[3] >= 0 else -1.0
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
    if n < 1e-12:
        f = 2.0 * s / max(abs(q[3]), 1e-300)
    else:
        f = 2.0 * math.atan2(n, abs(q[3])) / n * s
    for i in range(3):
        r[i] = f * q[i]
    return 2.0 * math.atan2(n, abs(q[3]))


@njit(cache=True, fastmath=_FM, inline="always")
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, fastmath=_FM)
def rhs(x, T0, T1, u0, u1, P, dx, aux):
    """State derivative dx of the TAOS engine + actuators with bearing torque (T0, T1) [N m]
    and post-avionics commands (u0, u1) [rad]. ``aux`` receives: 0-5 chain wrench W at O in
    the gimbal frame [N, N m], 6-7 F_L [N], 8-9 phi [rad], 10-11 engine angles [rad]."""
    (Y, Yinv, Ks, G, Kc, S, Satt, Eatt, Aa, bxc, bf, cxp, axes, sc) = P
    KL, Rarm, Kn, L00, L01 = sc[0], sc[1], sc[2], sc[3], sc[4]
    cL, ivp = sc[5], int(sc[6])  # load-path damping [N s/m] and the actuator's v_p state index
    lim = sc[7:]  # actuator/gimbal limits packed over one actuator's state (taos.actuator_limits)
    na = Aa.shape[0]
    Rm = np.empty((3, 3))
    _rot(x[3:7], Rm)
    e = np.empty(6)
    for i in range(3):
        e[i] = x[i]
    r = np.empty(3)
    th = _logq(x[3:7], r)
    for i in range(3):
        e[3 + i] = r[i]
    # bearing slip and chain wrench
    phi0 = -(Kc[0, 0] * T0 + Kc[0, 1] * T1)
    phi1 = -(Kc[1, 0] * T0 + Kc[1, 1] * T1)
    for j in range(6):
        phi0 += G[0, j] * e[j]
        phi1 += G[1, j] * e[j]
    d = np.empty(6)
    for j in range(6):
        d[j] = e[j] - S[j, 0] * phi0 - S[j, 1] * phi1
    W = np.empty(6)
    for i in range(6):
        s = 0.0
        for j in range(6):
            s += Ks[i, j] * d[j]
        W[i] = s
    # generalized torque conjugate to r, then world torque Jl^-T g
    tp = axes[0, 0] * r[0] + axes[0, 1] * r[1] + axes[0, 2] * r[2]
    ty = axes[1, 0] * r[0] + axes[1, 1] * r[1] + axes[1, 2] * r[2]
    g = np.empty(3)
    for i in range(3):
        g[i] = -W[3 + i] - Kn * (axes[0, i] * tp + axes[1, i] * ty)
    if lim.shape[0] > 0 and lim[4] > 0.0:  # hard stops at the gimbal range (taos.actuator_limits)
        wp = 0.0
        wy = 0.0
        for i in range(3):
            wi = Rm[i, 0] * x[10] + Rm[i, 1] * x[11] + Rm[i, 2] * x[12]
            wp += axes[0, i] * wi
            wy += axes[1, i] * wi
        tsp = _lim.stop_torque(tp, wp, lim[4], lim[5], lim[6])
        tsy = _lim.stop_torque(ty, wy, lim[4], lim[5], lim[6])
        for i in range(3):
            g[i] += axes[0, i] * tsp + axes[1, i] * tsy
    if th < 1e-4:
        c = 1.0 / 12.0 + th * th / 720.0
    else:
        c = 1.0 / (th * th) - (1.0 + math.cos(th)) / (2.0 * th * math.sin(th))
    rg = np.empty(3)
    _cross(r, g, rg)
    rrg = np.empty(3)
    _cross(r, rg, rrg)
    Fw = np.empty(3)
    Tw = np.empty(3)
    for i in range(3):
        Tw[i] = g[i] + 0.5 * rg[i] + c * rrg[i]
        Fw[i] = -W[i]
    # actuators
    Ew = np.empty(3)
    lever = np.empty(3)
    mom = np.empty(3)
    fl = np.empty(3)
    for a in range(2):
        for i in range(3):
            lever[i] = Rm[i, 0] * Eatt[a, 0] + Rm[i, 1] * Eatt[a, 1] + Rm[i, 2] * Eatt[a, 2]
            Ew[i] = x[i] + lever[i] - Satt[a, i]
        L = math.sqrt(Ew[0] * Ew[0] + Ew[1] * Ew[1] + Ew[2] * Ew[2])
        off = N_BODY + a * na
        xp = 0.0
        for k in range(na):
            xp += cxp[k] * x[off + k]
        F = KL * (xp - (L - (L00 if a == 0 else L01)))
        if cL > 0.0:  # structural damping across the line: c_L (v_p - L')
            wb = np.empty(3)
            _cross(x[10:13], Eatt[a], wb)
            Ld = 0.0
            for i in range(3):
                Ld += Ew[i] * (Rm[i, 0] * (x[7] + wb[0]) + Rm[i, 1] * (x[8] + wb[1]) + Rm[i, 2] * (x[9] + wb[2]))
            F += cL * (x[off + ivp] - Ld / L)
        for i in range(3):
            fl[i] = F * Ew[i] / L
            Fw[i] += fl[i]
        _cross(lever, fl, mom)
        for i in range(3):
            Tw[i] += mom[i]
        u = u0 if a == 0 else u1
        for k in range(na):
            s = bxc[k] * Rarm * u + bf[k] * F
            for j in range(na):
                s += Aa[k, j] * x[off + j]
            dx[off + k] = s
        _lim.apply_valve_pressure(lim, x, off, u, dx)  # rate and pressure limits (no-op if none)
        aux[6 + a] = F
    # rigid body (body frame, linear first): a = Yinv (f - v x* (Y v))
    f = np.empty(6)
    for i in range(3):
        f[i] = Rm[0, i] * Fw[0] + Rm[1, i] * Fw[1] + Rm[2, i] * Fw[2]
        f[3 + i] = Rm[0, i] * Tw[0] + Rm[1, i] * Tw[1] + Rm[2, i] * Tw[2]
    v = x[7:13]
    Yv = np.empty(6)
    for i in range(6):
        s = 0.0
        for j in range(6):
            s += Y[i, j] * v[j]
        Yv[i] = s
    w = v[3:6]
    c1 = np.empty(3)
    _cross(w, Yv[0:3], c1)
    c2 = np.empty(3)
    _cross(w, Yv[3:6], c2)
    c3 = np.empty(3)
    _cross(v[0:3], Yv[0:3], c3)
    for i in range(3):
        f[i] -= c1[i]
        f[3 + i] -= c2[i] + c3[i]
    for i in range(6):
        s = 0.0
        for j in range(6):
            s += Yinv[i, j] * f[j]
        dx[7 + i] = s
    for i in range(3):
        dx[i] = Rm[i, 0] * v[0] + Rm[i, 1] * v[1] + Rm[i, 2] * v[2]
    qx, qy, qz, qw = x[3], x[4], x[5], x[6]
    dx[3] = 0.5 * (qw * w[0] + qy * w[2] - qz * w[1])
    dx[4] = 0.5 * (qw * w[1] + qz * w[0] - qx * w[2])
    dx[5] = 0.5 * (qw * w[2] + qx * w[1] - qy * w[0])
    dx[6] = -0.5 * (qx * w[0] + qy * w[1] + qz * w[2])
    for i in range(6):
        aux[i] = W[i]
    aux[8] = phi0
    aux[9] = phi1
    aux[10] = tp
    aux[11] = ty


@njit(cache=True, fastmath=_FM)
def pose_psi(x, P):
    """psi = G e: the bearing angles that carry no torque at the current pose [rad]."""
    G = P[3]
    r = np.empty(3)
    _logq(x[3:7], r)
    p0 = 0.0
    p1 = 0.0
    for j in range(3):
        p0 += G[0, j] * x[j] + G[0, 3 + j] * r[j]
        p1 += G[1, j] * x[j] + G[1, 3 + j] * r[j]
    return p0, p1


@njit(cache=True, fastmath=_FM)
def step(x, bs, c0, cm, c1, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux):
    """One step: RK4 on (q, v, actuators) with T = bs[4:6] held, then the bearing update.
    ``bs`` = (phi0, phi1, z0, z1, T0, T1) is updated in place; c0/cm/c1 are the
    pre-avionics commands (2,) at the step start, middle and end."""
    n = x.shape[0]
    T0, T1 = bs[4], bs[5]
    rhs(x, T0, T1, _av.apply(c0[0], avp), _av.apply(c0[1], avp), P, k1, aux)
    um0, um1 = _av.apply(cm[0], avp), _av.apply(cm[1], avp)
    for i in range(n):
        xt[i] = x[i] + 0.5 * dt * k1[i]
    rhs(xt, T0, T1, um0, um1, P, k2, aux)
    for i in range(n):
        xt[i] = x[i] + 0.5 * dt * k2[i]
    rhs(xt, T0, T1, um0, um1, P, k3, aux)
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    rhs(xt, T0, T1, _av.apply(c1[0], avp), _av.apply(c1[1], avp), P, k4, aux)
    for i in range(n):
        x[i] += dt * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0
    qn = math.sqrt(x[3] * x[3] + x[4] * x[4] + x[5] * x[5] + x[6] * x[6])
    for i in range(3, 7):
        x[i] /= qn
    ps0, ps1 = pose_psi(x, P)
    w0, w1, z0, z1, t0, t1 = fid(fp, P[4], ps0 - bs[0], ps1 - bs[1], bs[2], bs[3], dt)
    bs[0] += w0 * dt
    bs[1] += w1 * dt
    bs[2] = z0
    bs[3] = z1
    bs[4] = t0
    bs[5] = t1
    ok = math.isfinite(t0) and math.isfinite(t1) and math.isfinite(z0) and math.isfinite(z1)
    for i in range(n):
        ok = ok and math.isfinite(x[i])
    return ok


@njit(cache=True, fastmath=_FM)
def _record(x, bs, c, P, avp, aux, dxs, out):
    rhs(x, bs[4], bs[5], _av.apply(c[0], avp), _av.apply(c[1], avp), P, dxs, aux)
    na = P[8].shape[0]
    cxp = P[11]
    out[0] = aux[10]
    out[1] = aux[11]
    for a in range(2):
        s = 0.0
        for k in range(na):
            s += cxp[k] * x[N_BODY + a * na + k]
        out[2 + a] = s
    out[4] = aux[6]
    out[5] = aux[7]
    out[6] = bs[4]
    out[7] = bs[5]
    out[8] = bs[2]
    out[9] = bs[3]
    out[10] = bs[0]
    out[11] = bs[1]
    out[12] = _av.apply(c[0], avp)
    out[13] = _av.apply(c[1], avp)
    for i in range(6):
        out[14 + i] = aux[i]
    for i in range(3):
        out[20 + i] = x[i]


@njit(cache=True, fastmath=_FM)
def integrate(P, fid, fp, avp, x0, bs0, r, dt, rec_every, out):
    """Integrate over command samples ``r`` (n_steps + 1, 2) [rad] every ``dt`` [s],
    recording :data:`REC` every ``rec_every`` steps into ``out``. Returns -1 or the first
    step whose state became non-finite. ``x0``/``bs0`` are updated to the final state."""
    n = x0.shape[0]
    x = x0
    bs = bs0
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    xt = np.empty(n)
    aux = np.empty(12)
    c0 = np.empty(2)
    cm = np.empty(2)
    c1 = np.empty(2)
    nsteps = r.shape[0] - 1
    rec = 0
    for k in range(nsteps + 1):
        kn = min(k + 1, nsteps)
        for j in range(2):
            c0[j] = r[k, j]
            c1[j] = r[kn, j]
            cm[j] = 0.5 * (c0[j] + c1[j])
        if k % rec_every == 0:
            _record(x, bs, c0, P, avp, aux, k1, out[rec])
            rec += 1
        if k == nsteps:
            break
        if not step(x, bs, c0, cm, c1, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux):
            return k + 1
    return -1


@njit(cache=True, fastmath=_FM)
def _dwell_one(P, fid, fp, avp, x0, amp, freq, fmeas, dt, nset, nmeas, out):
    """Two sines (pitch amp[0] sin(2 pi freq[0] t), yaw amp[1] sin(2 pi freq[1] t)) from rest;
    Fourier coefficients at ``fmeas`` of (xp_pitch, xp_yaw, theta_pitch, theta_yaw) over
    ``nmeas`` steps after ``nset``: out[o] = (2/N sum y sin, 2/N sum y cos, 1/N sum y)."""
    n = x0.shape[0]
    x = x0.copy()
    bs = np.zeros(6)
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    xt = np.empty(n)
    aux = np.empty(12)
    rec = np.empty(len(REC))
    c0 = np.empty(2)
    cm = np.empty(2)
    c1 = np.empty(2)
    for o in range(4):
        for j in range(3):
            out[o, j] = 0.0
    w = 2.0 * math.pi
    for k in range(nset + nmeas):
        t = k * dt
        for j in range(2):
            c0[j] = amp[j] * math.sin(w * freq[j] * t)
            cm[j] = amp[j] * math.sin(w * freq[j] * (t + 0.5 * dt))
            c1[j] = amp[j] * math.sin(w * freq[j] * (t + dt))
        if k >= nset:
            _record(x, bs, c0, P, avp, aux, k1, rec)
            s = math.sin(w * fmeas * t)
            c = math.cos(w * fmeas * t)
            for o in range(4):
                y = rec[(2, 3, 0, 1)[o]]
                out[o, 0] += y * s
                out[o, 1] += y * c
                out[o, 2] += y
        if not step(x, bs, c0, cm, c1, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux):
            return k + 1
    for o in range(4):
        out[o, 0] *= 2.0 / nmeas
        out[o, 1] *= 2.0 / nmeas
        out[o, 2] *= 1.0 / nmeas
    return -1


@njit(cache=True, parallel=True, fastmath=_FM)
def dwell_batch(P, fid, fp, avp, x0, amps, freqs, fmeas, dts, nset, nmeas, out, status):
    """Independent two-axis dwells in parallel (rows of ``amps``/``freqs`` (n, 2))."""
    for b in prange(amps.shape[0]):
        status[b] = _dwell_one(P, fid, fp, avp, x0, amps[b], freqs[b], fmeas[b], dts[b], nset[b],
                               nmeas[b], out[b])
