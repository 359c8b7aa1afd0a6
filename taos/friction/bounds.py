"""Physical bounds of the friction parameter-set keys, each with its reason (issue 40).

A friction parameter set (``models/friction/*.toml``, named by a model file's ``[friction]
parameter_set``) and a model file's own ``[friction]`` table hold the law parameters of one
gimbal bearing. :data:`FRICTION_BOUNDS` bounds every key of every built-in law (the torque
levels ``coulomb_torque`` and ``static_torque`` are bounded with the model file's values,
:data:`taos.bounds.MODEL_BOUNDS`) and the set's ``reference_torque``. As for the model file's
table, the bounds are orders of magnitude around gimbal-bearing hardware, not tolerances: they
refuse a mistyped unit or exponent (``"1e30 N*m/rad"``, a negative Stribeck exponent, a stick
band of ``"1e6 deg/s"`` that holds the engine stuck through every command), never a real
bearing. Sources of the typical values: the shipped RS-25 set (``models/friction/rs25_gimbal.toml``);
C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, IEEE TAC 40(3) (1995) 419-425
(LuGre: sigma_0 = 1e5 N/m, v_s = 1e-3 m/s, delta = 2); B. Armstrong-Helouvry, P. Dupont,
C. Canudas de Wit, Automatica 30(7) (1994) 1083-1138 (Stribeck velocities 1e-5 to 1e-1 m/s,
Stribeck exponents 0.5 to 2, pre-sliding displacements of micrometres); P. R. Dahl (1968);
N. Barabanov, R. Ortega, IEEE TAC 45(4) (2000) 830-832 (LuGre passivity).

Checked when a parameter set is read (:func:`check_friction_values`, naming the set file) and
again on the merged ``[friction]`` table a law is built from (:func:`taos.friction.friction_from_table`:
the model file's own keys, a set's values scaled to the file's ``coulomb_torque``, a variant's
values, naming the model file), then the cross-field rule :func:`check_friction_law`. Every
refusal is :class:`~taos.errors.InputError`: one line naming the file, the field, the range and
its reason (exit 2). Keys of laws registered at run time or by plug-ins carry no bound here.
Listed in docs/reference/bounds.md.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

from ..bounds import DEG
from ..errors import InputError
from ..units import to_si

#: ``[friction]`` key of a parameter set: the torque level its load-proportional values hold at
REFERENCE_TORQUE_KEY = "reference_torque"

#: "section.key" -> (lowest, highest) in SI, SI unit, why; angles and rates shown in deg here
FRICTION_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "friction.reference_torque": (1e-2, 1e7, "N*m", "the torque level the set's bristle, viscous and stick "
                                  "values hold at, as friction.coulomb_torque (RS-25 set 1.63e4 N m); above zero: "
                                  "they are scaled by coulomb_torque / reference_torque"),
    "friction.stick_velocity": (1e-6 * DEG, 10.0 * DEG, "rad/s", "Karnopp's stick band is a rate near zero "
                                "(RS-25 set 0.06 deg/s): at the TVC slew rates of 5-30 deg/s it would hold the engine "
                                "stuck through every command; below 1e-6 deg/s no step resolves it (the step is "
                                "checked against it at run time)"),
    "friction.stick_damping": (0.0, 1e11, "N*m*s/rad", "bleeds the residual rate while stuck (RS-25 set 1.2e7, "
                               "time constant J/c = 1 ms); 1e11 gives 0.1 ms on the largest engine inertia "
                               "1e7 kg m^2, below any step: a lock, not a damper"),
    "friction.regularization_velocity": (1e-6 * DEG, 10.0 * DEG, "rad/s", "the smooth Coulomb law's "
                                         "regularisation rate (RS-25 set 0.01 deg/s) lies far below the engine rates: "
                                         "at the TVC slew rates of 5-30 deg/s the law is a viscous damper, not "
                                         "Coulomb friction"),
    "friction.bristle_stiffness": (1.0, 1e12, "N*m/rad", "pre-sliding stiffness sigma_0 (RS-25 set 1.3e7, "
                                   "pre-sliding angle T_c/sigma_0 0.07 deg): the contact's spring is in series with "
                                   "the gimbal halves (RS-25 FEM at most 5.5e10 N m/rad) and is no stiffer by orders "
                                   "of magnitude; below 1 N m/rad even a 1 N m bearing would slide a radian "
                                   "before it slips"),
    "friction.dahl_exponent": (1.0, 10.0, "1", "Dahl's shape exponent alpha: 1 for ball bearings (Dahl 1968, "
                               "the usual choice); below 1 the state leaves its invariant set |z| <= T_c/sigma_0; "
                               "above 10 the pre-sliding curve is a step"),
    "friction.stribeck_velocity": (1e-4 * DEG, 1e3 * DEG, "rad/s", "Stribeck velocities of lubricated contacts "
                                   "are 1e-5 to 1e-1 m/s (Armstrong-Helouvry et al. 1994; Canudas de Wit et al. 1995 "
                                   "1e-3 m/s), 5e-3 to 50 deg/s at the 0.11 m bearing radius; RS-25 set 0.1 deg/s"),
    "friction.stribeck_exponent": (0.25, 10.0, "1", "shape delta of exp(-|v/v_s|^delta): 0.5 to 2 in the "
                                   "literature (Armstrong-Helouvry et al. 1994; Canudas de Wit et al. 1995 and the "
                                   "RS-25 set 2); at or below zero the curve no longer falls from T_s to T_c with the "
                                   "rate, above 10 it is a step"),
    "friction.bristle_damping": (0.0, 1e11, "N*m*s/rad", "bristle damping sigma_1 (RS-25 set 4e5, about half "
                                 "of critical 2 sqrt(sigma_0 J) on the bristle spring); 1e11 is 16 x critical at the "
                                 "largest bristle stiffness and engine inertia (6.3e9)"),
    "friction.viscous_damping": (0.0, 1e9, "N*m*s/rad", "viscous bearing friction sigma_2 (RS-25 set 0): 1e9 "
                                 "N m s/rad at an engine rate of 0.6 deg/s is already the largest Coulomb torque "
                                 "1e7 N m"),
    "friction.damping_decay_velocity": (1e-4 * DEG, 1e4 * DEG, "rad/s", "rate v_1 where the bristle damping "
                                        "has halved (RS-25 set 3 deg/s); positive: a constant sigma_1 (v_1 = 0) makes "
                                        "LuGre active above |v| = 4 g (sigma_1 + sigma_2) / sigma_1^2 (Barabanov and "
                                        "Ortega 2000)"),
    "friction.vibration_velocity": (0.0, 100.0 * DEG, "rad/s", "rate amplitude V_d of the bearing's vibration "
                                    "(RS-25 set 0.3 deg/s; 0: plain LuGre); at 100 deg/s the friction would vanish "
                                    "below every TVC rate"),
}


def key_kinds() -> dict[str, str]:
    """``[friction]`` key -> unit kind (:func:`taos.units.to_si`) of every key the laws known
    so far declare, and the set's ``reference_torque``."""
    from .registry import param_classes

    out = {REFERENCE_TORQUE_KEY: "torque"}
    for cls in param_classes().values():
        for f in dataclasses.fields(cls):
            out.setdefault(f.metadata["key"], f.metadata["kind"])
    return out


def _shown(v: float, unit: str) -> str:
    """``v`` (SI) as the bounds page shows it: rates in deg/s, a plain number when dimensionless."""
    if unit == "rad/s":
        return f"{v / DEG:.4g} deg/s"
    return f"{v:.4g}" if unit == "1" else f"{v:.4g} {unit}"


def _range_text(lo: float, hi: float, unit: str) -> str:
    return f"from {_shown(lo, unit)} to {_shown(hi, unit)}"


def check_friction_value(key: str, value, src: str, section: str = "friction",
                         kinds: Mapping[str, str] | None = None) -> float | None:
    """``value`` of ``[section] key`` (text with its unit, or a number for a dimensionless key)
    in SI, refused unless finite and within :data:`FRICTION_BOUNDS` (one line: ``src``, the
    field, the range and its reason); None for a key without a bound here. ``kinds``: the
    :func:`key_kinds` of the moment (given when checking a whole table)."""
    bound = FRICTION_BOUNDS.get(f"friction.{key}")
    if bound is None:
        return None
    lo, hi, unit, why = bound
    field = f"{section}.{key}"
    v = to_si(value, (kinds or key_kinds())[key], source=src, field=field)
    if not (math.isfinite(v) and lo <= v <= hi):
        raise InputError(src, field, f"a value {_range_text(lo, hi, unit)} ({why})", got=_shown(v, unit))
    return v


def check_friction_values(table: Mapping, src: str, section: str = "friction") -> None:
    """Every bounded key of a ``[friction]`` table or parameter set within :data:`FRICTION_BOUNDS`
    (:func:`check_friction_value`), the torque levels first (within :data:`taos.bounds.MODEL_BOUNDS`:
    the set's values are scaled to ``coulomb_torque``, so a level beyond its bound is named as
    the cause, not the scaled value); other keys are left to the loader."""
    from ..bounds import MODEL_BOUNDS, check_bound

    for key in ("coulomb_torque", "static_torque"):
        if key in table and f"friction.{key}" in MODEL_BOUNDS:
            check_bound(to_si(table[key], "torque", source=src, field=f"{section}.{key}"), f"friction.{key}", src)
    kinds = key_kinds()
    for key in sorted(k for k in table if isinstance(k, str)):
        check_friction_value(key, table[key], src, section, kinds)


def check_friction_law(law, src: str, section: str = "friction") -> None:
    """Cross-field rule of a built law: a LuGre law with bristle damping needs a positive
    ``damping_decay_velocity`` (a constant sigma_1 is active at high rates, Barabanov and Ortega
    2000; the key's default 0 would give one)."""
    s1 = getattr(law, "bristle_damping_Nms_per_rad", 0.0)
    v1 = getattr(law, "damping_decay_velocity_rad_s", None)
    if v1 is not None and s1 > 0 and not v1 > 0:
        lo, hi, unit, why = FRICTION_BOUNDS["friction.damping_decay_velocity"]
        raise InputError(src, f"{section}.damping_decay_velocity", f"a value {_range_text(lo, hi, unit)} with "
                         f"bristle_damping > 0 ({why})", got="nothing (key missing)")


def loader_bound(field: str) -> tuple[float, float] | None:
    """(lowest, highest) [SI] the model loader holds ``field`` ("section.key") to, from
    :data:`FRICTION_BOUNDS` or :data:`taos.bounds.MODEL_BOUNDS`; None when it has none. A fit or
    reduction clips its search to it, so it never returns a value the loader refuses."""
    from ..bounds import MODEL_BOUNDS

    b = FRICTION_BOUNDS.get(field) or MODEL_BOUNDS.get(field)
    return None if b is None else (b[0], b[1])
