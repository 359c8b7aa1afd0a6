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
* **Supply-pressure limit (stall force).** A critical-centre valve delivers
  Q = C_d w x_v sqrt((P_s - sgn(x_v) P_L) / rho) (Merritt 1967, ch. 3): no flow into the loaded
  side once P_L reaches P_s, so the piston force cannot exceed the stall force A P_s. Implemented
  as a flow factor that keeps the LINEAR (null-linearised) flow gain below (1 - b) P_s and ramps
  it to zero between (1 - b) P_s and P_s in the direction of the flow::

      continuity:  P_L' = (4 beta / V_t) (A q f - (K_c + C_l) P_L - A v_p),
      f = clip((P_s - sgn(q) P_L) / (b P_s), -1, 1),  b = :data:`PRESSURE_BAND`

  (f < 0: a load pressure driven past P_s by the load flows back to supply, as the square-root
  law does with its sign reversed)

  (a conservative simplification of the square-root law: the linear model is unchanged where
  it is valid, and the static stall force is exactly A P_s).
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
    2     LIM_PS      supply pressure P_s (<= 0: off)                   Pa
    3     LIM_BAND    pressure band b (:data:`PRESSURE_BAND`)           -
    4     LIM_THMAX   gimbal range theta_max (<= 0: off)                rad
    5     LIM_KS      hard-stop stiffness k_s                           N m/rad
    6     LIM_CS      hard-stop damping c_s                             N m s/rad

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

#: fraction of P_s over which the pressure-limit flow factor ramps from 1 to 0 [-]
PRESSURE_BAND = 0.05
#: head slots of the packed limits (module docstring)
LIM_VMAX = 0    # valve no-load piston rate v_max [m/s] (<= 0: off)
LIM_KVR = 1     # K_v R, the command's weight in u_v [m/(s rad)]
LIM_PS = 2      # supply pressure P_s [Pa] (<= 0: off)
LIM_BAND = 3    # pressure band b [-]
LIM_THMAX = 4   # gimbal range theta_max [rad] (<= 0: off)
LIM_KS = 5      # hard-stop stiffness k_s [N m/rad]
LIM_CS = 6      # hard-stop damping c_s [N m s/rad]
N_HEAD = 7
#: the state rows after the head, in packed order; ``ROW_*`` their indices
ROWS = ("uv", "uv_in", "q", "p", "flow_in", "theta", "omega", "stop_in")
ROW_UV, ROW_UV_IN, ROW_Q, ROW_P, ROW_FLOW_IN, ROW_THETA, ROW_OMEGA, ROW_STOP_IN = range(len(ROWS))
N_ROWS = len(ROWS)

_FM = {"reassoc", "contract", "arcp", "nsz"}


def pack_limits(v_max: float, kvr: float, p_s: float, theta_max: float, k_s: float, c_s: float,
                rows: dict[str, np.ndarray]) -> np.ndarray:
    """Pack limit parameters and state rows (see the module docstring) for the kernels.
    All limits off gives an empty array."""
    if not (v_max > 0 or p_s > 0 or theta_max > 0):
        return np.zeros(0)
    m = len(next(iter(rows.values())))
    out = np.zeros(N_HEAD + N_ROWS * m)
    out[LIM_VMAX] = v_max
    out[LIM_KVR] = kvr
    out[LIM_PS] = p_s
    out[LIM_BAND] = PRESSURE_BAND
    out[LIM_THMAX] = theta_max
    out[LIM_KS] = k_s
    out[LIM_CS] = c_s
    for i, k in enumerate(ROWS):
        if k in rows:
            out[row_start(i, m):row_start(i + 1, m)] = rows[k]
    return out


def row_start(row: int, m: int) -> int:
    """Slot of the first element of row ``row`` (``ROW_*``) in limits packed over m states."""
    return N_HEAD + row * m


def n_limit_states(lim) -> int:
    """m, the length of the state the packed limits ``lim`` (non-empty) are over."""
    return (lim.shape[0] - N_HEAD) // N_ROWS


def embed_limits(lim: np.ndarray, n_total: int, offset: int = 0) -> np.ndarray:
    """The same limits over a larger state (the plant's state at ``offset`` of ``n_total``)."""
    if lim.size == 0:
        return lim
    m = n_limit_states(lim)
    out = np.zeros(N_HEAD + N_ROWS * n_total)
    out[:N_HEAD] = lim[:N_HEAD]
    for i in range(N_ROWS):
        b = row_start(i, n_total) + offset
        out[b:b + m] = lim[row_start(i, m):row_start(i + 1, m)]
    return out


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


@njit(cache=True, fastmath=_FM)
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
    m = (lim.shape[0] - N_HEAD) // N_ROWS
    vmax = lim[LIM_VMAX]
    if vmax > 0.0:
        uv = _dot(lim, ROW_UV, m, x, off) + lim[LIM_KVR] * u
        if uv > vmax:
            _axpy(lim, ROW_UV_IN, m, vmax - uv, dx, off)
        elif uv < -vmax:
            _axpy(lim, ROW_UV_IN, m, -vmax - uv, dx, off)
    ps = lim[LIM_PS]
    if ps > 0.0:
        q = _dot(lim, ROW_Q, m, x, off)
        p = _dot(lim, ROW_P, m, x, off)
        sg = 1.0 if q >= 0 else -1.0
        f = (ps - sg * p) / (lim[LIM_BAND] * ps)
        if f < 1.0:
            f = max(f, -1.0)  # beyond P_s the valve flows back to supply (at most |q|)
            _axpy(lim, ROW_FLOW_IN, m, q * (f - 1.0), dx, off)


@njit(cache=True, fastmath=_FM)
def apply(lim, x, u, dx):
    """All limits on a planar plant's whole state (valve, pressure, hard stop): ``lim`` packed
    over the whole state (m = n), ``x`` the state, ``u`` the post-avionics command [rad],
    ``dx`` the derivative corrected in place (as :func:`apply_valve_pressure` with off = 0)."""
    if lim.shape[0] == 0:
        return
    apply_valve_pressure(lim, x, 0, u, dx)
    if lim[LIM_THMAX] > 0.0:
        m = (lim.shape[0] - N_HEAD) // N_ROWS
        t = stop_torque(_dot(lim, ROW_THETA, m, x, 0), _dot(lim, ROW_OMEGA, m, x, 0), lim[LIM_THMAX],
                        lim[LIM_KS], lim[LIM_CS])
        if t != 0.0:
            _axpy(lim, ROW_STOP_IN, m, t, dx, 0)


def limit_rows_for_actuator(act) -> tuple[dict[str, np.ndarray], float]:
    """State rows of the limits over the actuator's own state (:func:`taos.planar.actuator.actuator_state_space`
    order) and the command weight K_v [1/s] of u_v per metre of x_c."""
    from .actuator import actuator_state_space
    ss = actuator_state_space(act)
    n = len(ss.states)
    ix = {s: i for i, s in enumerate(ss.states)}
    z = lambda: np.zeros(n)  # noqa: E731
    uv, uv_in, q, p, flow = z(), z(), z(), z(), z()
    uv[ix["x_p_m"]] = -act.loop_gain_per_s
    kd = act.pressure_feedback_gain_m_per_s_Pa
    if "p_filt_Pa" in ix:
        uv[ix["p_load_Pa"]] -= kd
        uv[ix["p_filt_Pa"]] += kd
    wv = 2.0 * math.pi * act.valve_natural_frequency_hz
    if act.valve_order == 2:
        uv_in[ix["qdot_m_s2"]] = wv * wv
    else:
        uv_in[ix["q_m_s"]] = wv
    q[ix["q_m_s"]] = 1.0
    p[ix["p_load_Pa"]] = 1.0
    flow[ix["p_load_Pa"]] = 4.0 * act.oil_bulk_modulus_Pa * act.piston_area_m2 / act.trapped_volume_m3
    return {"uv": uv, "uv_in": uv_in, "q": q, "p": p, "flow_in": flow}, act.loop_gain_per_s
