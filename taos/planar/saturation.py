"""Actuator and gimbal limits: valve flow saturation, supply-pressure (stall) limit, hard stops.

Three hard nonlinearities every real TVC servo has, added to the linear actuator model of
:mod:`taos.planar.actuator` as corrections to its state derivative (so that, away from the limits,
the model is exactly the linear one the fits and the frequency responses use):

* **Valve flow saturation (rate limit).** The spool stroke bounds the servovalve's no-load
  flow, so the valve command u_v = K_v (x_c - x_p) - K_dpf (P_L - p_f) [m/s] (flow over piston
  area) is clipped to +-v_max before the valve dynamics::

      valve (order 2):  q'' = w_v^2 (sat(u_v, v_max) - q) - 2 zeta_v w_v q'
      valve (order 1):  q'  = w_v (sat(u_v, v_max) - q)

  v_max is the no-load piston rate [m/s]; the engine slews at most v_max / R [rad/s]
  (Merritt, *Hydraulic Control Systems*, 1967, sec. 5.2: flow limited by the valve opening).
* **Supply-pressure limit (stall force): the square-root law of a critical-centre valve.** The
  valve's flow through its orifices is Q = C_d w x_v sqrt((P_s - sgn(x_v) P_L) / rho) (Merritt,
  *Hydraulic Control Systems*, 1967, eq. 3-92 to 3-95, return pressure 0): no flow into the
  loaded side once P_L reaches P_s, so the piston force cannot exceed the stall force A P_s.
  Written with the linear model's state q = K_q x_v / A (the valve's NO-LOAD flow over the
  piston area, :mod:`taos.planar.actuator`) it is Q = A q g(d), d = (P_s - sgn(q) P_L) / P_s,
  g(d) = sqrt(d): the linear model's flow gain K_q is the no-load (P_L = 0) gain, which is
  what a flow-gain figure of a servovalve means (rated at no load). The continuity equation
  becomes::

      P_L' = (4 beta / V_t) (A q g(d) - (K_c + C_l) P_L - A v_p - Q_r(P_L)),
      g(d) = sgn(d) sqrt(|d|)  for |d| >= eps,   g(d) = d / sqrt(eps)  for |d| < eps,
      eps = :data:`SQRT_LAW_EPS`

  g is the square-root law, exact outside a pressure margin of eps P_s from stall and linear
  inside it (continuous, slope 1 / sqrt(eps) instead of an infinite one at d = 0, so the
  explicit RK4 step stays stable at stall: :func:`pressure_limit_rate_per_s`); for d < 0 (a
  load driving P_L past P_s) the valve flows back to supply, as the square-root law does with
  its sign reversed.
  **Why the linear model, the fits and the linear frequency responses are unchanged:** at the
  null (q = 0, P_L = 0) the flow A q g(d) has d(.)/dq = A g(1) = A and d(.)/dP_L = A q g'(1)
  / P_s = 0, so the null linearisation is exactly the linear model A q - K_c P_L (the ideal
  critical-centre valve's own pressure coefficient is zero at null; K_c stays the fitted
  one). In the time domain the law departs from the linear model by the factor g(d) - 1,
  -sgn(q) P_L / (2 P_s) to first order: the valve's real load sensitivity (a flow gain 13 %
  lower at P_L = P_s / 4 in the loaded quadrant, higher in the overrunning one).
  The static load-flow curve follows: a piston moving against a constant load force F with
  the valve open at its no-load rate v_nl moves at v = v_nl sqrt(1 - F / (A P_s)).
* **Cross-port relief valve.** A relief valve between the two actuator chambers cracks at
  P_r (the model file's ``relief_pressure``, a documented fraction at or above P_s) and passes
  Q_r = K_r (|P_L| - P_r) sgn(P_L) for |P_L| > P_r (0 below; K_r the file's
  ``relief_flow_coefficient`` [m^3/(s Pa)]), so |P_L| exceeds P_r by at most Q / K_r for a
  flow Q forced into the chamber: the steady relief curve is P_L = P_r + Q / K_r. The pressure
  limit off (``pressure_limited = false``) turns off the square-root law and the relief
  together (an ideal valve on an unlimited supply: the linear model, bit for bit).
* **Hard stops** at the gimbal range +-theta_max: a stiff, damped, one-sided contact torque on
  the engine (Hunt-Crossley style, never pulling)::

      T_stop = -sgn(theta) max(0, k_s (|theta| - theta_max) + c_s sgn(theta) theta')
               for |theta| > theta_max, else 0;  c_s = 2 zeta_s sqrt(k_s J)

  so a command beyond the range holds the engine at theta_max plus the contact's elastic
  deflection (the stall torque A P_s R over k_s at most).

Packed layout (one float64 array, read by the compiled kernels; length 0 = no limits). The
head slots are the ``LIM_*`` constants below, which the packer (:func:`pack_limits`) and the
kernels both index by::

    slot  name        quantity                                          unit
    0     LIM_VMAX    valve no-load piston rate v_max (<= 0: off)       m/s
    1     LIM_KVR     K_v R, the command's weight in u_v                m/(s rad)
    2     LIM_PS      supply pressure P_s (<= 0: pressure limit off)    Pa
    3     LIM_EPS     square-root law regularisation eps                -
                      (:data:`SQRT_LAW_EPS`)
    4     LIM_PR      relief cracking pressure P_r (inf: no relief)     Pa
    5     LIM_KRA     relief flow coefficient over piston area K_r / A  m/(s Pa)
    6     LIM_THMAX   gimbal range theta_max (<= 0: off)                rad
    7     LIM_KS      hard-stop stiffness k_s                           N m/rad
    8     LIM_CS      hard-stop damping c_s                             N m s/rad

then, from slot :data:`N_HEAD`, the :data:`ROWS` (index ``ROW_*``), each of length m over the
state the kernel sees: ``uv`` u_v row, ``uv_in`` u_v input column, ``q`` valve-flow row, ``p``
P_L row, ``flow_in`` continuity flow column (4 beta A / V_t), ``theta`` engine-angle row,
``omega`` engine-rate row, ``stop_in`` stop-torque column (1 / J on omega). Row ``i`` occupies
``N_HEAD + i m .. N_HEAD + (i + 1) m`` (:func:`row_start`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._limits_pack import (  # noqa: F401  (the packing and its layout, re-exported)
    SQRT_LAW_EPS, LIM_VMAX, LIM_KVR, LIM_PS, LIM_EPS, LIM_PR, LIM_KRA, LIM_THMAX, LIM_KS, LIM_CS,
    N_HEAD, ROWS, ROW_UV, ROW_UV_IN, ROW_Q, ROW_P, ROW_FLOW_IN, ROW_THETA, ROW_OMEGA, ROW_STOP_IN,
    N_ROWS, pack_limits, row_start, n_limit_states, embed_limits, pack_model_limits, pressure_limit_rate_per_s,
    limit_rows_for_actuator)

_FM = {"reassoc", "contract", "arcp", "nsz"}


@njit(cache=True, fastmath=_FM, inline="always")
def _dot(lim, row, m, x, off):
    """Row ``row`` (``ROW_*``) of ``lim`` (m states) times ``x[off:off+m]``."""
    s = 0.0
    b = N_HEAD + row * m
    for i in range(m):
        s += lim[b + i] * x[off + i]
    return s


@njit(cache=True, fastmath=_FM, inline="always")
def _axpy(lim, row, m, a, dx, off):
    """dx[off:off+m] += a times row ``row`` (``ROW_*``) of ``lim`` (m states)."""
    b = N_HEAD + row * m
    for i in range(m):
        dx[off + i] += a * lim[b + i]


@njit(cache=True, fastmath=_FM, inline="always")
def stop_torque(th, om, th_max, k_s, c_s):
    """Hard-stop contact torque [N m] at angle ``th`` [rad] and rate ``om`` [rad/s]; gimbal
    range ``th_max`` [rad] (<= 0: no stops), contact stiffness ``k_s`` [N m/rad] and damping
    ``c_s`` [N m s/rad]."""
    pen = abs(th) - th_max
    if th_max <= 0.0 or pen <= 0.0:
        return 0.0
    sg = 1.0 if th > 0 else -1.0
    return -sg * max(0.0, k_s * pen + c_s * sg * om)


@njit(cache=True, fastmath=_FM, inline="always")
def apply_valve_pressure(lim, x, off, u, dx):
    """Add the rate-limit and pressure-limit corrections to ``dx[off:off+m]`` for the state
    ``x[off:off+m]`` and post-avionics command ``u`` [rad]; no-op for an empty ``lim``.

    Parameters
    ----------
    lim : (N_HEAD + N_ROWS m,) float64
        Packed limits (module docstring, slots ``LIM_*``, rows ``ROW_*``) over m states.
    x : (n,) float64
        State (SI, the actuator's state order from ``off``).
    off : int
        Index of the actuator's first state in ``x`` and ``dx``.
    u : float
        Post-avionics command [rad].
    dx : (n,) float64
        State derivative, corrected in place (SI per second).
    """
    if lim.shape[0] == 0:
        return
    valve_pressure_rows(lim, x, off, u, dx, (lim.shape[0] - N_HEAD) // N_ROWS)


@njit(cache=True, fastmath=_FM, inline="always")
def valve_pressure_rows(lim, x, off, u, dx, m):
    """:func:`apply_valve_pressure` for a non-empty ``lim`` packed over ``m`` states (inlined:
    a caller that knows ``m`` at compile time, as the 3-D kernel, gets fixed-size loops)."""
    if lim[LIM_VMAX] > 0.0:
        a = valve_excess(lim, _dot(lim, ROW_UV, m, x, off) + lim[LIM_KVR] * u)
        if a != 0.0:
            _axpy(lim, ROW_UV_IN, m, a, dx, off)
    if lim[LIM_PS] > 0.0:
        _axpy(lim, ROW_FLOW_IN, m, pressure_flow_correction(lim, _dot(lim, ROW_Q, m, x, off),
                                                            _dot(lim, ROW_P, m, x, off)), dx, off)


@njit(cache=True, fastmath=_FM, inline="always")
def valve_excess(lim, uv):
    """The valve-command correction along the ``uv_in`` column for the valve command ``uv``
    [m/s]: sat(u_v, v_max) - u_v (0 inside the rate limit or with it off); ``lim`` the packed
    head (slots ``LIM_*``)."""
    vmax = lim[LIM_VMAX]
    if vmax > 0.0:
        if uv > vmax:
            return vmax - uv
        if uv < -vmax:
            return -vmax - uv
    return 0.0


@njit(cache=True, fastmath=_FM, inline="always")
def pressure_flow_correction(lim, q, p):
    """The continuity-equation flow correction along the ``flow_in`` column [m/s]: the
    square-root law's departure from the linear valve, q (g(d) - 1), minus the relief flow over
    piston area (module docstring), for the valve flow state ``q`` [m/s] and load pressure ``p``
    [Pa]; 0 with the pressure limit off. ``lim`` the packed head (slots ``LIM_*``)."""
    ps = lim[LIM_PS]
    if ps <= 0.0:
        return 0.0
    sg = 1.0 if q >= 0 else -1.0
    d = (ps - sg * p) / ps  # pressure margin across the metering orifices [-]
    eps = lim[LIM_EPS]
    if d >= eps:  # square-root law (d < 0: back to supply), linear within eps of stall
        g = math.sqrt(d)
    elif d <= -eps:
        g = -math.sqrt(-d)
    else:
        g = d / math.sqrt(eps)
    corr = q * (g - 1.0)
    over = abs(p) - lim[LIM_PR]
    if over > 0.0:  # cross-port relief: Q_r / A = (K_r / A) (|P_L| - P_r) sgn(P_L)
        corr -= lim[LIM_KRA] * over * (1.0 if p > 0 else -1.0)
    return corr


@njit(cache=True, fastmath=_FM)
def apply(lim, x, u, dx):
    """All limits on a planar plant's whole state (valve, pressure, hard stop): ``lim`` packed
    over the whole state (m = n), ``x`` the state, ``u`` the post-avionics command [rad],
    ``dx`` the derivative corrected in place (as :func:`apply_valve_pressure` with off = 0).

    :data:`apply_inlined` is the same function inlined where it is called (the RK4 rates of
    :mod:`taos.planar.dynamics`, four calls a step)."""
    if lim.shape[0] == 0:
        return
    # int(0): a run-time zero, not the literal 0 (a literal argument of a jitted call compiles a
    # specialisation of its own: numba types a constant argument as Literal[int](0))
    apply_valve_pressure(lim, x, int(0), u, dx)
    if lim[LIM_THMAX] > 0.0:
        m = (lim.shape[0] - N_HEAD) // N_ROWS
        t = stop_torque(_dot(lim, ROW_THETA, m, x, 0), _dot(lim, ROW_OMEGA, m, x, 0), lim[LIM_THMAX],
                        lim[LIM_KS], lim[LIM_CS])
        if t != 0.0:
            _axpy(lim, ROW_STOP_IN, m, t, dx, 0)


#: :func:`apply` inlined (numba ``inline="always"``) into the planar RK4 step's rates, called four
#: times a step: called out of line, each of its array arguments costs numba an atomic
#: reference-count increment and decrement a call (benchmarks/RESULTS.md "nrt"). The same Python
#: function (its ``py_func``), so the same arithmetic, bit for bit; the exponential kernels, which
#: call it once a step, keep the out-of-line :func:`apply`.
apply_inlined = njit(fastmath=_FM, inline="always")(apply.py_func)

# -- the same laws across lanes (many plants in lockstep: taos.planar.dynamics._rates_lanes) ----
# Each is the scalar law above written as one element-wise loop over the lanes, the branches as
# selects (both sides computed, one kept), so that LLVM vectorises it; compiled without fast-math
# it gives each lane the scalar function's bits. ``H`` (N_HEAD, R): the lanes' packed heads by
# slot (``H[LIM_*, q]`` the head of lane q).
@njit(cache=True, inline="always")
def valve_excess_lanes(H, UV, out):
    """:func:`valve_excess` per lane: ``UV`` (R,) valve commands [m/s] -> ``out`` (R,) [m/s]."""
    for q in range(UV.shape[0]):
        vmax = H[LIM_VMAX, q]
        uv = UV[q]
        e = (vmax - uv) if uv > vmax else ((-vmax - uv) if uv < -vmax else 0.0)
        out[q] = e if vmax > 0.0 else 0.0


@njit(cache=True, inline="always")
def pressure_flow_correction_lanes(H, Q, P, out):
    """:func:`pressure_flow_correction` per lane: ``Q`` (R,) valve flow states [m/s], ``P`` (R,)
    load pressures [Pa] -> ``out`` (R,) [m/s]."""
    for q in range(Q.shape[0]):
        ps = H[LIM_PS, q]
        qv = Q[q]
        p = P[q]
        sg = 1.0 if qv >= 0 else -1.0
        d = (ps - sg * p) / ps
        eps = H[LIM_EPS, q]
        s = math.sqrt(abs(d))  # sqrt(d) for d >= eps, -sqrt(-d) for d <= -eps
        g = s if d >= eps else (-s if d <= -eps else d / math.sqrt(eps))
        corr = qv * (g - 1.0)
        over = abs(p) - H[LIM_PR, q]
        rel = H[LIM_KRA, q] * over * (1.0 if p > 0 else -1.0)
        corr = (corr - rel) if over > 0.0 else corr
        out[q] = corr if ps > 0.0 else 0.0


@njit(cache=True, inline="always")
def stop_torque_lanes(H, TH, OM, out):
    """:func:`stop_torque` per lane: ``TH`` (R,) engine angles [rad], ``OM`` (R,) rates [rad/s]
    -> ``out`` (R,) [N m], with each lane's ``LIM_THMAX``, ``LIM_KS``, ``LIM_CS``."""
    for q in range(TH.shape[0]):
        th = TH[q]
        th_max = H[LIM_THMAX, q]
        pen = abs(th) - th_max
        sg = 1.0 if th > 0 else -1.0
        t = -sg * max(0.0, H[LIM_KS, q] * pen + H[LIM_CS, q] * sg * OM[q])
        out[q] = 0.0 if (th_max <= 0.0 or pen <= 0.0) else t
