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

* classical RK4 for (q, v, actuators) with T held at its step-start value T_n (:func:`_rk4`;
  :func:`_etd_rk4` near the actuators' stall, below), then the
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
at second order: 7.6e-5 / 1.8e-5 deg at 8e-4 / 4e-4 s against a 2.5e-5 s run (tests/test_taos3d_step.py,
benchmarks/RESULTS.md; :mod:`taos.taos3d._bearing`, docs/theory/taos3d.md). The stiff bearing time constant
never enters the explicit part, so stability sets no step below 1.1 ms (the oil column and
the engine's translational modes on the chain, |lambda|max 2463 rad/s on the hot-fire model,
omega dt < 2.8 for RK4; the explicit step's rule dt |lambda|max <= 2 allows 8.1e-4 s); accuracy
sets the time run's default 8e-4 s (:data:`taos.taos3d.simulate.DEFAULT_DT_S`; the dwells keep
4e-4 s). The one stiffer term is the supply-pressure limit near stall (its rate on the load
pressure up to 3,946 1/s, :func:`taos.planar.saturation.pressure_limit_rate_per_s`, which capped
the rule at 5.07e-4 s until issue 44): where its local rate exceeds 1 / dt
(:func:`pressure_guard`) the step advances the two load pressures by exponential time
differencing (:func:`_etd_rk4`) at that rate's excess, the other states by the same RK4; below
it (every shipped Green Run and dwell: its rate stays below 120 1/s there) the step is plain
RK4, bit for bit. A quantised command is piecewise
constant in time: every stage takes its mean over the step (:func:`stage_inputs`,
:func:`command_mean`), which removes the first-order error of sampling its jumps at the
stage points. Quaternions are renormalised after each step. With friction off (T = 0) the
scheme is plain RK4.

The right-hand side :func:`rhs` uses scalar locals and tuples only (no heap arrays), and the
step's kernels allocate nothing and are compiled without reference counting (``_nrt=False``);
the recorded step reuses its derivative as the first RK4 stage. The packed model ``P`` is a
numpy record (:func:`~taos.taos3d._layout.as_record`): numba passes it as one pointer (a
named tuple of arrays would be flattened into about 150 machine words a call) and its arrays
have compile-time shapes at fixed offsets, so the actuator block and its limits run
fixed-size, unrolled loops for whatever state size the model has. Each kernel is therefore
compiled once and called: the run's loops (:func:`_steps`, :func:`_dwell_steps`) call
:func:`step`, which calls :func:`rhs` for its four stages and
:func:`taos.taos3d._bearing.advance` for the bearing; only the small SO(3) and actuator
helpers are compiled inline. (Until issue 44 the loops inlined the step and the step the
right-hand side, through numba's ``inline="always"``, which re-types and copies the callee
into every caller: the 3-D Green Run compiled the right-hand side three times, about 75 of its
116 CPU-s from a cold cache; the warm step is as fast as then, benchmarks/RESULTS.md.) The log
map needs no library call (:func:`_logq4`).

The kernels live in small modules, one concept each, and are re-exported here (import them
from this module): :mod:`taos.taos3d._so3` the SO(3) maps (``_logq4``, ``_rotation``,
``_world_torque`` ...), :mod:`taos.taos3d._rhs` the right-hand side (``rhs``, ``pose_psi``,
``_torque_kick``), :mod:`taos.taos3d._commands` the avionics command path over a step
(``command_mean``, ``stage_inputs``), :mod:`taos.taos3d._bearing` the bearing's BDF2 substeps;
this module the step and the run's loops (``step``, ``integrate``, ``dwell_batch``).

Packed data (every index below is a module constant of :mod:`taos.taos3d._layout`, re-exported
here, used by the packer :func:`taos.taos3d.simulate.pack` and the kernels alike;
``tests/test_kernel_packs.py`` checks the tables tile their arrays):

* ``P``: the model, a record with the fields of the :class:`~taos.taos3d._layout.TaosParams`
  named tuple (fields, shapes and units in its docstring; :func:`~taos.taos3d._layout.as_record`,
  :func:`~taos.taos3d._layout.as_params`);
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
from . import _bearing as _bg
# the kernels' pieces, one concept a module (re-exported: callers and tests import them from here)
from ._commands import command_mean, stage_inputs  # noqa: F401
# the packed model and the index tables, shared with the packer (re-exported: the kernels' layout)
from ._layout import (  # noqa: F401
    AUX_FL, AUX_PHI, AUX_THETA, AUX_W, BS_H, BS_PHI, BS_PHI_PREV, BS_SLIP, BS_T, BS_W, BS_Z, BS_Z_PREV, N_AUX,
    N_BEARING, N_BODY, REC, REC_FL, REC_P, REC_PHI, REC_PL, REC_Q, REC_TF, REC_THETA, REC_U, REC_W, REC_XP, REC_Z,
    U_END, U_MID, U_START, X_P, X_Q, X_V, X_W, _DWELL_COLS, TaosParams, as_params, as_record)
from ._rhs import _act_linear, _psi, _torque_kick, _valve_pressure, pose_psi, pressure_guard, rhs  # noqa: F401
from ._so3 import (  # noqa: F401
    _FM, _cross3, _logq, _logq4, _mv6, _rotation, _row6, _rtv, _rv, _world_torque)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rk4(x, T0, T1, u, dt, P, ks, aux):
    """Classical RK4 of x (in place) over ``dt`` [s] at the held bearing torque (T0, T1) [N m]
    and the stage commands ``u`` (:func:`stage_inputs`), ks[0] holding f(x) (arguments as
    :func:`step`; ks[1:4] the other stages, ks[4] the trial state)."""
    n = x.shape[0]
    k1 = ks[0]
    k2 = ks[1]
    k3 = ks[2]
    k4 = ks[3]
    xt = ks[4]
    h = 0.5 * dt
    for i in range(n):
        xt[i] = x[i] + h * k1[i]
    rhs(xt, T0, T1, u[U_MID], u[U_MID + 1], P, k2, aux)
    for i in range(n):
        xt[i] = x[i] + h * k2[i]
    rhs(xt, T0, T1, u[U_MID], u[U_MID + 1], P, k3, aux)
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    rhs(xt, T0, T1, u[U_END], u[U_END + 1], P, k4, aux)
    h6 = dt / 6.0
    for i in range(n):
        x[i] += h6 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _phi123(z):
    """phi_1, phi_2, phi_3 of z <= 0 (phi_k(z) = sum_j z^j / (j + k)!; phi_1 = (e^z - 1) / z,
    phi_{k+1} = (phi_k - 1 / k!) / z): their series below |z| = 1 (to z^17: the next term is
    below 1e-18), the closed forms above (no cancellation worse than 1e-15 there)."""
    if z > -1.0:
        p3 = 0.0
        f = 1.0 / 2432902008176640000.0  # 1 / 20!, the coefficient of z^17 in phi_3
        for k in range(18):  # phi_3 = sum_j z^j / (j + 3)!, Horner from j = 17 down
            p3 = p3 * z + f
            f *= 20.0 - k  # 1 / (j + 3)! -> 1 / (j + 2)!
        p2 = 0.5 + z * p3
        p1 = 1.0 + z * p2
        return p1, p2, p3
    p1 = (math.exp(z) - 1.0) / z
    p2 = (p1 - 1.0) / z
    p3 = (p2 - 0.5) / z
    return p1, p2, p3


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _etd_rk4(x, T0, T1, u, dt, P, ks, aux, lam0, lam1):
    """:func:`_rk4` with the pitch and yaw actuators' load pressures y (the states P_L) advanced
    by the exponential time-differencing RK4 of Cox & Matthews (J. Comput. Phys. 176, 2002,
    eq. 26-29) on y' = -lam y + N(x), N = f + lam y, at the rates ``lam0``, ``lam1`` [1/s]
    (:func:`pressure_guard`, frozen over the step): with z = -lam dt, E = e^z, E2 = e^(z/2),
    Q = dt/2 phi_1(z/2) and N1..N4 at the stages,
    Y2 = E2 y + Q N1, Y3 = E2 y + Q N2, Y4 = E2 Y2 + Q (2 N3 - N1),
    y+ = E y + f1 N1 + 2 f2 (N2 + N3) + f3 N4, f1 = dt (phi_1 - 3 phi_2 + 4 phi_3),
    f2 = dt (phi_2 - 2 phi_3), f3 = dt (-phi_2 + 4 phi_3) (:func:`_phi123`). On
    y' = -(lam + mu) y it is stable for any lam while dt mu stays in an RK4-like region, and it
    keeps every equilibrium (f1 + 4 f2 + f3 = dt phi_1(z)): the stalled actuator's load pressure
    settles where the flows balance. The supply-pressure limit's flow enters P_L' alone (its
    ``flow_in`` column is zero off P_L, :mod:`taos.planar.saturation`), so its stiff rate is
    that of P_L. Every other state as :func:`_rk4` (arguments as there)."""
    i0 = N_BODY + P.act_pl_index  # the pitch and yaw load pressures
    i1 = i0 + P.act_A.shape[0]
    y0, y1 = x[i0], x[i1]
    h = 0.5 * dt
    n = x.shape[0]
    xt = ks[4]  # the trial state, then the four stages' derivatives
    k1 = ks[0]
    k2 = ks[1]
    k3 = ks[2]
    k4 = ks[3]
    e0, e1 = math.exp(-lam0 * dt), math.exp(-lam1 * dt)
    g0, g1 = math.exp(-lam0 * h), math.exp(-lam1 * h)
    q0, _, _ = _phi123(-lam0 * h)
    q1, _, _ = _phi123(-lam1 * h)
    q0 *= h  # dt/2 phi_1(-lam dt/2)
    q1 *= h
    p10, p20, p30 = _phi123(-lam0 * dt)
    p11, p21, p31 = _phi123(-lam1 * dt)
    k1[i0] += lam0 * y0  # N1
    k1[i1] += lam1 * y1
    for i in range(n):
        xt[i] = x[i] + h * k1[i]
    xt[i0] = g0 * y0 + q0 * k1[i0]  # Y2
    xt[i1] = g1 * y1 + q1 * k1[i1]
    c0, c1 = xt[i0], xt[i1]
    rhs(xt, T0, T1, u[U_MID], u[U_MID + 1], P, k2, aux)
    k2[i0] += lam0 * c0  # N2
    k2[i1] += lam1 * c1
    for i in range(n):
        xt[i] = x[i] + h * k2[i]
    xt[i0] = g0 * y0 + q0 * k2[i0]  # Y3
    xt[i1] = g1 * y1 + q1 * k2[i1]
    rhs(xt, T0, T1, u[U_MID], u[U_MID + 1], P, k3, aux)
    k3[i0] += lam0 * xt[i0]  # N3
    k3[i1] += lam1 * xt[i1]
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    xt[i0] = g0 * c0 + q0 * (2.0 * k3[i0] - k1[i0])  # Y4
    xt[i1] = g1 * c1 + q1 * (2.0 * k3[i1] - k1[i1])
    rhs(xt, T0, T1, u[U_END], u[U_END + 1], P, k4, aux)
    k4[i0] += lam0 * xt[i0]  # N4
    k4[i1] += lam1 * xt[i1]
    h6 = dt / 6.0
    for i in range(n):
        x[i] += h6 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    x[i0] = e0 * y0 + dt * ((p10 - 3.0 * p20 + 4.0 * p30) * k1[i0] + 2.0 * (p20 - 2.0 * p30) * (k2[i0] + k3[i0])
                            + (4.0 * p30 - p20) * k4[i0])
    x[i1] = e1 * y1 + dt * ((p11 - 3.0 * p21 + 4.0 * p31) * k1[i1] + 2.0 * (p21 - 2.0 * p31) * (k2[i1] + k3[i1])
                            + (4.0 * p31 - p21) * k4[i1])


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def step(x, bs, u, dt, P, fid, fp, ks, kc, aux, k1_ready, psi):
    """One step (module docstring): RK4 on (q, v, actuators) with the bearing torque T held at
    its step-start value, the BDF2 bearing update, the trapezoidal torque kick. One compiled
    kernel, called by every run's loop (:func:`_steps`, :func:`_dwell_steps`).

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
    P : record
        The packed model (:class:`TaosParams` fields, :func:`~taos.taos3d._layout.as_record`).
    fid : tuple of first-class functions
        The friction law's ``bearing_step``, ``zdot3``, ``torque3``
        (:data:`taos.friction.registry.BEARING_SIG`, ``ZDOT3_SIG``, ``TORQUE3_SIG``).
    fp : (NPARAM,) float64
        The law's packed (normal-load scaled) parameters (:mod:`taos.friction._slots`).
    ks : (5, N_BODY + 2 n_a) float64
        Scratch: the RK4 stages k1..k4 and the trial state (rows).
    kc : (2, 2) float64
        The bearing compliance ``P.bearing_compliance`` [rad/(N m)] as a C array (the friction
        law's bearing step takes an array, not a record's field: :func:`_steps` copies it).
    aux : (N_AUX,) float64
        Scratch for :func:`rhs`.
    k1_ready : bool
        ks[0] already holds the derivative at the step start (from the record, same inputs).
    psi : (2,) float64
        The pose-demanded bearing angle :func:`pose_psi` at the step start [rad]; receives
        its value at the step end (the torque kick moves no pose: the next step's start).

    Returns True while the state stays finite."""
    n = x.shape[0]
    k1 = ks[0]
    T0, T1 = bs[BS_T], bs[BS_T + 1]
    qa0, qa1 = psi[0], psi[1]  # the pose-demanded bearing angle at the step start
    if not k1_ready:
        rhs(x, T0, T1, u[U_START], u[U_START + 1], P, k1, aux)
    # the load pressures' stiff supply-pressure-limit rates, integrated exactly near stall
    # (:func:`_etd_rk4`); none (plain RK4, below) elsewhere
    lam0, lam1 = pressure_guard(x, dt, P)
    if lam0 > 0.0 or lam1 > 0.0:
        _etd_rk4(x, T0, T1, u, dt, P, ks, aux, lam0, lam1)
    else:
        _rk4(x, T0, T1, u, dt, P, ks, aux)
    qn = math.sqrt(x[X_Q] * x[X_Q] + x[X_Q + 1] * x[X_Q + 1] + x[X_Q + 2] * x[X_Q + 2] + x[X_Q + 3] * x[X_Q + 3])
    for i in range(X_Q, X_Q + 4):
        x[i] /= qn
    r0, r1, r2, th = _logq4(x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3])
    ps0, ps1 = _psi(x, r0, r1, r2, P)
    psi[0] = ps0
    psi[1] = ps1
    # the bearing by variable-step BDF2 under its own error control (taos.taos3d._bearing),
    # psi linear over the step; the engine gets the mean torque over the step
    m0, m1, _ = _bg.advance(bs, fid, fp, kc, dt, qa0, qa1, ps0, ps1, _bg.tolerance(dt), _bg.MAX_SPLIT, _bg.FAST_STEPS)
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
    P : record
        The packed model (:func:`taos.taos3d.simulate.pack`; :class:`TaosParams` fields).
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
                  np.empty((4, 2)), np.empty((2, 2)))


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _compliance(P, kc):
    """kc (2, 2) = the bearing compliance ``P.bearing_compliance`` [rad/(N m)], as a C array
    (the friction law's bearing step takes an array)."""
    Kc = P.bearing_compliance
    for i in range(2):
        for j in range(2):
            kc[i, j] = Kc[i, j]


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _steps(P, fid, fp, avp, x, bs, r, dt, rec_every, out, ks, aux, cs, kc):
    """:func:`integrate`'s loop (arguments as there; ``ks`` (5, n), ``aux`` (N_AUX,), ``cs``
    (4, 2), ``kc`` (2, 2) scratch), compiled without reference counting; each step a call of
    :func:`step`."""
    k1 = ks[0]
    _compliance(P, kc)
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
        if not step(x, bs, u, dt, P, fid, fp, ks, kc, aux, ready, psi):
            return k + 1
    return -1


@njit(cache=True, fastmath=_FM, error_model="numpy", _nrt=False)
def _dwell_steps(P, fid, fp, avp, x, bs, amp, freq, fmeas, dt, nset, nmeas, out, ks, aux, rec, cs, kc):
    """Two sines (pitch amp[0] sin(2 pi freq[0] t), yaw amp[1] sin(2 pi freq[1] t)) from the
    state ``x`` and bearing state ``bs`` (both advanced in place); Fourier coefficients at
    ``fmeas`` of (xp_pitch, xp_yaw, theta_pitch, theta_yaw) (:data:`_DWELL_COLS`) over ``nmeas``
    steps after ``nset``: out[o] = (2/N sum y sin, 2/N sum y cos, 1/N sum y) [m or rad].
    Compiled without reference counting; each step a call of :func:`step` (as :func:`_steps`).

    Parameters
    ----------
    P, fid, fp, avp
        As :func:`integrate`.
    x : (N_BODY + 2 n_a,) float64
        The start state (``X_*``; the rest state for a dwell).
    bs : (N_BEARING,) float64
        The start bearing state (``BS_*``; zeros at rest).
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
    ks, aux, rec, cs, kc
        Scratch: (5, n), (N_AUX,), (len(REC),), (4, 2), (2, 2).

    Returns -1, or the first step whose state became non-finite."""
    k1 = ks[0]
    _compliance(P, kc)
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
        if not step(x, bs, u, dt, P, fid, fp, ks, kc, aux, k >= nset, psi):
            return k + 1
    for o in range(4):
        out[o, 0] *= 2.0 / nmeas
        out[o, 1] *= 2.0 / nmeas
        out[o, 2] *= 1.0 / nmeas
    return -1


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy")
def dwell_batch(P, fid, fp, avp, x0, amps, freqs, fmeas, dts, nset, nmeas, out, status, b0, b1):
    """Independent two-axis dwells b0 <= b < b1, one after the other without the GIL (the caller
    runs slices on threads: :func:`taos.planar._parallel.run_each`): :func:`_dwell_steps` from
    the rest state ``x0`` (not modified) for row b of ``amps`` (n, 2) [rad] and ``freqs`` (n, 2)
    [Hz], with ``fmeas`` (n,) [Hz], ``dts`` (n,) [s], ``nset``, ``nmeas`` (n,) int, into
    ``out[b]`` (n, 4, 3) and ``status[b]`` (n,) int (-1 or the failing step); ``P``, ``fid``,
    ``fp``, ``avp`` as :func:`integrate`."""
    n = x0.shape[0]
    x = np.empty(n)
    bs = np.empty(N_BEARING)
    ks = np.empty((5, n))
    aux = np.empty(N_AUX)
    rec = np.empty(len(REC))
    cs = np.empty((4, 2))
    kc = np.empty((2, 2))
    for b in range(b0, b1):
        for i in range(n):
            x[i] = x0[i]
        for i in range(N_BEARING):
            bs[i] = 0.0
        status[b] = _dwell_steps(P, fid, fp, avp, x, bs, amps[b], freqs[b], fmeas[b], dts[b], nset[b], nmeas[b],
                                 out[b], ks, aux, rec, cs, kc)

