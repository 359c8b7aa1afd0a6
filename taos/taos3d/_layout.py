"""The 3-D kernels' packed data: the model as a named tuple and the index tables of the state,
the bearing state, the right-hand side's reports, the stage commands and the records (no numba
here). The packer (:func:`taos.taos3d.simulate.pack`) and the kernels
(:mod:`taos.taos3d.dynamics`, which re-exports these names) both use them;
``tests/test_kernel_packs.py`` checks that each table tiles its array."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class TaosParams(NamedTuple):
    """The 3-D model packed for the kernels (:func:`taos.taos3d.simulate.pack`; SI, float64,
    C-contiguous; numba types it as a named tuple, so the kernels read it by field name).

    =========================== ========== ===================================================
    field                       shape      quantity [unit]
    =========================== ========== ===================================================
    spatial_inertia             (6, 6)     Y, the engine's spatial inertia at O, linear first
                                           [kg, kg m, kg m^2] (Pinocchio)
    spatial_inertia_inv         (6, 6)     Y^-1
    chain_stiffness             (6, 6)     K_s, the two gimbal halves in series at O
                                           [N/m, N/rad, N m/m, N m/rad]
    slip_gain                   (2, 6)     G = Kc S^T K_s: the torque-free bearing slip per
                                           pose, phi = G e - Kc T [rad/m, rad/rad]
    bearing_compliance          (2, 2)     Kc = (S^T K_s S)^-1, pitch/yaw [rad/(N m)]
    bearing_selection           (6, 2)     S, the chain DOFs the bearing releases [-]
    structure_attach_m          (2, 3)     actuator structure attach points (pitch, yaw) [m]
    engine_attach_m             (2, 3)     actuator engine attach points at zero angle [m]
    act_A                       (n_a, n_a) actuator state matrix [SI per second]
    act_b_xc                    (n_a,)     actuator input column of the piston command x_c
                                           [per m]
    act_b_fl                    (n_a,)     actuator input column of the load force F_L
                                           [per N]
    act_c_xp                    (n_a,)     actuator output row of the piston position x_p
    bearing_axes                (2, 3)     pitch and yaw unit axes in the gimbal frame [-]
    line_stiffness_N_per_m      (2,)       K_line of the pitch and yaw actuator lines: each line's
                                           stiffness outside the gimbal [N/m], derived from that
                                           axis' total K_L with the FEM gimbal in series
                                           (taos.taos3d.calibrate)
    moment_arm_m                scalar     R, the actuator moment arm [m]
    engine_stiffness_Nm_per_rad scalar     K_n, the feedline/gravity spring on pitch and yaw
                                           [N m/rad]
    line_length0_m              (2,)       L0, actuator line lengths at zero angle [m]
    line_damping_Ns_per_m       (2,)       c_L of the pitch and yaw load paths, structural
                                           damping [N s/m]
    act_vp_index                int        index of the piston rate v_p in the actuator state
    limits                      (k,)       actuator/gimbal limits over one actuator's state
                                           (:mod:`taos.planar.saturation`; all zero: none)
    torque_wrench               (6, 2)     K_s S Kc: the chain wrench per unit bearing torque
                                           [N/(N m), N m/(N m)] (:func:`taos.taos3d.dynamics._torque_kick`)
    act_pl_index                int        index of the load pressure P_L [Pa] in the actuator
                                           state (recorded, ``REC_PL``)
    act_q_index                 int        index of the servovalve's no-load flow over piston
                                           area q [m/s] in the actuator state (the spool signal,
                                           recorded, ``REC_Q``)
    =========================== ========== ===================================================
    """

    spatial_inertia: np.ndarray
    spatial_inertia_inv: np.ndarray
    chain_stiffness: np.ndarray
    slip_gain: np.ndarray
    bearing_compliance: np.ndarray
    bearing_selection: np.ndarray
    structure_attach_m: np.ndarray
    engine_attach_m: np.ndarray
    act_A: np.ndarray
    act_b_xc: np.ndarray
    act_b_fl: np.ndarray
    act_c_xp: np.ndarray
    bearing_axes: np.ndarray
    line_stiffness_N_per_m: np.ndarray
    moment_arm_m: float
    engine_stiffness_Nm_per_rad: float
    line_length0_m: np.ndarray
    line_damping_Ns_per_m: np.ndarray
    act_vp_index: int
    limits: np.ndarray
    torque_wrench: np.ndarray
    act_pl_index: int
    act_q_index: int


def params_dtype(p: TaosParams) -> np.dtype:
    """The structured dtype of the packed model ``p``: one field per :class:`TaosParams` field,
    in its order, each array with its own shape (float64), the scalars float64 and the indices
    int64 (:func:`as_record`)."""
    fields = []
    for name in TaosParams._fields:
        v = getattr(p, name)
        if isinstance(v, np.ndarray):
            fields.append((name, np.float64, v.shape))
        elif isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            fields.append((name, np.int64))
        else:
            fields.append((name, np.float64))
    return np.dtype(fields, align=True)


def as_record(p: TaosParams) -> np.record:
    """The packed model as a numpy record (:func:`params_dtype`), the form the kernels take.

    numba passes a named tuple of arrays to a compiled call flattened (each array's data
    pointer, shape and strides: about 150 machine words a call) and reads every array through
    its run-time strides; a record is passed as one pointer, and its fields are arrays of
    compile-time shape at fixed offsets. So the kernels call each other (the right-hand side
    four times a step, the step once) without inlining one into another, and each kernel is
    compiled once. The record reads as the named tuple does (``P.act_A``, ``P.moment_arm_m``);
    :func:`as_params` gives the named tuple back."""
    rec = np.zeros(1, dtype=params_dtype(p)).view(np.recarray)[0]
    for name in TaosParams._fields:
        rec[name] = getattr(p, name)
    return rec


def as_params(rec) -> TaosParams:
    """The named tuple of a packed-model record (:func:`as_record`): arrays as views of the
    record, scalars as Python numbers."""
    out = []
    for name in TaosParams._fields:
        v = rec[name]
        if isinstance(v, np.ndarray):
            out.append(v)
        elif isinstance(v, np.integer):
            out.append(int(v))
        else:
            out.append(float(v))
    return TaosParams(*out)


#: the engine's body state in ``x``: position [m], quaternion (xyzw), linear [m/s] and angular
#: [rad/s] body velocity; the actuators' states follow from N_BODY
X_P, X_Q, X_V, X_W = 0, 3, 7, 10
N_BODY = 13
#: the bearing state ``bs``: slip phi (2) [rad], bristle state z (2) [rad], torque T (2) [N m],
#: phi and z one step back (BDF2; 2 each), the slip speed [rad/s] the next bearing solve
#: continues from (components pitch, yaw), the slip rate w (2) [rad/s] and the length [s] of the
#: last bearing (sub)step (0 at rest: no history yet)
BS_PHI, BS_Z, BS_T, BS_PHI_PREV, BS_Z_PREV, BS_SLIP, BS_W, BS_H = 0, 2, 4, 6, 8, 10, 11, 13
N_BEARING = 14
#: what :func:`taos.taos3d.dynamics.rhs` writes to ``aux``: the chain wrench at O in the gimbal
#: frame (6) [N, N m], the actuator load forces F_L (2) [N], the bearing slip phi (2) [rad], the
#: engine angles (2) [rad] (pitch, yaw)
AUX_W, AUX_FL, AUX_PHI, AUX_THETA = 0, 6, 8, 10
N_AUX = 12
#: recorded columns of :func:`taos.taos3d.dynamics.integrate` (SI: rad, m, N, N m; the load
#: pressures ``pl_*`` [Pa] and the spool signals ``q_*`` [m/s], the servovalve's no-load flow over
#: piston area, as the planar :class:`taos.planar.simulate.TimeHistory` records them)
REC = ("theta_pitch", "theta_yaw", "xp_pitch", "xp_yaw", "fl_pitch", "fl_yaw", "tf_pitch", "tf_yaw",
       "z_pitch", "z_yaw", "phi_pitch", "phi_yaw", "u_pitch", "u_yaw",
       "w_fx", "w_fy", "w_fz", "w_mx", "w_my", "w_mz", "px", "py", "pz",
       "pl_pitch", "pl_yaw", "q_pitch", "q_yaw")
#: first column of each group of :data:`REC` (pitch then yaw; wrench fx..mz; point x, y, z)
REC_THETA, REC_XP, REC_FL, REC_TF = (REC.index(k) for k in ("theta_pitch", "xp_pitch", "fl_pitch", "tf_pitch"))
REC_Z, REC_PHI, REC_U, REC_W, REC_P = (REC.index(k) for k in ("z_pitch", "phi_pitch", "u_pitch", "w_fx", "px"))
REC_PL, REC_Q = (REC.index(k) for k in ("pl_pitch", "q_pitch"))
#: the stage commands of :func:`taos.taos3d.dynamics.stage_inputs` (pitch, then yaw at each):
#: step start, middle, end
U_START, U_MID, U_END = 0, 2, 4
#: the columns a dwell correlates: x_p pitch, yaw, theta pitch, yaw
_DWELL_COLS = (REC_XP, REC_XP + 1, REC_THETA, REC_THETA + 1)
