"""Planar "simplex" TVC model: one actuator, one engine axis, compliant load path, gimbal
friction and command avionics (seed paper sections 2 and 3).

Equations (SI), built from the actuator state space of :mod:`taos.actuator`::

    x_c = R theta_c'                       theta_c' = avionics(theta_c)   [rad]
    F_L = K_L (x_p - R theta)              load path (structure, engine, gimbal, case)
    J_n theta'' = R F_L - K_n theta - T_f  engine about the gimbal
    T_f = friction(theta', z, T_app),  T_app = R F_L - K_n theta

The load resonance w_L = sqrt((K_L R^2 + K_n)/J_n) (paper eq. 1) is the notch of the
command -> piston response. Two views of one model: :func:`simplex_plant` gives the linear
block (exact frequency response, poles), and :mod:`taos.simulate` integrates the same block
with the friction and avionics nonlinearities closed around it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .actuator import actuator_state_space
from .linear import StateSpace, finish, is_symbolic, notch_hz, zeros
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
    (for step-size checks).
    """

    ss: StateSpace
    n_ext: int
    cmd_c: np.ndarray
    cmd_d: np.ndarray
    rate_c: np.ndarray
    applied_c: np.ndarray
    inertia_kgm2: float

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
    sym = is_symbolic(act.A, R, KL, Kn, J)
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
                     inertia_kgm2=model.engine.inertia(axis))


def load_resonance_from_notch(model: TvcModel, axis: str = "pitch",
                              f_lo: float = 0.5, f_hi: float = 30.0) -> float:
    """Frequency [Hz] of the minimum of the linear command -> piston gain (the notch) between
    ``f_lo`` and ``f_hi`` [Hz] (:func:`taos.linear.notch_hz`: dense log grid, bounded search)."""
    ss = simplex_state_space(model, axis)
    return notch_hz(lambda f: np.abs(ss.freqresp(f, "command_rad", "x_p_m")), f_lo, f_hi)
