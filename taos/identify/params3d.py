"""The parameters a fit of the 3-D TAOS model may free, their model-file keys and bounds.

Every fitted model is a model-file variant (:func:`taos.taos3d.with_values`: the file with other
values, through the loader, line stiffness re-derived), so each free parameter is one or two
model-file keys:

=========================  ===================================  ====================================
name                       model-file key(s)                    meaning [SI]
=========================  ===================================  ====================================
``load_stiffness``         ``structure.load_stiffness``         K_L, the fitted total load path
                                                                [N/m]; the actuator-line stiffness
                                                                follows with the FEM gimbal in
                                                                series (:mod:`taos.taos3d.calibrate`)
``load_stiffness_yaw``     ``structure.load_stiffness_yaw``     K_L,yaw, the yaw axis' own total
                                                                [N/m] (start: the file's, else
                                                                ``load_stiffness``); the yaw
                                                                line follows it
``upper_stiffness_scale``  ``gimbal.upper_stiffness_scale``     s_u [-] on the upper FEM half K_u
``lower_stiffness_scale``  ``gimbal.lower_stiffness_scale``     s_l [-] on the lower FEM half K_l
``coulomb_torque``         ``friction.coulomb_torque``          T_c, the friction LEVEL [N m]; the
                           (+ ``gimbal.friction_coefficient``   law's torque-like parameters follow
                           = T_c / (N r_b) when the file holds  it; mu kept consistent
                           it)
``friction_coefficient``   ``gimbal.friction_coefficient``      mu [-]; T_c = mu N r_b set with it
                           + ``friction.coulomb_torque``
``bristle_stiffness``      ``friction.bristle_stiffness``       sigma_0 [N m/rad] (set after level)
``vibration_velocity``     ``friction.vibration_velocity``      V_d [rad/s] (modified LuGre)
``static_torque``          ``friction.static_torque``           T_s [N m] (held >= T_c)
=========================  ===================================  ====================================

Bounds (:func:`bounds3d`) come from physics and the record, never from the start value: K_L
(and K_L,yaw) and T_c as the planar fit's (:mod:`taos.identify.physbounds`: the load resonance within the
measured band widened by an octave; T_c from 1e-4 to 1 times the stall torque A P_s R), mu
from those T_c over N r_b, the half scales 0.1 to 10 (a FEM correction within an order of
magnitude), sigma_0 for a pre-sliding angle T_c / sigma_0 between 1e-3 and 1 deg, V_d from
1e-3 to 10 deg/s, T_s from T_c to 3 T_c (a Stribeck peak at most three times the sliding level).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.errors import InputError

DEG = math.pi / 180
#: the 3-D model's largest step in a replay [s] (its default step, taos.taos3d.simulate)
REPLAY_DT_S = 4e-4


class Unidentifiable(InputError):
    """The record does not identify some free parameters (:func:`taos.identify.fit3d.fit_taos`
    refuses). ``result``: the fit refused, the :class:`~taos.identify.fit3d_result.Fit3dResult`
    ``refuse=False`` returns (its flags say why), or None."""

    result = None


@dataclass(frozen=True)
class Param3d:
    """One free parameter: its model-file key, physical kind (:data:`taos.units.DIMENSIONS`) and
    the unit it is shown in."""

    name: str
    key: str
    kind: str
    unit: str
    friction: bool = False

    def get(self, tm) -> float:
        """The parameter's value [SI] in 3-D model ``tm``."""
        b = tm.base
        if self.name == "load_stiffness":
            return b.structure.load_stiffness_N_per_m
        if self.name == "load_stiffness_yaw":
            return float(b.structure.stiffness_N_per_m("yaw"))
        if self.name == "upper_stiffness_scale":
            return tm.gimbal.upper_stiffness_scale
        if self.name == "lower_stiffness_scale":
            return tm.gimbal.lower_stiffness_scale
        if self.name == "friction_coefficient":
            return tm.gimbal.friction_coefficient
        attr = {"coulomb_torque": "coulomb_torque_Nm", "bristle_stiffness": "bristle_stiffness_Nm_per_rad",
                "vibration_velocity": "vibration_velocity_rad_s", "static_torque": "static_torque_Nm"}[self.name]
        return float(getattr(b.friction, attr))


PARAMETERS3D: dict[str, Param3d] = {p.name: p for p in (
    Param3d("load_stiffness", "structure.load_stiffness", "stiffness", "lbf/in"),
    Param3d("load_stiffness_yaw", "structure.load_stiffness_yaw", "stiffness", "lbf/in"),
    Param3d("upper_stiffness_scale", "gimbal.upper_stiffness_scale", "dimensionless", ""),
    Param3d("lower_stiffness_scale", "gimbal.lower_stiffness_scale", "dimensionless", ""),
    Param3d("coulomb_torque", "friction.coulomb_torque", "torque", "in*lbf", True),
    Param3d("friction_coefficient", "gimbal.friction_coefficient", "dimensionless", "", True),
    Param3d("bristle_stiffness", "friction.bristle_stiffness", "rotational_stiffness", "N*m/rad", True),
    Param3d("vibration_velocity", "friction.vibration_velocity", "angular_velocity", "deg/s", True),
    Param3d("static_torque", "friction.static_torque", "torque", "in*lbf", True),
)}


def check_free3d(tm, free) -> tuple[Param3d, ...]:
    """The :class:`Param3d` of names ``free``, else one-line :class:`InputError` (an unknown or
    repeated name, both friction-level names, a friction parameter of a law without it)."""
    import dataclasses

    src = "command line"
    if not free:
        raise InputError(src, "--free", "one or more of " + ", ".join(PARAMETERS3D), got="none")
    out = []
    law = tm.base.friction
    fields = {f.metadata.get("key") for f in dataclasses.fields(law)}
    for n in free:
        if n not in PARAMETERS3D:
            raise InputError(src, "--free", "names of the 3-D fit: " + ", ".join(PARAMETERS3D), got=repr(n))
        p = PARAMETERS3D[n]
        if p.friction and not law.has_friction:
            raise InputError(tm.base.source, "friction.model", f"a law with friction to fit {n}", got=law.name)
        if p.friction and n not in ("coulomb_torque", "friction_coefficient") and n not in fields:
            raise InputError(tm.base.source, "friction.model", f"a law with {n} (e.g. modified-lugre)", got=law.name)
        out.append(p)
    if len(set(free)) != len(free):
        raise InputError(src, "--free", "each parameter once", got=",".join(free))
    if {"coulomb_torque", "friction_coefficient"} <= set(free):
        raise InputError(src, "--free", "one friction level: coulomb_torque OR friction_coefficient (T_c = mu N r_b)",
                         got=",".join(free))
    return tuple(out)


def variant_values(tm, params, values) -> dict:
    """The model-file keys and values (SI) of ``params`` at ``values``: the friction level sets
    ``friction.coulomb_torque`` and, when the file holds ``gimbal.friction_coefficient``, that
    too (mu = T_c / (N r_b), so the load-time check holds); a static torque is held >= T_c."""
    from taos.taos3d.model import normal_load_N

    out: dict = {}
    nrb = normal_load_N(tm.base) * tm.gimbal.bearing_radius_m
    gtab = tm.base.extra.get("gimbal", {}) if isinstance(tm.base.extra.get("gimbal"), dict) else {}
    tc = None
    for p, v in zip(params, values):
        v = float(v)
        if p.name == "coulomb_torque":
            tc = v
        elif p.name == "friction_coefficient":
            tc = v * nrb
        else:
            out[p.key] = v
    if tc is not None:
        out["friction.coulomb_torque"] = tc
        if "friction_coefficient" in gtab or "friction_coefficient" in {p.name for p in params}:
            out["gimbal.friction_coefficient"] = tc / nrb
    if "friction.static_torque" in out:
        out["friction.static_torque"] = max(out["friction.static_torque"],
                                            tc if tc is not None else tm.base.friction.coulomb_torque_Nm)
    return out


def bounds3d(tm, params, freq_hz, axes) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """(lower, upper) [SI] and the rule of each of ``params`` (module docstring), for a record
    with points at ``freq_hz`` [Hz] on ``axes``."""
    from taos.friction.bounds import loader_bound
    from taos.identify.physbounds import physical_bounds
    from taos.taos3d.model import normal_load_N

    names = [p.name for p in params]
    phys = physical_bounds(tm.base, ["load_stiffness", "coulomb_torque"], axes, freq_hz)
    tc = tm.base.friction.coulomb_torque_Nm
    nrb = normal_load_N(tm.base) * tm.gimbal.bearing_radius_m
    lo, hi, basis = [], [], []
    for n in names:
        if n in ("load_stiffness", "coulomb_torque", "load_stiffness_yaw"):
            b = phys[n.removesuffix("_yaw")]
            lo.append(b.lower), hi.append(b.upper), basis.append(b.basis)
        elif n == "friction_coefficient":
            b = phys["coulomb_torque"]
            lo.append(b.lower / nrb), hi.append(b.upper / nrb), basis.append(b.basis + ", over N r_b")
        elif n.endswith("_stiffness_scale"):
            lo.append(0.1), hi.append(10.0), basis.append("FEM half stiffness within x0.1..x10 of the FEM")
        elif n == "bristle_stiffness":
            lo.append(tc / (1.0 * DEG)), hi.append(tc / (1e-3 * DEG))
            basis.append("pre-sliding angle T_c/sigma_0 from 1e-3 to 1 deg")
        elif n == "vibration_velocity":
            lo.append(1e-3 * DEG), hi.append(10.0 * DEG), basis.append("1e-3 to 10 deg/s")
        elif n == "static_torque":
            lo.append(tc), hi.append(3.0 * tc), basis.append("T_c to 3 T_c (Stribeck peak)")
    for k, p in enumerate(params):   # never a value the model loader refuses (issue 40)
        b = loader_bound(p.key)
        if b is not None:
            lo[k], hi[k] = max(lo[k], b[0]), min(hi[k], b[1])
    return np.array(lo, float), np.array(hi, float), tuple(basis)


def to_eng(p: Param3d, v_si: float) -> float:
    """``v_si`` in the parameter's display unit."""
    from taos.units import DIMENSIONS, from_si
    return v_si if not p.unit else from_si(v_si, DIMENSIONS[p.kind][1], p.unit)
