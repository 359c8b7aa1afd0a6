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
    actuators    the one linear actuator model (taos.planar.actuator), x_c,i = R avionics(theta_c,i),
                 load input F_L,i
    bearing      (phi, z, T) advanced over each step by the friction law's implicit bearing solve
                 (its registry entry's ``bearing_step``; :mod:`taos.friction._vector`) in
                 substeps (:mod:`taos.taos3d._bearing`), given the pose at the step ends; the
                 kernels take the law as ``fid`` = (bearing_step, zdot3, torque3), a tuple
                 of first-class functions

Time stepping (second order in the bearing coupling):

* classical RK4 for (q, v, actuators) with T held at its step-start value T_n, then the
  bearing update to T_{n+1}, then the velocity kick v += (dt / 2) a_T (T_{n+1} - T_n)
  (:func:`_torque_kick`; the body acceleration is affine in T, so this makes the velocity
  increment the trapezoid of T over the step; the position's share of the ramp is
  O(dt^2 dT), third order);
* the bearing (phi, z) by variable-step BDF2 under its own step-size control
  (:func:`taos.taos3d._bearing.advance`): psi = G e linear over the body step, substeps where
  the local error estimate or the law's unstable fast mode asks for them, one substep
  (h_b = dt, the constant-step BDF2 y_{n+1} = (4 y_n - y_{n-1}) / 3 + (2 dt / 3) y'_{n+1},
  i.e. the law's backward-Euler step with y_n -> (4 y_n - y_{n-1}) / 3 and dt -> 2 dt / 3)
  elsewhere; L-stable, as the stiff chain-rotation / bristle-damping time constant
  Kc (sigma_1 + sigma_2) needs; the history starts at rest (y_{-1} = y_0); the velocity kick
  uses the torque's mean over the substeps;
* the bearing solve continues from the previous (sub)step's slip speed (``bs[BS_SLIP]``), so
  where a Stribeck law makes the implicit step multi-valued it keeps the bearing's branch
  (stick-slip hysteresis; :func:`taos.friction._vector.solve_slip`).

Against a fine reference on the 60 s two-axis Green Run (first 4 s) the smooth laws' error
at 4e-4 s is 1-3 % of the former first-order scheme's (T held, backward-Euler bearing) at
2e-4 s. Where a law's torque falls with the slip rate at fixed z the massless bearing has an
unstable fast mode (a relaxation oscillation of the slip rate), which a fixed implicit step
damps away; the bearing substeps resolve it. The shipped LuGre laws' torque rises with the
slip rate (rational bristle-damping decay), and modified LuGre's 60 s engine angle converges
at second order: 1.8e-5 deg at 4e-4 s against a 2.5e-5 s run (tests/test_taos3d_step.py,
benchmarks/RESULTS.md; :mod:`taos.taos3d._bearing`, docs/theory/taos3d.md). The stiff bearing time constant
never enters the explicit part, so stability sets no step below 1.1 ms (the oil column and
the engine's translational modes on the chain, |lambda|max 2463 rad/s on the hot-fire model,
omega dt < 2.8 for RK4); accuracy sets the default 4e-4 s. A quantised command is piecewise
constant in time: every stage takes its mean over the step (:func:`stage_inputs`,
:func:`command_mean`), which removes the first-order error of sampling its jumps at the
stage points. Quaternions are renormalised after each step. With friction off (T = 0) the
scheme is plain RK4.

The right-hand side :func:`_rhs` uses scalar locals and tuples only (no heap arrays), and the
step's kernels allocate nothing and are compiled without reference counting (``_nrt=False``);
the recorded step reuses its derivative as the first RK4 stage. A numba call passes the
packed model ``P`` as about 150 machine words on the stack, so the run's loops
(:func:`_steps`, :func:`_dwell_steps`) inline the step (:func:`_step`), which runs its four
stages through one inlined right-hand side; :func:`rhs` and :func:`step` are the callable
(non-inlined) forms. The actuator block and its limits run with the second-order valve's state
size (6) as a literal (unrolled loops; other sizes the runtime-size loops), and the log map
needs no library call (:func:`_logq4`): issue 28, 1.29 -> 0.92 us a step at 4e-4 s, the
arithmetic unchanged to rounding (benchmarks/RESULTS.md).

Packed data (every index below is a module constant of :mod:`taos.taos3d._layout`, re-exported
here, used by the packer :func:`taos.taos3d.simulate.pack` and the kernels alike;
``tests/test_kernel_packs.py`` checks the tables tile their arrays):

* ``P``: the model, a :class:`~taos.taos3d._layout.TaosParams` named tuple (fields, shapes and
  units in its docstring);
* ``x`` (:data:`N_BODY` + 2 n_a): engine position ``X_P`` (3) [m], orientation quaternion
  ``X_Q`` (4, xyzw) [-], body twist: linear ``X_V`` (3) [m/s] and angular ``X_W`` (3)
  [rad/s]; then the pitch and the yaw actuator's states (n_a each,
  :func:`taos.planar.actuator.actuator_state_space` order, SI);
* ``bs`` (:data:`N_BEARING`): the bearing state, ``BS_*``;
* ``aux`` (:data:`N_AUX`): what :func:`rhs` reports besides the derivative, ``AUX_*``;
* ``fp``: the friction law's packed parameters (:mod:`taos.friction._slots`), ``avp`` the
  avionics' (``AV_*``, :mod:`taos.planar._avionics_slots`);
* records (:data:`REC`, columns ``REC_*``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..planar import _avionics_kernels as _av
from ..planar import saturation as _lim
from ..planar._avionics_slots import AV_LSB, AV_ROUND
from . import _bearing as _bg
# the packed model and the index tables, shared with the packer (re-exported: the kernels' layout)
from ._layout import (  # noqa: F401
    AUX_FL, AUX_PHI, AUX_THETA, AUX_W, BS_H, BS_PHI, BS_PHI_PREV, BS_SLIP, BS_T, BS_W, BS_Z, BS_Z_PREV, N_AUX,
    N_BEARING, N_BODY, REC, REC_FL, REC_P, REC_PHI, REC_PL, REC_Q, REC_TF, REC_THETA, REC_U, REC_W, REC_XP, REC_Z,
    U_END, U_MID, U_START, X_P, X_Q, X_V, X_W, _DWELL_COLS, TaosParams)

_FM = {"reassoc", "contract", "arcp", "nsz"}


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _logq(q, r):
    """Rotation vector of the unit quaternion q (xyzw) into r; returns the angle."""
    r0, r1, r2, th = _logq4(q[0], q[1], q[2], q[3])
    r[0] = r0
    r[1] = r1
    r[2] = r2
    return th


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _logq4(qx, qy, qz, qw):
    """Rotation vector (r0, r1, r2) [rad] and angle [rad] of the unit quaternion (xyzw):
    a = 2 atan2(n, |w|), r = a q_xyz / n sgn(w) (n = |q_xyz|). Below t = n / |w| = 0.15 (angles
    below 17 deg, the gimbal's range) atan(t) / t is its Taylor series to t^22 (the next term,
    t^24 / 25, is below 1.1e-18 there): no call to atan2, whose call makes the compiled
    right-hand side spill every live register."""
    s = 1.0 if qw >= 0 else -1.0
    n = math.sqrt(qx * qx + qy * qy + qz * qz)
    aw = abs(qw)
    if n < 0.15 * aw:
        t = n / aw
        t2 = t * t
        at = 1.0 + t2 * (-1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (-1.0 / 7.0 + t2 * (1.0 / 9.0 + t2 * (
            -1.0 / 11.0 + t2 * (1.0 / 13.0 + t2 * (-1.0 / 15.0 + t2 * (1.0 / 17.0 + t2 * (
                -1.0 / 19.0 + t2 * (1.0 / 21.0 + t2 * (-1.0 / 23.0)))))))))))  # atan(t) / t
        f = 2.0 * at / aw * s
        return f * qx, f * qy, f * qz, f * s * n
    a = 2.0 * math.atan2(n, aw)
    f = a / n * s
    return f * qx, f * qy, f * qz, a


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _row6(M, i, a0, a1, a2, a3, a4, a5):
    return M[i, 0] * a0 + M[i, 1] * a1 + M[i, 2] * a2 + M[i, 3] * a3 + M[i, 4] * a4 + M[i, 5] * a5


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _mv6(M, a0, a1, a2, a3, a4, a5):
    """M (6, 6) times the vector (a0..a5), as a tuple (scalar locals: no heap arrays)."""
    return (_row6(M, 0, a0, a1, a2, a3, a4, a5), _row6(M, 1, a0, a1, a2, a3, a4, a5),
            _row6(M, 2, a0, a1, a2, a3, a4, a5), _row6(M, 3, a0, a1, a2, a3, a4, a5),
            _row6(M, 4, a0, a1, a2, a3, a4, a5), _row6(M, 5, a0, a1, a2, a3, a4, a5))


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _cross3(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rotation(qx, qy, qz, qw):
    """Rotation matrix R (body -> world) of the unit quaternion (xyzw), row-major 9-tuple."""
    return (1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw),
            2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw),
            2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy))


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rv(R, a0, a1, a2):
    """R a for R the row-major 9-tuple of :func:`_rotation` (body -> world)."""
    return (R[0] * a0 + R[1] * a1 + R[2] * a2, R[3] * a0 + R[4] * a1 + R[5] * a2,
            R[6] * a0 + R[7] * a1 + R[8] * a2)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rtv(R, a0, a1, a2):
    """R^T a for R the row-major 9-tuple of :func:`_rotation` (world -> body)."""
    return (R[0] * a0 + R[3] * a1 + R[6] * a2, R[1] * a0 + R[4] * a1 + R[7] * a2,
            R[2] * a0 + R[5] * a1 + R[8] * a2)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _world_torque(r0, r1, r2, th, g0, g1, g2):
    """World torque Jl(r)^-T g [N m] of the generalized torque g conjugate to the rotation
    vector r [rad] (angle th [rad]): g + r x g / 2 + c r x (r x g),
    c = 1/th^2 - (1 + cos th) / (2 th sin th) = 1/th^2 - cot(th/2) / (2 th); below 0.3 rad its
    Taylor series 1/12 + th^2/720 + th^4/30240 + th^6/1209600 + th^8/47900160 (the next term,
    5.3e-10 th^10, is below 4e-14 of c there)."""
    if th < 0.3:
        t2 = th * th
        c = 1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 * (1.0 / 47900160.0))))
    else:
        c = 1.0 / (th * th) - (1.0 + math.cos(th)) / (2.0 * th * math.sin(th))
    rg0, rg1, rg2 = _cross3(r0, r1, r2, g0, g1, g2)
    rrg0, rrg1, rrg2 = _cross3(r0, r1, r2, rg0, rg1, rg2)
    return g0 + 0.5 * rg0 + c * rrg0, g1 + 0.5 * rg1 + c * rrg1, g2 + 0.5 * rg2 + c * rrg2


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _act_linear(Aa, bxc, bf, ux, F, x, off, dx, m):
    """dx[off:off+m] = A x[off:off+m] + b_xc ux + b_fl F: the linear actuator (m states,
    :func:`taos.planar.actuator.actuator_state_space`) at the command ``ux`` = R u [m] and the load
    force ``F`` [N]; inlined, so a literal ``m`` lets LLVM unroll the fixed-size products."""
    for k in range(m):
        s = bxc[k] * ux + bf[k] * F
        for j in range(m):
            s += Aa[k, j] * x[off + j]
        dx[off + k] = s


#: the actuator rate/pressure limits (taos.planar.saturation), the same source compiled inline here
_valve_pressure = njit(fastmath=_FM, error_model="numpy", inline="always")(_lim.valve_pressure_rows.py_func)


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def rhs(x, T0, T1, u0, u1, P, dx, aux):
    """State derivative of the TAOS engine + actuators (module docstring); arguments as
    :func:`_rhs`, whose compiled body this calls (the step inlines that body instead: a call
    passes the packed model's ~150 machine words on the stack)."""
    _rhs(x, T0, T1, u0, u1, P, dx, aux)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rhs(x, T0, T1, u0, u1, P, dx, aux):
    """State derivative of the TAOS engine + actuators (module docstring).

    Parameters
    ----------
    x : (N_BODY + 2 n_a,) float64
        State (``X_*``, then the pitch and yaw actuators) [SI].
    T0, T1 : float
        Bearing friction torque, pitch and yaw [N m].
    u0, u1 : float
        Post-avionics commands, pitch and yaw [rad].
    P : TaosParams
        The packed model.
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
        # second-order valve's size (6 states) as a literal: fixed-size loops
        if na == 6:
            _act_linear(Aa, bxc, bf, Rarm * u, F, x, off, dx, 6)
        else:
            _act_linear(Aa, bxc, bf, Rarm * u, F, x, off, dx, na)
        if mlim == 6:
            _valve_pressure(lim, x, off, u, dx, 6)
        elif mlim > 0:
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
    ``P`` the packed model (:class:`TaosParams`)."""
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
    ``x`` (``X_*``) [rad]; ``P`` the packed model (:class:`TaosParams`)."""
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


@njit(cache=True, error_model="numpy")
def command_mean(c0, c1, p):
    """Mean of the avionics command path (:func:`taos.planar.avionics.apply`, packed parameters ``p``)
    over a command ramping linearly from ``c0`` to ``c1`` [rad] (one integration step) [rad].
    With quantisation the command path is piecewise constant in the command (bins of one LSB,
    edges at k LSB for truncation, (k + 1/2) LSB for rounding; the crossover gain is a
    function of the quantised value), so the mean is the bin values weighted by the fraction
    of the ramp in each bin: an integrator that uses it for a step places the output's jumps
    in time to first order instead of at its stage points. ``p``: slots ``AV_*``."""
    lo = min(c0, c1)
    hi = max(c0, c1)
    lsb = p[AV_LSB]
    if lsb <= 0.0 or hi - lo <= 0.0:
        return _av.apply(0.5 * (lo + hi), p)
    off = 0.5 if p[AV_ROUND] > 0.5 else 0.0
    k = math.floor(lo / lsb - off) + 1.0
    b = (k + off) * lsb  # first bin edge above lo
    a = lo
    s = 0.0
    while b < hi:
        s += (b - a) * _av.apply(0.5 * (a + b), p)
        a = b
        k += 1.0
        b = (k + off) * lsb
    s += (hi - a) * _av.apply(0.5 * (a + hi), p)
    return s / (hi - lo)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def stage_inputs(c0, cm, c1, avp):
    """Post-avionics commands [rad] for the RK4 stages (start, middle, end; pitch and yaw) of a
    step with pre-avionics commands c0/cm/c1 (2,) at its start, middle and end. A quantised
    command path is piecewise constant in time: every stage then takes its mean over the step
    (:func:`command_mean`), which places its jumps in time to first order
    (sampled at the stages, a jump would move to a stage point: an O(dt) error). ``avp`` the
    packed avionics (``AV_*``). Returns (u0, u1) at the start, the middle and the end."""
    if avp[AV_LSB] > 0.0:
        a0 = command_mean(c0[0], c1[0], avp)
        a1 = command_mean(c0[1], c1[1], avp)
        return a0, a1, a0, a1, a0, a1
    return (_av.apply(c0[0], avp), _av.apply(c0[1], avp), _av.apply(cm[0], avp), _av.apply(cm[1], avp),
            _av.apply(c1[0], avp), _av.apply(c1[1], avp))


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def step(x, bs, u, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux, k1_ready, psi):
    """One step (:func:`_step`, whose compiled body this calls; the run's loop
    :func:`_steps` inlines that body instead); arguments and return as :func:`_step`."""
    return _step(x, bs, u, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux, k1_ready, psi)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _step(x, bs, u, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux, k1_ready, psi):
    """One step (module docstring): RK4 on (q, v, actuators) with the bearing torque T held at
    its step-start value, the BDF2 bearing update, the trapezoidal torque kick.

    Parameters
    ----------
    x : (N_BODY + 2 n_a,) float64
        State (``X_*``, then the actuators) [SI], advanced in place.
    bs : (N_BEARING,) float64
        Bearing state (``BS_*``), advanced in place.
    u : 6-tuple of float
        Post-avionics stage commands [rad] (:func:`stage_inputs`): pitch and yaw at the step's
        start (``U_START``), middle (``U_MID``) and end (``U_END``).
    dt : float
        Step [s].
    P : TaosParams
        The packed model.
    fid : tuple of first-class functions
        The friction law's ``bearing_step``, ``zdot3``, ``torque3``
        (:data:`taos.friction.registry.BEARING_SIG`, ``ZDOT3_SIG``, ``TORQUE3_SIG``).
    fp : (NPARAM,) float64
        The law's packed (normal-load scaled) parameters (:mod:`taos.friction._slots`).
    avp : float64 array
        Packed avionics (``AV_*``; unused here, the stage commands already passed through it).
    k1, k2, k3, k4, xt : (N_BODY + 2 n_a,) float64
        Scratch: the RK4 stages and the trial state.
    aux : (N_AUX,) float64
        Scratch for :func:`rhs`.
    k1_ready : bool
        k1 already holds the derivative at the step start (from the record, same inputs).
    psi : (2,) float64
        The pose-demanded bearing angle :func:`pose_psi` at the step start [rad]; receives
        its value at the step end (the torque kick moves no pose: the next step's start).

    Returns True while the state stays finite."""
    n = x.shape[0]
    T0, T1 = bs[BS_T], bs[BS_T + 1]
    qa0, qa1 = psi[0], psi[1]  # the pose-demanded bearing angle at the step start
    h = 0.5 * dt
    # the four stages through one inlined right-hand side (one copy of its code, no call)
    for st in range(4):
        if st == 0:
            if k1_ready:
                continue
            for i in range(n):
                xt[i] = x[i]
            ko = k1
            ua, ub = u[U_START], u[U_START + 1]
        elif st == 1:
            for i in range(n):
                xt[i] = x[i] + h * k1[i]
            ko = k2
            ua, ub = u[U_MID], u[U_MID + 1]
        elif st == 2:
            for i in range(n):
                xt[i] = x[i] + h * k2[i]
            ko = k3
            ua, ub = u[U_MID], u[U_MID + 1]
        else:
            for i in range(n):
                xt[i] = x[i] + dt * k3[i]
            ko = k4
            ua, ub = u[U_END], u[U_END + 1]
        _rhs(xt, T0, T1, ua, ub, P, ko, aux)
    h6 = dt / 6.0
    for i in range(n):
        x[i] += h6 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    qn = math.sqrt(x[X_Q] * x[X_Q] + x[X_Q + 1] * x[X_Q + 1] + x[X_Q + 2] * x[X_Q + 2] + x[X_Q + 3] * x[X_Q + 3])
    for i in range(X_Q, X_Q + 4):
        x[i] /= qn
    r0, r1, r2, th = _logq4(x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3])
    ps0, ps1 = _psi(x, r0, r1, r2, P)
    psi[0] = ps0
    psi[1] = ps1
    # the bearing by variable-step BDF2 under its own error control (taos.taos3d._bearing),
    # psi linear over the step; the engine gets the mean torque over the step
    m0, m1, _ = _bg.advance(bs, fid, fp, P.bearing_compliance, dt, qa0, qa1, ps0, ps1, _bg.tolerance(dt), _bg.MAX_SPLIT,
                            _bg.FAST_STEPS)
    _torque_kick(x, r0, r1, r2, th, m0 - T0, m1 - T1, dt, P)  # the mean of T over the step (second order)
    t0, t1, z0, z1 = bs[BS_T], bs[BS_T + 1], bs[BS_Z], bs[BS_Z + 1]
    s = t0 + t1 + z0 + z1  # a NaN or an infinity anywhere makes the sum non-finite
    for i in range(n):
        s += x[i]
    return math.isfinite(s)


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _record(x, bs, c, u0, u1, P, avp, aux, dxs, out):
    """Record :data:`REC` (columns ``REC_*``) into ``out`` at the state ``x`` with bearing
    state ``bs``, pre-avionics commands ``c`` (2,) [rad] and post-avionics ``u0``, ``u1``
    [rad] as the first RK4 stage takes them; ``P`` the packed model, ``avp`` the packed
    avionics; ``dxs`` receives the derivative there, ``aux`` :func:`rhs`'s reports."""
    rhs(x, bs[BS_T], bs[BS_T + 1], u0, u1, P, dxs, aux)
    cxp = P.act_c_xp
    na = cxp.shape[0]
    for a in range(2):
        out[REC_THETA + a] = aux[AUX_THETA + a]
        s = 0.0
        for k in range(na):
            s += cxp[k] * x[N_BODY + a * na + k]
        out[REC_XP + a] = s
        out[REC_FL + a] = aux[AUX_FL + a]
        out[REC_TF + a] = bs[BS_T + a]
        out[REC_Z + a] = bs[BS_Z + a]
        out[REC_PHI + a] = bs[BS_PHI + a]
        out[REC_U + a] = _av.apply(c[a], avp)
        out[REC_PL + a] = x[N_BODY + a * na + P.act_pl_index]
        out[REC_Q + a] = x[N_BODY + a * na + P.act_q_index]
    for i in range(6):
        out[REC_W + i] = aux[AUX_W + i]
    for i in range(3):
        out[REC_P + i] = x[X_P + i]


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy")
def integrate(P, fid, fp, avp, x0, bs0, r, dt, rec_every, out):
    """Integrate over command samples, recording :data:`REC` every ``rec_every`` steps.

    Parameters
    ----------
    P : TaosParams
        The packed model (:func:`taos.taos3d.simulate.pack`).
    fid : tuple of first-class functions
        The friction law's ``bearing_step``, ``zdot3``, ``torque3``
        (:data:`taos.friction.registry.BEARING_SIG`, ``ZDOT3_SIG``, ``TORQUE3_SIG``).
    fp : (NPARAM,) float64
        The law's packed (normal-load scaled) parameters (:mod:`taos.friction._slots`).
    avp : float64 array
        Packed avionics (``AV_*``, :meth:`taos.planar.avionics.Avionics.pack`).
    x0 : (N_BODY + 2 n_a,) float64
        Initial state (``X_*``) [SI]; updated to the final state.
    bs0 : (N_BEARING,) float64
        Initial bearing state (``BS_*``; zeros at rest); updated to the final state.
    r : (n_steps + 1, 2) float64
        Pre-avionics commands, pitch and yaw, every ``dt`` [rad].
    dt : float
        Step [s].
    rec_every : int
        Record every that many steps.
    out : (n_steps // rec_every + 1, len(REC)) float64
        Receives the records (columns ``REC_*``).

    Returns -1, or the first step whose state became non-finite."""
    n = x0.shape[0]
    return _steps(P, fid, fp, avp, x0, bs0, r, dt, rec_every, out, np.empty((5, n)), np.empty(N_AUX),
                  np.empty((4, 2)))


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _steps(P, fid, fp, avp, x, bs, r, dt, rec_every, out, ks, aux, cs):
    """:func:`integrate`'s loop (arguments as there; ``ks`` (5, n), ``aux`` (N_AUX,), ``cs``
    (4, 2) scratch), compiled without reference counting, with the step inlined (a call
    passes the packed model's ~150 machine words on the stack)."""
    k1 = ks[0]
    k2 = ks[1]
    k3 = ks[2]
    k4 = ks[3]
    xt = ks[4]
    c0 = cs[0]
    cm = cs[1]
    c1 = cs[2]
    psi = cs[3]
    psi[0], psi[1] = pose_psi(x, P)
    nsteps = r.shape[0] - 1
    rec = 0
    for k in range(nsteps + 1):
        kn = min(k + 1, nsteps)
        for j in range(2):
            c0[j] = r[k, j]
            c1[j] = r[kn, j]
            cm[j] = 0.5 * (c0[j] + c1[j])
        u = stage_inputs(c0, cm, c1, avp)
        ready = k % rec_every == 0
        if ready:
            # k1 = the derivative at the step start
            _record(x, bs, c0, u[U_START], u[U_START + 1], P, avp, aux, k1, out[rec])
            rec += 1
        if k == nsteps:
            break
        if not _step(x, bs, u, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux, ready, psi):
            return k + 1
    return -1


@njit(cache=True, fastmath=_FM, error_model="numpy")
def _dwell_one(P, fid, fp, avp, x0, amp, freq, fmeas, dt, nset, nmeas, out):
    """Two sines (pitch amp[0] sin(2 pi freq[0] t), yaw amp[1] sin(2 pi freq[1] t)) from rest;
    Fourier coefficients at ``fmeas`` of (xp_pitch, xp_yaw, theta_pitch, theta_yaw)
    (:data:`_DWELL_COLS`) over ``nmeas`` steps after ``nset``: out[o] = (2/N sum y sin,
    2/N sum y cos, 1/N sum y) [m or rad].

    Parameters
    ----------
    P, fid, fp, avp
        As :func:`integrate`.
    x0 : (N_BODY + 2 n_a,) float64
        The rest state (``X_*``); not modified.
    amp : (2,) float64
        Command amplitudes, pitch and yaw [rad].
    freq : (2,) float64
        Command frequencies, pitch and yaw [Hz].
    fmeas : float
        Frequency the outputs are correlated at [Hz].
    dt : float
        Step [s].
    nset, nmeas : int
        Settling and measured steps.
    out : (4, 3) float64
        Receives the Fourier coefficients.

    Returns -1, or the first step whose state became non-finite."""
    return _dwell_steps(P, fid, fp, avp, x0.copy(), np.zeros(N_BEARING), amp, freq, fmeas, dt, nset, nmeas, out,
                        np.empty((5, x0.shape[0])), np.empty(N_AUX), np.empty(len(REC)), np.empty((4, 2)))


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _dwell_steps(P, fid, fp, avp, x, bs, amp, freq, fmeas, dt, nset, nmeas, out, ks, aux, rec, cs):
    """:func:`_dwell_one`'s loop from the state ``x``, bearing state ``bs`` (scratch ``ks``
    (5, n), ``aux``, ``rec``, ``cs`` (4, 2)), compiled without reference counting, with the
    step inlined (as :func:`_steps`)."""
    k1 = ks[0]
    k2 = ks[1]
    k3 = ks[2]
    k4 = ks[3]
    xt = ks[4]
    c0 = cs[0]
    cm = cs[1]
    c1 = cs[2]
    for o in range(4):
        for j in range(3):
            out[o, j] = 0.0
    psi = cs[3]
    psi[0], psi[1] = pose_psi(x, P)
    w = 2.0 * math.pi
    for k in range(nset + nmeas):
        t = k * dt
        for j in range(2):
            c0[j] = amp[j] * math.sin(w * freq[j] * t)
            cm[j] = amp[j] * math.sin(w * freq[j] * (t + 0.5 * dt))
            c1[j] = amp[j] * math.sin(w * freq[j] * (t + dt))
        u = stage_inputs(c0, cm, c1, avp)
        if k >= nset:
            _record(x, bs, c0, u[U_START], u[U_START + 1], P, avp, aux, k1, rec)
            s = math.sin(w * fmeas * t)
            c = math.cos(w * fmeas * t)
            for o in range(4):
                y = rec[_DWELL_COLS[o]]
                out[o, 0] += y * s
                out[o, 1] += y * c
                out[o, 2] += y
        if not _step(x, bs, u, dt, P, fid, fp, avp, k1, k2, k3, k4, xt, aux, k >= nset, psi):
            return k + 1
    for o in range(4):
        out[o, 0] *= 2.0 / nmeas
        out[o, 1] *= 2.0 / nmeas
        out[o, 2] *= 1.0 / nmeas
    return -1


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy")
def dwell_batch(P, fid, fp, avp, x0, amps, freqs, fmeas, dts, nset, nmeas, out, status, b0, b1):
    """Independent two-axis dwells b0 <= b < b1, one after the other without the GIL (the caller
    runs slices on threads: :func:`taos.planar._parallel.run_each`): :func:`_dwell_one` for row b of ``amps``
    (n, 2) [rad] and ``freqs`` (n, 2) [Hz], with ``fmeas`` (n,) [Hz], ``dts`` (n,) [s],
    ``nset``, ``nmeas`` (n,) int, into ``out[b]`` (n, 4, 3) and ``status[b]`` (n,) int
    (-1 or the failing step); ``P``, ``fid``, ``fp``, ``avp``, ``x0`` as :func:`_dwell_one`."""
    for b in range(b0, b1):
        status[b] = _dwell_one(P, fid, fp, avp, x0, amps[b], freqs[b], fmeas[b], dts[b], nset[b],
                               nmeas[b], out[b])
