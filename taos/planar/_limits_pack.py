"""The packed actuator and gimbal limits' layout and packing (numba-free: model loading, the
planners and the compiled-C dwell path use it without importing the kernels). The laws, the
layout's meaning and units are described in :mod:`taos.planar.saturation`, which re-exports
every name here and holds the kernels."""

from __future__ import annotations

import math

import numpy as np

#: regularisation of the square-root law: the pressure margin d = (P_s - sgn(q) P_L) / P_s
#: below which g(d) turns from sqrt(d) to linear [-] (module docstring; g'(0) = 1 / sqrt(eps))
SQRT_LAW_EPS = 0.05
#: head slots of the packed limits (module docstring)
LIM_VMAX = 0    # valve no-load piston rate v_max [m/s] (<= 0: off)
LIM_KVR = 1     # K_v R, the command's weight in u_v [m/(s rad)]
LIM_PS = 2      # supply pressure P_s [Pa] (<= 0: pressure limit and relief off)
LIM_EPS = 3     # square-root law regularisation eps [-]
LIM_PR = 4      # relief cracking pressure P_r [Pa] (inf: no relief)
LIM_KRA = 5     # relief flow coefficient over piston area K_r / A [m/(s Pa)]
LIM_THMAX = 6   # gimbal range theta_max [rad] (<= 0: off)
LIM_KS = 7      # hard-stop stiffness k_s [N m/rad]
LIM_CS = 8      # hard-stop damping c_s [N m s/rad]
N_HEAD = 9
#: the state rows after the head, in packed order; ``ROW_*`` their indices
ROWS = ("uv", "uv_in", "q", "p", "flow_in", "theta", "omega", "stop_in")
ROW_UV, ROW_UV_IN, ROW_Q, ROW_P, ROW_FLOW_IN, ROW_THETA, ROW_OMEGA, ROW_STOP_IN = range(len(ROWS))
N_ROWS = len(ROWS)



def pack_limits(v_max: float, kvr: float, p_s: float, theta_max: float, k_s: float, c_s: float,
                rows: dict[str, np.ndarray], p_relief: float = math.inf, k_relief_per_area: float = 0.0
                ) -> np.ndarray:
    """Pack limit parameters and state rows (see the module docstring) for the kernels:
    ``v_max`` [m/s], ``kvr`` K_v R [m/(s rad)], ``p_s`` [Pa] (0: no pressure limit),
    ``theta_max`` [rad], ``k_s`` [N m/rad], ``c_s`` [N m s/rad], ``p_relief`` P_r [Pa] (inf: no
    relief), ``k_relief_per_area`` K_r / A [m/(s Pa)]. All limits off gives an empty array."""
    if not (v_max > 0 or p_s > 0 or theta_max > 0):
        return np.zeros(0)
    m = len(next(iter(rows.values())))
    out = np.zeros(N_HEAD + N_ROWS * m)
    out[LIM_VMAX] = v_max
    out[LIM_KVR] = kvr
    out[LIM_PS] = p_s
    out[LIM_EPS] = SQRT_LAW_EPS
    out[LIM_PR] = p_relief if p_s > 0 else math.inf
    out[LIM_KRA] = k_relief_per_area if p_s > 0 else 0.0
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


def pack_model_limits(act, eng, axis: str, rows: dict[str, np.ndarray]) -> np.ndarray:
    """The limits of actuator ``act`` (:class:`taos.model.Actuator`) and engine ``eng``
    (:class:`taos.model.Engine`, hard stops with the damping of ``axis``) packed over the state
    rows ``rows`` (:func:`pack_limits`): the one place the model's limit parameters go into the
    pack (planar and 3-D alike)."""
    plim = act.pressure_limited
    return pack_limits(act.max_rate_m_per_s, act.loop_gain_per_s * act.moment_arm_m,
                       act.supply_pressure_Pa if plim else 0.0, eng.gimbal_range_rad,
                       eng.hard_stop_stiffness_Nm_per_rad, eng.hard_stop_damping_Nms_per_rad(axis), rows,
                       p_relief=act.relief_pressure_Pa if (plim and act.relief_pressure_Pa > 0) else math.inf,
                       k_relief_per_area=(act.relief_flow_coefficient_m3_per_s_Pa / act.piston_area_m2
                                          if plim else 0.0))


def pressure_limit_rate_per_s(act) -> float:
    """The fastest rate [1/s] the pressure limit adds to the continuity equation (0 when off):
    (4 beta / V_t) (A v_max g'(0) / P_s + K_r), the slope of the regularised square-root law
    at stall with the valve wide open (q = v_max) plus the relief's; an explicit RK4 step must
    keep dt times it within the stability bound, as for the linear modes."""
    if not act.pressure_limited:
        return 0.0
    ch = 4.0 * act.oil_bulk_modulus_Pa / act.trapped_volume_m3
    gp0 = 1.0 / math.sqrt(SQRT_LAW_EPS)
    valve = act.piston_area_m2 * act.max_rate_m_per_s * gp0 / act.supply_pressure_Pa
    return ch * (valve + act.relief_flow_coefficient_m3_per_s_Pa)


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
