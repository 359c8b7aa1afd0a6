"""The TAOS right-hand side: the state derivative of the engine + actuators at a held bearing
torque (the formulation is in :mod:`taos.taos3d.dynamics`), the bearing's pose-demanded angle
psi = G e, and the velocity kick of a change of the bearing torque.

* :func:`rhs`: dx/dt of the packed state ``x`` (``X_*``, then the pitch and yaw actuators) and
  the reports ``aux`` (``AUX_*``: chain wrench [N, N m], load forces [N], bearing slip [rad],
  engine angles [rad]) given the bearing torque (T0, T1) [N m] and the post-avionics commands
  (u0, u1) [rad];
* :func:`pose_psi` / :func:`_psi`: psi = G e [rad], the bearing angles that carry no torque at
  the pose of ``x``;
* :func:`_torque_kick`: x[7:13] += h a, the body acceleration a change of the bearing torque adds
  (the step's trapezoidal torque kick).

Each is one compiled kernel, called by the step (:func:`taos.taos3d.dynamics.step`) and the
records; the packed model ``P`` is a record (:func:`taos.taos3d._layout.as_record`), passed as
one pointer, whose arrays have compile-time shapes (the actuator's state size is a constant of
the compiled code: fixed-size loops). The small helpers (:mod:`taos.taos3d._so3`,
:func:`_act_linear`, the limits, :func:`_psi`, :func:`_torque_kick`) are compiled inline into
their callers. Scalar locals and tuples only: no heap
arrays.
"""

from __future__ import annotations

import math

from numba import njit

from ..planar import saturation as _lim
from ._layout import AUX_FL, AUX_PHI, AUX_THETA, AUX_W, N_BODY, X_P, X_Q, X_V, X_W
from ._so3 import _FM, _cross3, _logq4, _mv6, _rotation, _row6, _rtv, _rv, _world_torque


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _act_linear(Aa, bxc, bf, ux, F, x, off, dx, m):
    """dx[off:off+m] = A x[off:off+m] + b_xc ux + b_fl F: the linear actuator (m states,
    :func:`taos.planar.actuator.actuator_state_space`) at the command ``ux`` = R u [m] and the load
    force ``F`` [N] (``m`` the size of the packed model's arrays: a compile-time constant, so
    LLVM unrolls the fixed-size products)."""
    for k in range(m):
        s = bxc[k] * ux + bf[k] * F
        for j in range(m):
            s += Aa[k, j] * x[off + j]
        dx[off + k] = s


#: the actuator rate/pressure limits (taos.planar.saturation), the same source compiled inline into
#: the right-hand side with the 3-D kernels' flags
_valve_pressure = njit(fastmath=_FM, error_model="numpy", inline="always")(_lim.valve_pressure_rows.py_func)


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def rhs(x, T0, T1, u0, u1, P, dx, aux):
    """State derivative of the TAOS engine + actuators (module docstring).

    Parameters
    ----------
    x : (N_BODY + 2 n_a,) float64
        State (``X_*``, then the pitch and yaw actuators) [SI].
    T0, T1 : float
        Bearing friction torque, pitch and yaw [N m].
    u0, u1 : float
        Post-avionics commands, pitch and yaw [rad].
    P : record
        The packed model (:class:`~taos.taos3d._layout.TaosParams` fields,
        :func:`~taos.taos3d._layout.as_record`).
    dx : (N_BODY + 2 n_a,) float64
        Receives dx/dt [SI per second].
    aux : (N_AUX,) float64
        Receives the chain wrench, load forces, bearing slip and engine angles (``AUX_*``).

    Written with scalar locals and tuples only (no heap arrays: it runs four times a step)."""
    Y, Yinv, Ks, G, Kc, S = (P.spatial_inertia, P.spatial_inertia_inv, P.chain_stiffness, P.slip_gain,
                             P.bearing_compliance, P.bearing_selection)
    Satt, Eatt, axes = P.structure_attach_m, P.engine_attach_m, P.bearing_axes
    Aa, bxc, bf, cxp = P.act_A, P.act_b_xc, P.act_b_fl, P.act_c_xp
    KLs, Rarm, Kn = P.line_stiffness_N_per_m, P.moment_arm_m, P.engine_stiffness_Nm_per_rad
    cLs, ivp, L0 = P.line_damping_Ns_per_m, P.act_vp_index, P.line_length0_m
    KLt, cLt = (KLs[0], KLs[1]), (cLs[0], cLs[1])   # each actuator line's own (pitch, yaw)
    lim = P.limits  # actuator/gimbal limits packed over one actuator's state (taos.planar.saturation)
    na = Aa.shape[0]
    mlim = (lim.shape[0] - _lim.N_HEAD) // _lim.N_ROWS if lim.shape[0] > 0 else 0  # states lim is packed over
    p0, p1, p2 = x[X_P], x[X_P + 1], x[X_P + 2]
    qx, qy, qz, qw = x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3]
    R = _rotation(qx, qy, qz, qw)
    r0, r1, r2, th = _logq4(qx, qy, qz, qw)
    # bearing slip and chain wrench
    phi0 = (G[0, 0] * p0 + G[0, 1] * p1 + G[0, 2] * p2 + G[0, 3] * r0 + G[0, 4] * r1 + G[0, 5] * r2
            - (Kc[0, 0] * T0 + Kc[0, 1] * T1))
    phi1 = (G[1, 0] * p0 + G[1, 1] * p1 + G[1, 2] * p2 + G[1, 3] * r0 + G[1, 4] * r1 + G[1, 5] * r2
            - (Kc[1, 0] * T0 + Kc[1, 1] * T1))
    W0, W1, W2, W3, W4, W5 = _mv6(Ks, p0 - S[0, 0] * phi0 - S[0, 1] * phi1, p1 - S[1, 0] * phi0 - S[1, 1] * phi1,
                                  p2 - S[2, 0] * phi0 - S[2, 1] * phi1, r0 - S[3, 0] * phi0 - S[3, 1] * phi1,
                                  r1 - S[4, 0] * phi0 - S[4, 1] * phi1, r2 - S[5, 0] * phi0 - S[5, 1] * phi1)
    # generalized torque conjugate to r, then world torque Jl^-T g
    tp = axes[0, 0] * r0 + axes[0, 1] * r1 + axes[0, 2] * r2
    ty = axes[1, 0] * r0 + axes[1, 1] * r1 + axes[1, 2] * r2
    g0 = -W3 - Kn * (axes[0, 0] * tp + axes[1, 0] * ty)
    g1 = -W4 - Kn * (axes[0, 1] * tp + axes[1, 1] * ty)
    g2 = -W5 - Kn * (axes[0, 2] * tp + axes[1, 2] * ty)
    wx, wy, wz = x[X_W], x[X_W + 1], x[X_W + 2]
    if lim.shape[0] > 0 and lim[_lim.LIM_THMAX] > 0.0:  # hard stops at the gimbal range (taos.planar.saturation)
        th_max, k_s, c_s = lim[_lim.LIM_THMAX], lim[_lim.LIM_KS], lim[_lim.LIM_CS]
        wo0, wo1, wo2 = _rv(R, wx, wy, wz)
        wp = axes[0, 0] * wo0 + axes[0, 1] * wo1 + axes[0, 2] * wo2
        wyw = axes[1, 0] * wo0 + axes[1, 1] * wo1 + axes[1, 2] * wo2
        tsp = _lim.stop_torque(tp, wp, th_max, k_s, c_s)
        tsy = _lim.stop_torque(ty, wyw, th_max, k_s, c_s)
        g0 += axes[0, 0] * tsp + axes[1, 0] * tsy
        g1 += axes[0, 1] * tsp + axes[1, 1] * tsy
        g2 += axes[0, 2] * tsp + axes[1, 2] * tsy
    Tw0, Tw1, Tw2 = _world_torque(r0, r1, r2, th, g0, g1, g2)
    Fw0, Fw1, Fw2 = -W0, -W1, -W2
    vx, vy, vz = x[X_V], x[X_V + 1], x[X_V + 2]
    # actuators
    for a in range(2):
        e0, e1, e2 = Eatt[a, 0], Eatt[a, 1], Eatt[a, 2]
        l0, l1, l2 = _rv(R, e0, e1, e2)  # lever R E_a
        E0 = p0 + l0 - Satt[a, 0]
        E1 = p1 + l1 - Satt[a, 1]
        E2 = p2 + l2 - Satt[a, 2]
        L = math.sqrt(E0 * E0 + E1 * E1 + E2 * E2)
        off = N_BODY + a * na
        xp = 0.0
        for k in range(na):
            xp += cxp[k] * x[off + k]
        KL, cL = KLt[a], cLt[a]
        F = KL * (xp - (L - L0[a]))
        if cL > 0.0:  # structural damping across the line: c_L (v_p - L')
            b0, b1, b2 = _cross3(wx, wy, wz, e0, e1, e2)
            b0 += vx
            b1 += vy
            b2 += vz
            Rb0, Rb1, Rb2 = _rv(R, b0, b1, b2)
            Ld = E0 * Rb0 + E1 * Rb1 + E2 * Rb2
            F += cL * (x[off + ivp] - Ld / L)
        fl0 = F * E0 / L
        fl1 = F * E1 / L
        fl2 = F * E2 / L
        Fw0 += fl0
        Fw1 += fl1
        Fw2 += fl2
        m0, m1, m2 = _cross3(l0, l1, l2, fl0, fl1, fl2)
        Tw0 += m0
        Tw1 += m1
        Tw2 += m2
        u = u0 if a == 0 else u1
        # the linear actuator, then the rate and pressure limits (none if lim is empty); the
        # sizes are the record's array shapes, constants of the compiled code: fixed-size loops
        _act_linear(Aa, bxc, bf, Rarm * u, F, x, off, dx, na)
        if mlim > 0:
            _valve_pressure(lim, x, off, u, dx, mlim)
        aux[AUX_FL + a] = F
    # rigid body (body frame, linear first): a = Yinv (f - v x* (Y v))
    Yv0, Yv1, Yv2, Yv3, Yv4, Yv5 = _mv6(Y, vx, vy, vz, wx, wy, wz)
    c10, c11, c12 = _cross3(wx, wy, wz, Yv0, Yv1, Yv2)
    c20, c21, c22 = _cross3(wx, wy, wz, Yv3, Yv4, Yv5)
    c30, c31, c32 = _cross3(vx, vy, vz, Yv0, Yv1, Yv2)
    f0, f1, f2 = _rtv(R, Fw0, Fw1, Fw2)
    f3, f4, f5 = _rtv(R, Tw0, Tw1, Tw2)
    f0 -= c10
    f1 -= c11
    f2 -= c12
    f3 -= c20 + c30
    f4 -= c21 + c31
    f5 -= c22 + c32
    for i in range(6):
        dx[X_V + i] = _row6(Yinv, i, f0, f1, f2, f3, f4, f5)
    dx[X_P], dx[X_P + 1], dx[X_P + 2] = _rv(R, vx, vy, vz)
    dx[X_Q] = 0.5 * (qw * wx + qy * wz - qz * wy)
    dx[X_Q + 1] = 0.5 * (qw * wy + qz * wx - qx * wz)
    dx[X_Q + 2] = 0.5 * (qw * wz + qx * wy - qy * wx)
    dx[X_Q + 3] = -0.5 * (qx * wx + qy * wy + qz * wz)
    aux[AUX_W] = W0
    aux[AUX_W + 1] = W1
    aux[AUX_W + 2] = W2
    aux[AUX_W + 3] = W3
    aux[AUX_W + 4] = W4
    aux[AUX_W + 5] = W5
    aux[AUX_PHI] = phi0
    aux[AUX_PHI + 1] = phi1
    aux[AUX_THETA] = tp
    aux[AUX_THETA + 1] = ty


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _torque_kick(x, r0, r1, r2, th, d0, d1, h, P):
    """x[7:13] += h a, a [m/s^2, rad/s^2] the engine's body-frame acceleration that a change
    (d0, d1) [N m] of the bearing torque adds at the state x (its rotation vector (r0, r1, r2)
    and angle th [rad], :func:`_logq4` of its quaternion): the chain wrench changes by
    dW = Ks S Kc dT (phi = G e - Kc T in :func:`rhs`), acting on the engine as
    (-dW[:3], Jl^-T (-dW[3:])) in the world, Y^-1 of that in the body frame. ``h`` [s];
    ``P`` the packed model (record, :func:`taos.taos3d._layout.as_record`)."""
    Yinv, BT = P.spatial_inertia_inv, P.torque_wrench
    dF0 = -(BT[0, 0] * d0 + BT[0, 1] * d1)
    dF1 = -(BT[1, 0] * d0 + BT[1, 1] * d1)
    dF2 = -(BT[2, 0] * d0 + BT[2, 1] * d1)
    g0 = -(BT[3, 0] * d0 + BT[3, 1] * d1)
    g1 = -(BT[4, 0] * d0 + BT[4, 1] * d1)
    g2 = -(BT[5, 0] * d0 + BT[5, 1] * d1)
    qx, qy, qz, qw = x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3]
    R = _rotation(qx, qy, qz, qw)
    Tw0, Tw1, Tw2 = _world_torque(r0, r1, r2, th, g0, g1, g2)
    f0, f1, f2 = _rtv(R, dF0, dF1, dF2)
    f3, f4, f5 = _rtv(R, Tw0, Tw1, Tw2)
    for i in range(6):
        x[X_V + i] += h * _row6(Yinv, i, f0, f1, f2, f3, f4, f5)


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def pose_psi(x, P):
    """psi = G e: the bearing angles (pitch, yaw) that carry no torque at the pose of the state
    ``x`` (``X_*``) [rad]; ``P`` the packed model (record, :func:`taos.taos3d._layout.as_record`)."""
    r0, r1, r2, _ = _logq4(x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3])
    return _psi(x, r0, r1, r2, P)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _psi(x, r0, r1, r2, P):
    """:func:`pose_psi` given the rotation vector (r0, r1, r2) [rad] of the state's quaternion."""
    G = P.slip_gain
    e0, e1, e2 = x[X_P], x[X_P + 1], x[X_P + 2]
    p0 = G[0, 0] * e0 + G[0, 1] * e1 + G[0, 2] * e2 + G[0, 3] * r0 + G[0, 4] * r1 + G[0, 5] * r2
    p1 = G[1, 0] * e0 + G[1, 1] * e1 + G[1, 2] * e2 + G[1, 3] * r0 + G[1, 4] * r1 + G[1, 5] * r2
    return p0, p1



#: the supply-pressure limit's share of an explicit step: its local rate r is integrated
#: explicitly up to GUARD_RATE_DT / dt, the excess exactly (:func:`pressure_guard`)
GUARD_RATE_DT = 1.0


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _limit_rate(lim, x, off, m, ip):
    """The supply-pressure limit's local decay rate r [1/s] of the load pressure P_L (state
    ``ip`` of the actuator at ``x[off:off+m]``): the limit adds c_f corr(q, P_L) to P_L' (c_f =
    4 beta A / V_t, the ``flow_in`` row, which is zero off P_L; :mod:`taos.planar.saturation`,
    :func:`~taos.planar.saturation.pressure_flow_correction`), whose slope in P_L is -r with
    r = c_f (|q| g'(d) / P_s + K_r / A [|P_L| > P_r]), g'(d) = 1 / (2 sqrt |d|) for |d| >= eps
    and 1 / sqrt(eps) within eps of stall (d = (P_s - sgn(q) P_L) / P_s). Its largest value
    (q = v_max, at stall, relief open) is :func:`taos.planar.saturation.pressure_limit_rate_per_s`.
    0 with the pressure limit off."""
    ps = lim[_lim.LIM_PS]
    if ps <= 0.0:
        return 0.0
    q = _lim._dot(lim, _lim.ROW_Q, m, x, off)
    p = _lim._dot(lim, _lim.ROW_P, m, x, off)
    sg = 1.0 if q >= 0 else -1.0
    ad = abs((ps - sg * p) / ps)
    eps = lim[_lim.LIM_EPS]
    gp = 1.0 / math.sqrt(eps) if ad < eps else 0.5 / math.sqrt(ad)
    r = abs(q) * gp / ps
    if abs(p) - lim[_lim.LIM_PR] > 0.0:
        r += lim[_lim.LIM_KRA]
    return r * lim[_lim.N_HEAD + _lim.ROW_FLOW_IN * m + ip]


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def pressure_guard(x, dt, P):
    """The rates lambda (pitch, yaw) [1/s] that the step integrates exactly on each actuator's
    load pressure (:func:`taos.taos3d.dynamics.step`): the part of the supply-pressure limit's
    local rate :func:`_limit_rate` at the state ``x`` above GUARD_RATE_DT / ``dt`` [s], 0 below
    (the limit's stiffness within eps of stall, up to :func:`taos.planar.saturation.
    pressure_limit_rate_per_s`, 3,946 1/s on the shipped models, is what would otherwise cap
    the explicit step at 2 / 3,946 = 5.07e-4 s). ``P`` the packed model (record)."""
    lim = P.limits
    na = P.act_A.shape[0]
    mlim = (lim.shape[0] - _lim.N_HEAD) // _lim.N_ROWS if lim.shape[0] > 0 else 0
    if mlim == 0:
        return 0.0, 0.0
    ip = P.act_pl_index
    cap = GUARD_RATE_DT / dt
    l0 = _limit_rate(lim, x, N_BODY, mlim, ip) - cap
    l1 = _limit_rate(lim, x, N_BODY + na, mlim, ip) - cap
    return max(l0, 0.0), max(l1, 0.0)
