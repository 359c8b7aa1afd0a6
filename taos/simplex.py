"""Planar "simplex" TVC model: one actuator, one engine axis, compliant load path, gimbal
friction and command avionics (seed paper sections 2 and 3; DESIGN.md "Physics").

Equations (SI), built from the actuator state space of :mod:`taos.actuator`::

    x_c = R theta_c'                       theta_c' = avionics(theta_c)   [rad]
    F_L = K_L (x_p - R theta)              load path (structure, engine, gimbal, case)
          + c_L (v_p - R theta')           its structural damping (:class:`taos.model.Structure`)
    J_n theta'' = R F_L - K_n theta - T_f  engine about the gimbal
    T_f = friction(theta', z, T_app),  T_app = R F_L - K_n theta

The load resonance w_L = sqrt((K_L R^2 + K_n)/J_n) (paper eq. 1) is the notch of the
command -> piston response. Two views of one model: :func:`simplex_plant` gives the linear
block (exact frequency response, poles), and :mod:`taos.simulate` integrates the same block
with the friction and avionics nonlinearities closed around it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .actuator import actuator_state_space
from .linear import StateSpace, finish, is_symbolic, zeros
from .model import TvcModel

#: Outputs of the simplex linear block, in order.
SIMPLEX_OUTPUTS = ("x_p_m", "theta_rad", "omega_rad_s", "applied_torque_Nm", "load_force_N", "p_load_Pa")


@dataclass(frozen=True, eq=False)
class LurePlant:
    """A linear block closed through two scalar nonlinearities (a Lur'e system).

    ``ss`` has the external inputs first, then ``command_rad`` (the avionics output) and
    ``friction_torque_Nm``. The avionics input is ``cmd_c . x + cmd_d . r`` (``r`` the external
    inputs); the friction element sees the relative rate ``rate_c . x`` [rad/s] and the applied
    torque ``applied_c . x`` [N m]. ``inertia_kgm2`` is the inertia the friction acts on
    (for step-size checks). ``limits`` packs the actuator/gimbal limits over the state
    (:mod:`taos.limits`; empty: none).
    """

    ss: StateSpace
    n_ext: int
    cmd_c: np.ndarray
    cmd_d: np.ndarray
    rate_c: np.ndarray
    applied_c: np.ndarray
    inertia_kgm2: float
    limits: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def ext_inputs(self) -> tuple[str, ...]:
        return self.ss.inputs[: self.n_ext]


def simplex_state_space(model: TvcModel, axis: str = "pitch") -> StateSpace:
    """Linear simplex block for one axis.

    Inputs: ``command_rad`` (engine-angle command after the avionics), ``friction_torque_Nm``.
    Outputs: :data:`SIMPLEX_OUTPUTS`. States: the actuator states, ``theta_rad``, ``omega_rad_s``.
    Parameters may be CasADi SX expressions (fits); the matrices are then SX.
    """
    act = actuator_state_space(model.actuator)
    R = model.actuator.moment_arm_m
    KL = model.structure.load_stiffness_N_per_m
    Kn = model.engine.rotational_stiffness_Nm_per_rad
    J = model.engine.inertia(axis)
    sym = is_symbolic(act.A, R, KL, Kn, J, model.structure.load_damping_ratio)
    if sym:  # work on object arrays holding SX scalars
        import casadi as ca
        obj = lambda M: np.array([[M[i, j] for j in range(M.shape[1])] for i in range(M.shape[0])],  # noqa: E731
                                 dtype=object)
        actA, actB, actC = (obj(ca.SX(M)) for M in (act.A, act.B, act.C))
    else:
        actA, actB, actC = act.A, act.B, act.C
    na = len(act.states)
    n = na + 2
    ith, iom = na, na + 1
    cxp = actC[act.output_index("x_p_m")]
    # load force F_L = K_L (x_p - R theta) as a row over the full state
    fl = zeros(n, sym)
    fl[:na] = [KL * c for c in cxp]   # element-wise: also for CasADi scalars
    fl[ith] = -KL * R
    cL = model.structure.load_damping_Ns_per_m(R, J)  # structural damping on the load path
    if not (isinstance(cL, float) and cL == 0.0):
        cvp = actC[act.output_index("v_p_m_s")]
        for i in range(na):
            fl[i] = fl[i] + cL * cvp[i]
        fl[iom] = -cL * R
    A = zeros((n, n), sym)
    A[:na, :na] = actA
    bf = actB[:, act.input_index("f_load_N")]
    A[:na, :] += np.array([[b * f for f in fl] for b in bf], dtype=A.dtype)
    A[ith, iom] = 1.0
    applied = np.array([R * f for f in fl], dtype=fl.dtype)
    applied[ith] -= Kn
    A[iom, :] = [a / J for a in applied]
    B = zeros((n, 2), sym)
    B[:na, 0] = [b * R for b in actB[:, act.input_index("x_c_m")]]
    B[iom, 1] = -1.0 / J
    C = zeros((len(SIMPLEX_OUTPUTS), n), sym)
    C[0, :na] = cxp
    C[1, ith] = 1.0
    C[2, iom] = 1.0
    C[3] = applied
    C[4] = fl
    C[5, :na] = actC[act.output_index("p_load_Pa")]
    states = tuple(act.states) + ("theta_rad", "omega_rad_s")
    return StateSpace(finish(A, sym), finish(B, sym), finish(C, sym), finish(zeros((C.shape[0], 2), sym), sym),
                      states, ("command_rad", "friction_torque_Nm"), SIMPLEX_OUTPUTS)


def simplex_plant(model: TvcModel, axis: str = "pitch") -> LurePlant:
    """The simplex block as a Lur'e plant for the integrator: the external input is the FCS
    engine-angle command ``theta_cmd_rad``, which passes through the avionics."""
    ss = simplex_state_space(model, axis)
    n = ss.A.shape[0]
    A = ss.A
    B = np.column_stack([np.zeros(n), ss.B])
    full = StateSpace(A, B, ss.C, np.zeros((ss.C.shape[0], 3)), ss.states,
                      ("theta_cmd_rad",) + ss.inputs, ss.outputs)
    return LurePlant(ss=full, n_ext=1, cmd_c=np.zeros(n), cmd_d=np.ones(1),
                     rate_c=ss.C[ss.output_index("omega_rad_s")].copy(),
                     applied_c=ss.C[ss.output_index("applied_torque_Nm")].copy(),
                     inertia_kgm2=model.engine.inertia(axis), limits=simplex_limits(model, axis))


def simplex_limits(model: TvcModel, axis: str = "pitch") -> np.ndarray:
    """The model's actuator and gimbal limits packed over the simplex state (:mod:`taos.limits`):
    valve flow saturation, supply-pressure limit, hard stops at the gimbal range."""
    from .limits import limit_rows_for_actuator, pack_limits
    act, eng = model.actuator, model.engine
    rows, kv = limit_rows_for_actuator(act)
    ss = simplex_state_space(model, axis)
    n = len(ss.states)
    full = {k: np.concatenate([v, np.zeros(n - v.size)]) for k, v in rows.items()}
    full["theta"] = np.zeros(n)
    full["theta"][ss.state_index("theta_rad")] = 1.0
    full["omega"] = np.zeros(n)
    full["omega"][ss.state_index("omega_rad_s")] = 1.0
    full["stop_in"] = full["omega"] / eng.inertia(axis)
    return pack_limits(act.max_rate_m_per_s, kv * act.moment_arm_m,
                       act.supply_pressure_Pa if act.pressure_limited else 0.0,
                       eng.gimbal_range_rad, eng.hard_stop_stiffness_Nm_per_rad,
                       eng.hard_stop_damping_Nms_per_rad(axis), full)


def load_resonance_from_notch(model: TvcModel, axis: str = "pitch",
                              f_lo: float = 0.5, f_hi: float = 30.0) -> float:
    """Frequency [Hz] of the minimum of the linear command -> piston gain (the notch),
    located by a dense log grid and refined with a bounded scalar search."""
    import scipy.optimize

    ss = simplex_state_space(model, axis)
    R = model.actuator.moment_arm_m

    def g(logf):
        h = ss.freqresp(10 ** logf, "command_rad", "x_p_m")[0] / R
        return abs(h)

    grid = np.linspace(np.log10(f_lo), np.log10(f_hi), 400)
    vals = np.abs(ss.freqresp(10 ** grid, "command_rad", "x_p_m")) / R
    k = int(np.argmin(vals))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    res = scipy.optimize.minimize_scalar(g, bounds=(lo, hi), method="bounded",
                                         options={"xatol": 1e-9})
    return float(10 ** res.x)
