"""Gimbal compliance seen along an actuator line, and the load stiffness K_L it implies.

Series model (quasi-static, one actuator, engine rotating about the gimbal)::

    thrust structure (held) -- upper half -- pivot at O -- lower half -- engine (rigid)

* Upper half: its 6x6 matrix with the bolted face held, at the bearing centre O.
* Pivot: the halves share the translations of O and the roll rotation rz (the universal
  joint's cross keeps roll); pitch/yaw rotations rx, ry are released (the bearing slides:
  that rotation is the engine angle theta itself).
* Lower half: its 12x12 free-free matrix between O and its bolted face L; the engine is a
  rigid body fixed to L.
* Loads on the engine: the actuator force F along the unit vector e at the attach point A,
  plus the d'Alembert loads of the rigid rotation it causes about O (rate of change of
  angular momentum): alpha = ((A - O) x F e) . n / J_O about the axis n, the centre-of-mass
  acceleration a = alpha n x (c - O), inertial force -m a at c and torque -J_c alpha n. The
  net moment about O then vanishes and the net force F e - m a goes through the gimbal.

The load-path deflection along the actuator line is delta = e . u_A - R theta, i.e. the
actuator-line motion of A minus the part due to the engine's rigid rotation about O; the
gimbal compliance is C_g = delta / F [m/N]. With a remaining compliance C_rest of the
rest of the load path (thrust structure, actuator case and attachments, engine),
1 / K_L = C_rest + C_g (springs in series). C_rest is chosen so that the ambient (hanging)
total is the Green Run ambient value, and the hot-fire (thrust-loaded) K_L follows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve

from ..units import N_PER_M_PER_LBF_PER_IN
from .elasticity import rigid_transform

#: N/m per lbf/in (:data:`taos.units.N_PER_M_PER_LBF_PER_IN`, under the name the FEM API exports)
LBF_PER_IN = N_PER_M_PER_LBF_PER_IN


@dataclass(frozen=True)
class ActuatorLine:
    """Actuator and engine geometry for the series model (gimbal frame, origin O) [SI].

    attach_point_m : A, engine-side attach point [m]; direction : e (normalised here);
    engine_mass_kg : m; engine_com_m : c [m]; engine_inertia_about_gimbal_kgm2 : J_O about
    the rotation axis n = e x (A - O) / |...| [kg m^2] (the pitch or yaw inertia).
    """

    attach_point_m: tuple[float, float, float] = (0.8, 0.0, -0.5)
    direction: tuple[float, float, float] = (0.0, 0.0, 1.0)
    engine_mass_kg: float = 3527.0
    engine_com_m: tuple[float, float, float] = (0.0, 0.0, -1.5)
    engine_inertia_about_gimbal_kgm2: float = 12000.0

    @property
    def moment_arm_m(self) -> float:
        """R = |(A - O) x e| [m]."""
        return float(np.linalg.norm(np.cross(self.attach_point_m, self._e)))

    @property
    def _e(self) -> np.ndarray:
        e = np.asarray(self.direction, float)
        return e / np.linalg.norm(e)


def _condense(K: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Static condensation of K onto the DOFs ``keep`` (others unloaded)."""
    drop = np.setdiff1d(np.arange(K.shape[0]), keep)
    Kkk, Kkd, Kdd = K[np.ix_(keep, keep)], K[np.ix_(keep, drop)], K[np.ix_(drop, drop)]
    return Kkk - Kkd @ solve(Kdd, Kkd.T, assume_a="sym")


def actuator_line_compliance(K_upper: np.ndarray, K_lower_free: np.ndarray,
                             lower_bolted_point_m: np.ndarray, line: ActuatorLine) -> float:
    """Gimbal compliance C_g = delta / F [m/N] along the actuator line (see module notes).

    K_upper : (6, 6) upper half at O with its bolted face held [SI blocks].
    K_lower_free : (12, 12) lower half, DOFs of O then of its bolted face L [SI blocks].
    lower_bolted_point_m : (3,) L [m].
    """
    # upper: release its pitch/yaw rotations at O (they belong to the pivot)
    Ku = _condense(np.asarray(K_upper, float), np.array([0, 1, 2, 5]))  # (ux, uy, uz, rz)
    # assembly DOFs: 0-2 u_O, 3 rz_O, 4-5 lower rx, ry at O, 6-11 engine/L
    n = 12
    K = np.zeros((n, n))
    K[np.ix_([0, 1, 2, 3], [0, 1, 2, 3])] += Ku
    low_map = np.array([0, 1, 2, 4, 5, 3, 6, 7, 8, 9, 10, 11])
    K[np.ix_(low_map, low_map)] += np.asarray(K_lower_free, float)
    L = np.asarray(lower_bolted_point_m, float)
    A = np.asarray(line.attach_point_m, float)
    c = np.asarray(line.engine_com_m, float)
    e = line._e
    F = 1.0
    axis = np.cross(A, e)
    R = np.linalg.norm(axis)
    nvec = axis / R
    alpha = F * R / line.engine_inertia_about_gimbal_kgm2
    acc = alpha * np.cross(nvec, c)
    J_c = line.engine_inertia_about_gimbal_kgm2 - line.engine_mass_kg * float(
        np.dot(c, c) - np.dot(c, nvec) ** 2)
    f = np.zeros(6)
    f[:3] = F * e - line.engine_mass_kg * acc
    f[3:] = np.cross(A - L, F * e) + np.cross(c - L, -line.engine_mass_kg * acc) - J_c * alpha * nvec
    load = np.zeros(n)
    load[6:] = f
    # remove the pivot mechanism by holding the engine's pitch/yaw rotations; the loads are
    # self-equilibrated about O so the held rotations carry no reaction.
    free = np.array([0, 1, 2, 3, 4, 5, 6, 7, 8, 11])
    q = np.zeros(n)
    q[free] = solve(K[np.ix_(free, free)], load[free], assume_a="sym")
    reaction = K @ q - load
    if np.abs(reaction[[9, 10]]).max() > 1e-6 * np.abs(f).max() * max(1.0, np.linalg.norm(A - L)):
        raise ArithmeticError("actuator-line loads are not balanced about the gimbal")
    uA = rigid_transform(np.repeat(A[:, None], 3, 1), np.arange(3), L) @ q[6:]
    return float(e @ uA) / F


@dataclass(frozen=True)
class LoadStiffnessShift:
    """Implied load stiffness K_L [N/m] ambient and hot fire from the gimbal FEM pair.

    compliance_hanging/thrust_m_per_N : C_g per condition; rest_compliance_m_per_N : C_rest,
    chosen so that 1 / (C_rest + C_g,hanging) = K_L ambient target.
    """

    compliance_hanging_m_per_N: float
    compliance_thrust_m_per_N: float
    rest_compliance_m_per_N: float
    K_L_ambient_N_per_m: float
    K_L_hotfire_N_per_m: float

    @property
    def ratio(self) -> float:
        """K_L hot fire / K_L ambient."""
        return self.K_L_hotfire_N_per_m / self.K_L_ambient_N_per_m

    @property
    def gimbal_share_ambient(self) -> float:
        """Fraction of the ambient load-path compliance that is in the gimbal."""
        return self.compliance_hanging_m_per_N * self.K_L_ambient_N_per_m


def implied_load_stiffness(C_hanging: float, C_thrust: float,
                           K_L_ambient_N_per_m: float = 115000.0 * LBF_PER_IN) -> LoadStiffnessShift:
    """K_L hot fire implied by the gimbal's change, with C_rest fixed by the ambient K_L."""
    C_rest = 1.0 / K_L_ambient_N_per_m - C_hanging
    if C_rest <= 0.0:
        raise ValueError("gimbal alone is softer than the ambient load stiffness")
    return LoadStiffnessShift(C_hanging, C_thrust, C_rest, K_L_ambient_N_per_m,
                              1.0 / (C_rest + C_thrust))


def stuck_gimbal_stiffness(K_upper: np.ndarray, K_lower_free: np.ndarray) -> np.ndarray:
    """6x6 stiffness of the whole gimbal at the lower (engine) bolted face, thrust structure
    held and the bearing stuck (all 6 DOFs of O shared): upper and lower halves in series,
    O condensed out. DOFs (ux, uy, uz, rx, ry, rz) of the lower bolted-face point [SI]."""
    K = np.asarray(K_lower_free, float).copy()
    K[:6, :6] += np.asarray(K_upper, float)
    return _condense(K, np.arange(6, 12))
