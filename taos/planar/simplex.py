"""Planar "simplex" TVC model: one actuator, one engine axis, compliant load path, gimbal
friction and command avionics (seed paper sections 2 and 3).

Equations (SI), built from the actuator state space of :mod:`taos.planar.actuator`::

    x_c = R theta_c'                       theta_c' = avionics(theta_c)   [rad]
    F_L = K_L (x_p - R theta)              load path (structure, engine, gimbal, case)
          + c_L (v_p - R theta')           its structural damping (:class:`taos.model.Structure`)
    J_n theta'' = R F_L - K_n theta - T_f  engine about the gimbal
    T_f = friction(theta', z, T_app),  T_app = R F_L - K_n theta

The load resonance w_L = sqrt((K_L R^2 + K_n)/J_n) (paper eq. 1) is the notch of the
command -> piston response. Two views of one model: :func:`simplex_plant` gives the linear
block (exact frequency response, poles), and :mod:`taos.planar.simulate` integrates the same block
with the friction and avionics nonlinearities closed around it.

On an elastic structure (MASV, paper sec. 1 and 3.3) the same block takes the structure's
motion as inputs and returns the reactions on the structure (``structure_inputs=True``)::

    F_L = K_L (x_p - R theta - e)          e  structure elongation along the line of action
                                              (gimbal point minus actuator attach point) [m]
    J_n theta'' = R F_L - K_n (theta - r) - T_f - m_e l_e a_g
                                           r  structure rotation at the gimbal [rad]
                                           a_g gimbal-point acceleration along d = unit(a x c) [m/s^2]
    reactions on the structure: F_L (pushing the gimbal along the line of action and the
    attach point against it), K_n (theta - r) (a torque about a at the gimbal),
    f_twd = -m_e l_e theta'' (a force at the gimbal along d)

theta is the engine's inertial angle, m_e its mass and l_e the distance of its centre of mass
from the gimbal (perpendicular to the rotation axis a). The engine's kinetic energy
1/2 m_e (u_d' + l_e theta')^2 + 1/2 I_c theta'^2 (J_n = I_c + m_e l_e^2) gives both inertial
couplings: "dog wags tail" (the gimbal's acceleration turns the engine, - m_e l_e a_g) and
"tail wags dog" (the engine's angular acceleration loads the structure, - m_e l_e theta'').
The rigid-translation part - m_e a_g of the engine's inertia is left to the structure model
(MASV adds it as a mass at the gimbal). With e = r = a_g = 0 the block is the planar one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .actuator import actuator_state_space
from ..linear import StateSpace, finish, is_symbolic, notch_hz, zeros
from ..model import TvcModel
from ..bounds import RESPONSE_FREQ_HZ, check_axis, check_flag, check_instance, check_number

#: Outputs of the simplex linear block, in order.
SIMPLEX_OUTPUTS = ("x_p_m", "theta_rad", "omega_rad_s", "applied_torque_Nm", "load_force_N", "p_load_Pa")
#: Inputs appended with ``structure_inputs=True``: the structure's motion at the engine.
STRUCTURE_INPUTS = ("elongation_m", "gimbal_rotation_rad", "gimbal_accel_m_s2")
#: Outputs appended with ``structure_inputs=True``: reactions on the structure.
STRUCTURE_OUTPUTS = ("spring_torque_Nm", "twd_force_N")


@dataclass(frozen=True, eq=False)
class LurePlant:
    """A linear block closed through two scalar nonlinearities (a Lur'e system).

    ``ss`` has the external inputs first, then ``command_rad`` (the avionics output) and
    ``friction_torque_Nm``. The avionics input is ``cmd_c . x + cmd_d . r`` (``r`` the external
    inputs); the friction element sees the relative rate ``rate_c . x`` [rad/s] and the applied
    torque ``applied_c . x`` [N m]. ``inertia_kgm2`` is the inertia the friction acts on
    (for step-size checks). ``limits`` packs the actuator/gimbal limits over the state
    (:mod:`taos.planar.saturation`; empty: none).
    """

    ss: StateSpace
    n_ext: int
    cmd_c: np.ndarray
    cmd_d: np.ndarray
    rate_c: np.ndarray
    applied_c: np.ndarray
    inertia_kgm2: float
    limits: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self):
        from ._limits_pack import n_limit_states
        n = self.ss.A.shape[0]
        if self.limits.size and n_limit_states(self.limits) != n:
            raise ValueError(f"LurePlant: limits packed over {n_limit_states(self.limits)} states, "
                             f"the plant has {n}")

    @property
    def ext_inputs(self) -> tuple[str, ...]:
        return self.ss.inputs[: self.n_ext]


def extend_plant(base: LurePlant, ss: StateSpace, n_ext: int, cmd_d) -> LurePlant:
    """``base`` grown by states appended after its own: ``ss`` is the new linear block (its first
    states are ``base``'s, in order; external inputs first, then ``command_rad`` and
    ``friction_torque_Nm``), ``n_ext`` its number of external inputs and ``cmd_d`` the avionics
    input's weights on them. The command, rate and applied-torque rows are padded with zeros
    and the actuator/gimbal limits are embedded over the larger state, so a grown plant keeps
    every limit of the one it grew from (the one construction for this)."""
    from ._limits_pack import embed_limits
    n0, n = base.ss.A.shape[0], ss.A.shape[0]
    if n < n0 or ss.states[:n0] != base.ss.states:
        raise ValueError("extend_plant: the new block's first states must be the base plant's")
    pad = lambda v: np.concatenate([v, np.zeros(n - n0)])  # noqa: E731
    return LurePlant(ss=ss, n_ext=n_ext, cmd_c=pad(base.cmd_c), cmd_d=np.asarray(cmd_d, float),
                     rate_c=pad(base.rate_c), applied_c=pad(base.applied_c), inertia_kgm2=base.inertia_kgm2,
                     limits=embed_limits(base.limits, n, 0))


def simplex_state_space(model: TvcModel, axis: str = "pitch", *, structure_inputs: bool = False,
                        engine_cg_offset_m: float = 0.0) -> StateSpace:
    """Linear simplex block for one axis.

    Inputs: ``command_rad`` (engine-angle command after the avionics), ``friction_torque_Nm``.
    Outputs: :data:`SIMPLEX_OUTPUTS`. States: the actuator states, ``theta_rad``, ``omega_rad_s``.
    Parameters may be CasADi SX expressions (fits); the matrices are then SX.

    ``structure_inputs=True`` (an elastic structure; module docstring) appends the inputs
    :data:`STRUCTURE_INPUTS` (e [m], r [rad], a_g [m/s^2]) and the outputs
    :data:`STRUCTURE_OUTPUTS` (K_n (theta - r) [N m], f_twd = -m_e l_e theta'' [N]);
    ``load_force_N`` and ``applied_torque_Nm`` then include e and r. ``engine_cg_offset_m`` is
    l_e [m], the engine c.g.'s distance from the gimbal perpendicular to the rotation axis
    (m_e is ``model.engine.mass_kg``).
    """
    _check_model_axis(model, axis)
    check_flag(structure_inputs, "structure_inputs")
    act = actuator_state_space(model.actuator)
    R = model.actuator.moment_arm_m
    KL = model.structure.stiffness_N_per_m(axis)   # the axis' own K_L ([structure] load_stiffness_yaw)
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
    cL = model.structure.load_damping_Ns_per_m(R, J, axis)  # structural damping on the load path
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
    if structure_inputs:
        return _with_structure_inputs(A, B, C, states, bf, R, KL, Kn, J,
                                      model.engine.mass_kg * engine_cg_offset_m, na, sym)
    return StateSpace(finish(A, sym), finish(B, sym), finish(C, sym), finish(zeros((C.shape[0], 2), sym), sym),
                      states, ("command_rad", "friction_torque_Nm"), SIMPLEX_OUTPUTS)


def _with_structure_inputs(A, B, C, states, bf, R, KL, Kn, J, ml, na, sym) -> StateSpace:
    """Append the structure-motion inputs and the reaction outputs (module docstring) to the
    planar block (A, B, C; ``bf`` the actuator's load-force input column, ``ml`` = m_e l_e
    [kg m])."""
    n = A.shape[0]
    ith, iom = na, na + 1
    # dF_L/de = -K_L; d(applied)/de = -R K_L, d(applied)/dr = K_n; the engine also feels -m_e l_e a_g
    B2 = zeros((n, 5), sym)
    B2[:, :2] = B
    B2[:na, 2] = [-KL * b for b in bf]
    B2[iom, 2] = -R * KL / J
    B2[iom, 3] = Kn / J
    B2[iom, 4] = -ml / J
    C2 = zeros((C.shape[0] + 2, n), sym)
    C2[:C.shape[0]] = C
    C2[-2, ith] = Kn
    C2[-1, :] = [-ml * a for a in A[iom, :]]              # f_twd = -m_e l_e theta''
    D2 = zeros((C2.shape[0], 5), sym)
    ia, il = SIMPLEX_OUTPUTS.index("applied_torque_Nm"), SIMPLEX_OUTPUTS.index("load_force_N")
    D2[ia, 2] = -R * KL
    D2[ia, 3] = Kn
    D2[il, 2] = -KL
    D2[-2, 3] = -Kn
    D2[-1, :] = [-ml * b for b in B2[iom, :]]
    return StateSpace(finish(A, sym), finish(B2, sym), finish(C2, sym), finish(D2, sym), states,
                      ("command_rad", "friction_torque_Nm") + STRUCTURE_INPUTS, SIMPLEX_OUTPUTS + STRUCTURE_OUTPUTS)


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
    """The model's actuator and gimbal limits packed over the simplex state (:mod:`taos.planar.saturation`):
    valve flow saturation, supply-pressure limit (square-root law and relief valve), hard stops at
    the gimbal range."""
    from ._limits_pack import limit_rows_for_actuator, pack_model_limits
    act, eng = model.actuator, model.engine
    rows, _ = limit_rows_for_actuator(act)
    ss = simplex_state_space(model, axis)
    n = len(ss.states)
    full = {k: np.concatenate([v, np.zeros(n - v.size)]) for k, v in rows.items()}
    full["theta"] = np.zeros(n)
    full["theta"][ss.state_index("theta_rad")] = 1.0
    full["omega"] = np.zeros(n)
    full["omega"][ss.state_index("omega_rad_s")] = 1.0
    full["stop_in"] = full["omega"] / eng.inertia(axis)
    return pack_model_limits(act, eng, axis, full)


def load_resonance_from_notch(model: TvcModel, axis: str = "pitch",
                              f_lo: float = 0.5, f_hi: float = 30.0) -> float:
    """Frequency [Hz] of the minimum of the linear command -> piston gain (the notch) between
    ``f_lo`` and ``f_hi`` [Hz] (:func:`taos.linear.notch_hz`: dense log grid, bounded search)."""
    _check_model_axis(model, axis)
    lo = check_number(f_lo, "f_lo", RESPONSE_FREQ_HZ[0], RESPONSE_FREQ_HZ[1], "Hz")
    check_number(f_hi, "f_hi", lo, RESPONSE_FREQ_HZ[1], "Hz", lo_open=True)
    ss = simplex_state_space(model, axis)
    return notch_hz(lambda f: np.abs(ss.freqresp(f, "command_rad", "x_p_m")), f_lo, f_hi)


def _check_model_axis(model, axis) -> None:
    """The public functions' ``model`` (a TvcModel) and ``axis`` ('pitch' or 'yaw'), as the command line."""
    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    check_axis(axis)


def check_rk4_step(dt_s: float, model, field: str, source: str = "argument", *, pressure_limit: bool = True) -> None:
    """The explicit step's rule of the command line's ``--dt`` (dt |lambda|max <=
    :data:`taos.bounds.RK4_STEP_LIMIT`, over the linear modes of both axes and, unless
    ``pressure_limit`` is False (an engine that integrates that rate exactly, the 3-D one), the
    supply-pressure limit's rate: :func:`taos.planar.envelope.fastest_mode_rad_s`)."""
    import math

    from ..bounds import AXES, RK4_STEP_LIMIT
    from ..errors import InputError
    from ._limits_pack import pressure_limit_rate_per_s

    lam = max(float(np.max(np.abs(simplex_state_space(model, ax).poles()))) for ax in AXES)
    if pressure_limit:
        lam = max(lam, pressure_limit_rate_per_s(model.actuator))
    if dt_s * lam > RK4_STEP_LIMIT:
        raise InputError(source, field, f"a step at most {RK4_STEP_LIMIT / lam:.3g} s (dt |lambda|max <= "
                         f"{RK4_STEP_LIMIT:g}, fastest mode {lam / (2 * math.pi):.4g} Hz)", got=f"{dt_s:g} s")
