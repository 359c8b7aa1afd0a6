"""Hydraulic TVC actuator: mechanical-feedback position servo as a linear state space.

This is the one definition of the actuator dynamics; the simplex model, the 3-D TAOS model
and the MASV layer all build on :func:`actuator_state_space`.

States (SI): ``q_m_s`` valve no-load flow over piston area [m/s] (and ``qdot_m_s2`` for a
second-order valve), ``p_load_Pa`` load pressure [Pa], ``x_p_m`` piston position [m],
``v_p_m_s`` piston velocity [m/s], and ``p_filt_Pa`` the dynamic-pressure-feedback filter
state [Pa] when that feedback is fitted.
Inputs: ``x_c_m`` piston position command [m]; ``f_load_N`` load force on the rod [N]
(positive resisting extension).
Outputs: ``x_p_m``, ``v_p_m_s``, ``p_load_Pa``, ``f_piston_N`` = A P_L.

Equations (Merritt, *Hydraulic Control Systems*, Wiley 1967, ch. 5 and 8)::

    valve input:      u_v = K_v (x_c - x_p) - K_dpf (P_L - p_f)
    pressure filter:  p_f' = (P_L - p_f) / tau_dpf          (only when K_dpf > 0)
    valve (order 2):  q'' = w_v^2 (u_v - q) - 2 zeta_v w_v q'
    valve (order 1):  q'  = w_v (u_v - q)
    continuity:       P_L' = (4 beta / V_t) (A q - (K_c + C_l) P_L - A v_p)
    piston:           v_p' = (A P_L - F_L - B_p v_p) / M_p
"""

from __future__ import annotations

import math

from ..linear import StateSpace, finish, is_symbolic, zeros
from ..model import Actuator


def actuator_state_space(act: Actuator) -> StateSpace:
    """Linear state space of one actuator (see the module docstring for the equations).

    Parameters
    ----------
    act : Actuator
        Parameters in SI (areas m^2, pressures Pa, volumes m^3, masses kg, gains 1/s,
        frequencies Hz, flow-pressure coefficients m^3/(s Pa)). Fields may be CasADi SX
        expressions; the matrices are then SX (for exact derivatives in fits).
    """
    sym = is_symbolic(*(getattr(act, f) for f in act.__dataclass_fields__))
    A = act.piston_area_m2
    wv = 2.0 * math.pi * act.valve_natural_frequency_hz
    zv = act.valve_damping_ratio
    Kv = act.loop_gain_per_s
    ch = 4.0 * act.oil_bulk_modulus_Pa / act.trapped_volume_m3
    kce = act.flow_pressure_coefficient_m3_per_s_Pa + act.leakage_coefficient_m3_per_s_Pa
    M = act.piston_mass_kg
    Bp = act.piston_damping_Ns_per_m
    kd = act.pressure_feedback_gain_m_per_s_Pa
    has_dpf = sym or kd > 0
    states = ("q_m_s",) + (("qdot_m_s2",) if act.valve_order == 2 else ()) + (
        "p_load_Pa", "x_p_m", "v_p_m_s") + (("p_filt_Pa",) if has_dpf else ())
    n = len(states)
    ix = {s: i for i, s in enumerate(states)}
    Am = zeros((n, n), sym)
    Bm = zeros((n, 2), sym)
    q, P, x, v = ix["q_m_s"], ix["p_load_Pa"], ix["x_p_m"], ix["v_p_m_s"]
    # valve input u_v = uv_x . state + K_v x_c
    uv = zeros(n, sym)
    uv[x] = -Kv
    if has_dpf:
        pf = ix["p_filt_Pa"]
        uv[P] -= kd
        uv[pf] += kd
        tau = act.pressure_feedback_time_constant_s
        Am[pf, P] = 1.0 / tau
        Am[pf, pf] = -1.0 / tau
    if act.valve_order == 2:
        qd = ix["qdot_m_s2"]
        Am[q, qd] = 1.0
        Am[qd, :] += wv * wv * uv
        Am[qd, q] -= wv * wv
        Am[qd, qd] -= 2.0 * zv * wv
        Bm[qd, 0] = wv * wv * Kv
    else:
        Am[q, :] += wv * uv
        Am[q, q] -= wv
        Bm[q, 0] = wv * Kv
    Am[P, q] = ch * A
    Am[P, P] = -ch * kce
    Am[P, v] = -ch * A
    Am[x, v] = 1.0
    Am[v, P] = A / M
    Am[v, v] = -Bp / M
    Bm[v, 1] = -1.0 / M
    outputs = ("x_p_m", "v_p_m_s", "p_load_Pa", "f_piston_N")
    C = zeros((4, n), sym)
    C[0, x] = 1.0
    C[1, v] = 1.0
    C[2, P] = 1.0
    C[3, P] = A
    return StateSpace(finish(Am, sym), finish(Bm, sym), finish(C, sym), finish(zeros((4, 2), sym), sym),
                      states, ("x_c_m", "f_load_N"), outputs)
