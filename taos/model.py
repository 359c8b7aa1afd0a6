"""Model files: TOML parameter sets with units, loaded into frozen SI dataclasses.

A model file (``models/rs25_ambient.toml`` and friends) holds the sections below; every physical value
is a string with its unit, parsed by pint (:mod:`taos.units`). The DESIGN contract keys (model files
written for one release load in the next) are ``[engine] mass, inertia_pitch, inertia_yaw,
rotational_stiffness``, ``[actuator] moment_arm``, ``[structure] load_stiffness``, ``[friction] model,
coulomb_torque``, ``[avionics] quantization_bits, command_range, rounding``; every key a file may hold,
with its unit kind, is in one table, :mod:`taos.model_keys` (the docs' key reference is generated from
the loader and it). A variant of a model, any key with another value, goes through this loader too
(:meth:`TvcModel.with_values`, :mod:`taos.variants`).

Shared hardware: ``[actuator] parameter_set`` and ``[friction] parameter_set`` name one TOML file per
piece of hardware (``models/actuators/tvc_actuator.toml``, ``models/friction/rs25_gimbal.toml``) whose
table is merged into the section; a key given in both places is an error
(:func:`actuator_table_with_parameter_set`, :func:`friction_table_with_parameter_set`).

Other sections (``[gimbal]``, ``[geometry]``) belong to the 3-D model and are kept as raw tables in
:attr:`TvcModel.extra` for it to validate.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import types
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from .planar.avionics import Avionics
from .errors import InputError, read_toml  # noqa: F401  (read_toml: model files and the 3-D loader)
from .friction import FrictionLaw, friction_from_table
#: REFERENCE_TORQUE_KEY: key of a parameter set, the torque level its load-proportional values hold at
from .friction.bounds import REFERENCE_TORQUE_KEY, check_friction_values
from .shipped import resolve
from .units import to_si

KNOWN_SECTIONS = {"name", "description", "engine", "actuator", "structure", "friction", "avionics",
                  "gimbal", "geometry"}


@dataclass(frozen=True)
class Engine:
    """Gimballed engine (rigid body about the gimbal point).

    mass_kg : gimballed mass [kg]; inertia_pitch/yaw_kgm2 : J_n about the gimbal [kg m^2];
    rotational_stiffness_Nm_per_rad : K_n, feedlines and gravity [N m/rad]; thrust_N : thrust pressing
    the gimbal bearing [N] (0 when hanging); gimbal_range_rad : hard stops at +-theta_max [rad] (0: none);
    hard_stop_stiffness_Nm_per_rad : contact stiffness k_s [N m/rad]; hard_stop_damping_ratio : zeta_s of
    the contact on J_n [-] (:mod:`taos.planar.saturation`).
    """

    mass_kg: float
    inertia_pitch_kgm2: float
    inertia_yaw_kgm2: float
    rotational_stiffness_Nm_per_rad: float
    thrust_N: float = 0.0
    gimbal_range_rad: float = 0.0
    hard_stop_stiffness_Nm_per_rad: float = 0.0
    hard_stop_damping_ratio: float = 0.0

    def hard_stop_damping_Nms_per_rad(self, axis: str) -> float:
        """c_s = 2 zeta_s sqrt(k_s J_n) [N m s/rad] of the hard-stop contact."""
        return 2.0 * self.hard_stop_damping_ratio * math.sqrt(self.hard_stop_stiffness_Nm_per_rad * self.inertia(axis))

    def inertia(self, axis: str) -> float:
        """J_n [kg m^2] about ``axis`` ('pitch' or 'yaw')."""
        return self.inertia_pitch_kgm2 if axis == "pitch" else self.inertia_yaw_kgm2


@dataclass(frozen=True)
class Actuator:
    """Mechanical-feedback hydraulic position servo (Merritt, Hydraulic Control Systems, 1967).

    Equations (SI)::

        valve:       q'' + 2 zeta_v w_v q' + w_v^2 q = w_v^2 K_v (x_c - x_p)   (order 2)
                     q' = w_v (K_v (x_c - x_p) - q)                               (order 1)
        continuity:  (V_t / 4 beta) P_L' = A q - (K_c + C_l) P_L - A v_p
        piston:      M_p v_p' = A P_L - F_L - B_p v_p

    q is the valve's no-load flow divided by the piston area [m/s]; K_v = K_q K_fb / A is the position
    loop gain [1/s]; K_dpf [m/(s Pa)] with time constant tau_dpf [s] is the dynamic pressure feedback
    that damps the load resonance without softening the static stiffness (a velocity servo with oil
    compressibility alone gives the load mode negative damping unless K_c > A^2 K_v / K_h). Limits (:mod:`taos.planar.saturation`, nonlinear, time domain only):
    ``max_rate_m_per_s`` the valve flow saturation as a no-load piston rate [m/s] (0: none);
    ``pressure_limited`` the supply-pressure limit, stall force A P_s: the critical-centre valve's
    square-root pressure-drop law Q = K_q x_v sqrt((P_s - sgn(x_v) P_L) / P_s) (K_q the no-load flow
    gain, so the null linearisation is the linear model above) with a cross-port relief valve,
    Q_r = K_r (|P_L| - P_r) sgn(P_L) for |P_L| > P_r: ``relief_pressure_Pa`` P_r [Pa] (>= P_s; 0: no
    relief) and ``relief_flow_coefficient_m3_per_s_Pa`` K_r [m^3/(s Pa)] (Merritt 1967, ch. 3).
    Duty-cycle limits (:mod:`taos.flight.duty`; 0: none): servovalve rated flow, pump capacity [m^3/s].
    """

    moment_arm_m: float
    piston_area_m2: float
    supply_pressure_Pa: float
    oil_bulk_modulus_Pa: float
    trapped_volume_m3: float
    piston_mass_kg: float
    piston_damping_Ns_per_m: float
    loop_gain_per_s: float
    valve_natural_frequency_hz: float
    valve_damping_ratio: float
    valve_order: int
    flow_pressure_coefficient_m3_per_s_Pa: float
    leakage_coefficient_m3_per_s_Pa: float
    pressure_feedback_gain_m_per_s_Pa: float = 0.0
    pressure_feedback_time_constant_s: float = 0.0
    max_rate_m_per_s: float = 0.0
    pressure_limited: bool = False
    relief_pressure_Pa: float = 0.0
    relief_flow_coefficient_m3_per_s_Pa: float = 0.0
    rated_flow_m3_per_s: float = 0.0
    pump_capacity_m3_per_s: float = 0.0

    @property
    def oil_column_stiffness_N_per_m(self) -> float:
        """K_h = 4 beta A^2 / V_t [N/m] (Merritt eq. 5-56, piston centred)."""
        return 4.0 * self.oil_bulk_modulus_Pa * self.piston_area_m2 ** 2 / self.trapped_volume_m3

    @property
    def stall_force_N(self) -> float:
        """A P_s [N]."""
        return self.piston_area_m2 * self.supply_pressure_Pa


@dataclass(frozen=True)
class Structure:
    """Load path outside the actuator position loop: K_L [N/m] (thrust structure, engine,
    gimbal, actuator case and attachments in series), and its structural damping as the
    damping ratio zeta_L [-] of the engine on the load spring (piston held): a viscous damper
    c_L = 2 zeta_L sqrt(K_L R^2 J_n) / R^2 [N s/m] in parallel with K_L, so that
    F_L = K_L (x_p - R theta) + c_L (v_p - R theta'). Without it the command -> piston notch is
    an undamped zero of unbounded depth."""

    load_stiffness_N_per_m: float
    load_damping_ratio: float = 0.0
    #: K_L of the yaw axis [N/m] (``[structure] load_stiffness_yaw``, optional): the yaw
    #: actuator's load path when it differs from the pitch one; 0 (the key absent):
    #: ``load_stiffness`` on both axes (a float, never None: the FMU exposes every field)
    load_stiffness_yaw_N_per_m: float = 0.0

    def stiffness_N_per_m(self, axis: str = "pitch"):
        """K_L of ``axis`` [N/m]: ``load_stiffness_yaw`` for yaw when the file gives it, else
        ``load_stiffness`` (pitch, and yaw by default)."""
        if axis == "yaw" and not (isinstance(self.load_stiffness_yaw_N_per_m, (int, float))
                                  and self.load_stiffness_yaw_N_per_m == 0):
            return self.load_stiffness_yaw_N_per_m
        return self.load_stiffness_N_per_m

    def load_damping_Ns_per_m(self, moment_arm_m, inertia_kgm2, axis: str = "pitch"):
        """c_L = 2 zeta_L sqrt(K_L R^2 J) / R^2 [N s/m] with the K_L of ``axis``
        (:meth:`stiffness_N_per_m`); works on CasADi expressions too, for fits."""
        if isinstance(self.load_damping_ratio, (int, float)) and self.load_damping_ratio == 0:
            return 0.0
        return 2.0 * self.load_damping_ratio * (self.stiffness_N_per_m(axis) * moment_arm_m ** 2
                                                * inertia_kgm2) ** 0.5 / moment_arm_m ** 2


@dataclass(frozen=True)
class TvcModel:
    """One engine, its gimbal friction, actuators and command avionics (SI inside)."""

    name: str
    engine: Engine
    actuator: Actuator
    structure: Structure
    friction: FrictionLaw
    avionics: Avionics
    source: str = "<code>"
    #: this model's hash: its files' combined hash (:attr:`base_sha256`) with its overrides
    sha256: str = ""
    #: (``"section.key"``, value as a model file holds it) of a variant, in the order given
    #: (:mod:`taos.variants`); ``code.FIELD`` for a field changed in code (:meth:`replace`)
    overrides: tuple = ()
    #: the combined hash of the files it was read from (:func:`combined_sha256`)
    base_sha256: str = ""
    #: role -> (resolved path, SHA-256) of every file the model was read from: ``model``, and the
    #: ``actuator_parameter_set``, ``friction_parameter_set`` and ``stiffness_file`` it names;
    #: ``sha256`` is their combined hash (:func:`combined_sha256`)
    input_files: Mapping[str, tuple[str, str]] = field(default_factory=lambda: types.MappingProxyType({}),
                                                       compare=False)
    friction_table: Mapping[str, Any] = field(default_factory=lambda: types.MappingProxyType({}),
                                              compare=False, repr=False)
    extra: Mapping[str, Any] = field(default_factory=lambda: types.MappingProxyType({}),
                                     compare=False, repr=False)
    #: path -> bytes of every TOML file it was read from (model file, parameter sets): its variants
    #: are parsed from these, never from the disk (:func:`taos.errors.stored_inputs`)
    input_bytes: Mapping[str, bytes] = field(default_factory=lambda: types.MappingProxyType({}),
                                             compare=False, repr=False)

    # -- derived figures ------------------------------------------------------------------
    def load_resonance_hz(self, axis: str = "pitch") -> float:
        """w_L / 2 pi with w_L = sqrt((K_L R^2 + K_n) / J_n) (seed paper eq. 1) [Hz], K_L and J_n
        of ``axis`` (:meth:`Structure.stiffness_N_per_m`)."""
        R = self.actuator.moment_arm_m
        k = self.structure.stiffness_N_per_m(axis) * R * R + self.engine.rotational_stiffness_Nm_per_rad
        return math.sqrt(k / self.engine.inertia(axis)) / (2 * math.pi)

    def breakaway_deflection_rad(self) -> float:
        """T_c / (K_L R^2) [rad]: load-path deflection that friction holds before the engine moves."""
        R = self.actuator.moment_arm_m
        return self.friction.coulomb_torque_Nm / (self.structure.load_stiffness_N_per_m * R * R)

    # -- variants (taos.variants) ----------------------------------------------------------
    def with_values(self, values: Mapping[str, Any]) -> "TvcModel":
        """The model file with the keys ``values`` (``{"structure.load_stiffness": "160000
        lbf/in", ...}``; a plain number is SI) given other values, through the loader and its
        bounds: the one way to make a variant (:mod:`taos.variants`)."""
        from .errors import stored_inputs
        from .variants import (base_variant, check_unchanged, check_variant_source, code_changes,
                               keep_code_changes, merge_overrides, variant_sha256)

        check_variant_source(self, values)
        code = code_changes(self)
        old = tuple(kv for kv in self.overrides if not kv[0].startswith("code."))
        overrides = merge_overrides(old, values)

        def load(over):
            table = dict(over)
            kept = {f: (self.input_bytes.get(f), h) for f, h in self.input_files.values()}
            with stored_inputs(kept):   # the very files it was read from, wherever this runs
                return load_model(self.source, friction=table.pop("friction.model", None), overrides=table,
                                  source_bytes=self.input_bytes.get(self.source))
        out = load(overrides)
        check_unchanged(self, out)
        if not code:
            return out
        # the changes made in code stay, with the variant's own effect laid over them
        code = keep_code_changes(code, base_variant(self, old, load), out)
        out = dataclasses.replace(out, **code)
        marks = tuple((f"code.{k}", v) for k, v in code.items())
        return dataclasses.replace(out, overrides=overrides + marks, sha256=variant_sha256(out.base_sha256,
                                                                                        overrides + marks))

    def with_friction(self, name: str) -> "TvcModel":
        """The same model with friction law ``name``, keeping the file's torque levels
        (the variant ``{"friction.model": name}``)."""
        return self.with_values({"friction.model": name})

    def replace(self, **changes) -> "TvcModel":
        """Copy with dataclass fields replaced in code. The copy records it (``code.FIELD`` in
        :attr:`overrides`) and carries its own hash; a change a model file can express is a
        variant, :meth:`with_values`."""
        from .variants import _same, variant_sha256

        out = dataclasses.replace(self, **changes)
        marks = tuple((f"code.{k}", v) for k, v in sorted(changes.items())   # an equal value changes nothing
                      if k not in ("overrides", "sha256", "base_sha256") and not _same(getattr(self, k), v))
        if not marks:
            return out
        overrides = tuple(kv for kv in out.overrides if kv[0] not in dict(marks)) + marks
        return dataclasses.replace(out, overrides=overrides, sha256=variant_sha256(out.base_sha256, overrides))


# -- loading ------------------------------------------------------------------------------
def _need(table: Mapping, key: str, kind: str, src: str, section: str, **checks) -> float:
    if key not in table:
        from .units import DIMENSIONS
        raise InputError(src, f"{section}.{key}", f"a {kind.replace('_', ' ')} with its unit, like "
                         f"{DIMENSIONS[kind][2]}", got="nothing (key missing)")
    return to_si(table[key], kind, source=src, field=f"{section}.{key}", **checks)


def _section(doc: Mapping, name: str, src: str) -> Mapping:
    sec = doc.get(name)
    if not isinstance(sec, Mapping):
        raise InputError(src, f"[{name}]", f"a [{name}] table",
                         got="nothing (section missing)" if sec is None else repr(sec)[:60])
    return sec


def _check_keys(sec: Mapping, allowed: set[str], src: str, section: str) -> None:
    from .errors import check_keys

    check_keys(sec, allowed, src, section)


def parse_engine(doc: Mapping, src: str) -> Engine:
    s = _section(doc, "engine", src)
    _check_keys(s, {"mass", "inertia_pitch", "inertia_yaw", "rotational_stiffness", "thrust", "gimbal_range",
                    "hard_stop_stiffness", "hard_stop_damping_ratio"}, src, "engine")
    stops = {}
    if "gimbal_range" in s:
        stops = dict(gimbal_range_rad=_need(s, "gimbal_range", "angle", src, "engine", positive=True),
                     hard_stop_stiffness_Nm_per_rad=_need(s, "hard_stop_stiffness", "rotational_stiffness", src,
                                                          "engine", positive=True),
                     hard_stop_damping_ratio=_need(s, "hard_stop_damping_ratio", "dimensionless", src, "engine",
                                                   nonnegative=True))
    return Engine(
        mass_kg=_need(s, "mass", "mass", src, "engine", positive=True),
        inertia_pitch_kgm2=_need(s, "inertia_pitch", "inertia", src, "engine", positive=True),
        inertia_yaw_kgm2=_need(s, "inertia_yaw", "inertia", src, "engine", positive=True),
        rotational_stiffness_Nm_per_rad=_need(s, "rotational_stiffness", "rotational_stiffness", src,
                                              "engine", nonnegative=True),
        thrust_N=(to_si(s["thrust"], "force", source=src, field="engine.thrust", nonnegative=True)
                  if "thrust" in s else 0.0),
        **stops,
    )


from .model_keys import ACTUATOR_FIELDS as _ACTUATOR_FIELDS, ACTUATOR_SI as _ACTUATOR_SI  # noqa: E402

#: the relief valve's cracking pressure against the supply: P_s <= P_r <= RELIEF_PRESSURE_MAX P_s
RELIEF_PRESSURE_MAX = 1.5


def parse_actuator(doc: Mapping, src: str) -> Actuator:
    s = _section(doc, "actuator", src)
    _check_keys(s, set(_ACTUATOR_FIELDS) | {"valve_order", "pressure_limited"}, src, "actuator")
    optional = {"pressure_feedback_gain", "pressure_feedback_time_constant", "max_rate", "relief_pressure",
                "relief_flow_coefficient", "rated_flow", "pump_capacity"}
    kw = {_ACTUATOR_SI[k]: _need(s, k, kind, src, "actuator", **{chk: True})
          for k, (kind, chk) in _ACTUATOR_FIELDS.items() if k not in optional or k in s}
    from .bounds import MODEL_BOUNDS, check_bound

    for key, si_name in _ACTUATOR_SI.items():   # the bounds first: a cross-field check names the right field
        if si_name in kw and f"actuator.{key}" in MODEL_BOUNDS and not (key in optional and kw[si_name] == 0.0):
            check_bound(kw[si_name], f"actuator.{key}", src)
    if kw.get("pressure_feedback_gain_m_per_s_Pa", 0.0) > 0 and not kw.get(
            "pressure_feedback_time_constant_s", 0.0) > 0:
        raise InputError(src, "actuator.pressure_feedback_time_constant",
                         "a positive time constant when pressure_feedback_gain is set")
    order = s.get("valve_order", 2)
    if order not in (1, 2) or isinstance(order, bool):
        raise InputError(src, "actuator.valve_order", "1 or 2", got=repr(order))
    _check_relief(s, kw, src)
    plim = s.get("pressure_limited", False)
    if not isinstance(plim, bool):
        raise InputError(src, "actuator.pressure_limited", "true or false", got=repr(plim))
    return Actuator(valve_order=int(order), pressure_limited=plim, **kw)


def _check_relief(s: Mapping, kw: dict, src: str) -> None:
    """The relief valve's two keys come together, and it cracks between P_s and
    :data:`RELIEF_PRESSURE_MAX` P_s (a relief below the supply would cut the stall force)."""
    has = [k for k in ("relief_pressure", "relief_flow_coefficient") if k in s]
    if len(has) == 1:
        other = ({"relief_pressure", "relief_flow_coefficient"} - set(has)).pop()
        raise InputError(src, f"actuator.{other}", f"a value with its unit when actuator.{has[0]} is set "
                         "(the relief valve needs both)")
    if has:
        pr, ps = kw["relief_pressure_Pa"], kw["supply_pressure_Pa"]
        if not ps <= pr <= RELIEF_PRESSURE_MAX * ps:
            raise InputError(src, "actuator.relief_pressure", f"a cracking pressure from the supply pressure "
                             f"({ps:.4g} Pa) to {RELIEF_PRESSURE_MAX:g} times it", got=f"{pr:.4g} Pa")


def parse_avionics(doc: Mapping, src: str) -> Avionics:
    s = _section(doc, "avionics", src)
    _check_keys(s, {"quantization_bits", "command_range", "rounding", "crossover_command",
                    "crossover_gain"}, src, "avionics")
    bits = s.get("quantization_bits")
    if not isinstance(bits, int) or isinstance(bits, bool) or not 0 <= bits <= 32:
        raise InputError(src, "avionics.quantization_bits", "a whole number of bits from 0 to 32",
                         got="nothing (key missing)" if bits is None else repr(bits))
    rng = _need(s, "command_range", "angle", src, "avionics", positive=True)
    rounding = s.get("rounding")
    if rounding not in ("truncate", "round"):
        raise InputError(src, "avionics.rounding", "'truncate' or 'round'",
                         got="nothing (key missing)" if rounding is None else repr(rounding))
    cmd = s.get("crossover_command", [])
    gain = s.get("crossover_gain", [])
    if not isinstance(cmd, list) or not isinstance(gain, list) or len(cmd) != len(gain):
        raise InputError(src, "avionics.crossover_gain", "a list as long as crossover_command")
    amps = tuple(to_si(c, "angle", source=src, field=f"avionics.crossover_command[{i}]", nonnegative=True)
                 for i, c in enumerate(cmd))
    gains = tuple(to_si(g, "dimensionless", source=src, field=f"avionics.crossover_gain[{i}]", positive=True)
                  for i, g in enumerate(gain))
    if any(b <= a for a, b in zip(amps, amps[1:])):
        raise InputError(src, "avionics.crossover_command", "strictly increasing command magnitudes")
    return Avionics(quantization_bits=bits, command_range_rad=rng, rounding=(rounding == "round"),
                    gain_table_rad=amps, gain_table=gains)


#: ``[friction]`` key naming the shared friction parameter set of one piece of hardware
PARAMETER_SET_KEY = "parameter_set"


def resolve_parameter_set(ref: str, model_path: Path, section: str | None = None) -> Path:
    """Absolute path of a ``parameter_set`` named by the model file at ``model_path`` (in its
    ``[section]``): the one rule for file references (:func:`taos.shipped.resolve_reference`),
    relative to the model file, else to the shipped models folder (so a copied model file still
    finds it); :class:`InputError` naming the model file, the field and both places when missing."""
    from .shipped import resolve_reference

    field = f"{section}.{PARAMETER_SET_KEY}" if section else PARAMETER_SET_KEY
    return resolve_reference(ref, model_path, field=field, kind="model",
                             what=f"a {section + ' ' if section else ''}parameter-set file")


def _parameter_set(ref, model_path: Path, src: str, section: str) -> tuple[Path, dict]:
    """Path and ``[section]`` table of the parameter set ``ref`` named by a model file's
    ``[section] parameter_set`` (a path relative to the model file, else to the shipped models
    folder, so a copied model file still finds it)."""
    if not isinstance(ref, str) or not ref:
        raise InputError(src, f"{section}.{PARAMETER_SET_KEY}", f"a path to a {section} parameter-set TOML file",
                         got=repr(ref))
    ppath = resolve_parameter_set(ref, model_path, section)
    _, pdoc = read_toml(ppath, f"a readable {section} parameter-set file")
    shared = pdoc.get(section)
    if not isinstance(shared, Mapping):
        raise InputError(str(ppath), f"[{section}]", f"a [{section}] table of the hardware's parameters",
                         got="nothing (section missing)")
    return ppath, dict(shared)


def _merge_parameter_set(table: dict, shared: Mapping, file_only: set[str], ppath: Path, ref: str,
                         src: str, section: str) -> None:
    """Merge the set's keys into the model file's ``table`` in place: a key in both places is an
    error (one piece of hardware, one value), and so is a key of ``file_only`` in the set."""
    for k in sorted(shared):
        if k in file_only or k == PARAMETER_SET_KEY:
            raise InputError(str(ppath), f"{section}.{k}", "hardware parameters only (this key belongs to "
                             "the model file)", got="a model-file key")
        if k in table:
            raise InputError(src, f"{section}.{k}", f"no value here: it is set once, in the parameter set {ref}",
                             got="a second value for the same hardware")
        table[k] = shared[k]


def friction_table_with_parameter_set(ftab: Mapping, model_path: Path, src: str) -> dict:
    """The ``[friction]`` table with its shared parameter set merged in.

    ``parameter_set = "friction/rs25_gimbal.toml"`` (a path relative to the model file, else to the
    shipped models folder, so a copied model file still finds it) names a
    TOML file whose ``[friction]`` table holds the law parameters of one piece of hardware
    (bristle, Stribeck, vibration, regularisation); the model file keeps only ``model`` and the
    torque levels of its condition. A key in both places is an error (one hardware, one value).
    """
    table = dict(ftab)
    ref = table.pop(PARAMETER_SET_KEY, None)
    if ref is None:
        return table
    ppath, shared = _parameter_set(ref, model_path, src, "friction")
    check_friction_values(shared, str(ppath))   # the set's own values, naming the set (issue 40)
    ref_torque = shared.pop(REFERENCE_TORQUE_KEY, None)
    _merge_parameter_set(table, shared, {"model"}, ppath, ref, src, "friction")
    if ref_torque is not None:
        _scale_to_torque_level(table, ref_torque, str(ppath), src)
    return table


#: ``[actuator]`` keys of the installation and the modelling choice, not of the actuator
#: hardware: they stay in each model file and a parameter set may not carry them
ACTUATOR_FILE_KEYS = frozenset({"moment_arm", "pressure_limited"})


def actuator_table_with_parameter_set(atab: Mapping, model_path: Path, src: str) -> dict:
    """The ``[actuator]`` table with its shared parameter set merged in.

    ``[actuator] parameter_set = "actuators/tvc_actuator.toml"`` names a TOML file whose
    ``[actuator]`` table holds the servoactuator hardware (piston, oil, servovalve, loop gain,
    dynamic pressure feedback, rate limit): one piece of hardware, one set, shared by the
    ambient, hot-fire and flight files. The model file keeps the installation (``moment_arm``,
    the DESIGN.md contract key) and the modelling switch ``pressure_limited``. As for the
    friction set, a key in both places is an error: a different actuator is a different set.
    """
    table = dict(atab)
    ref = table.pop(PARAMETER_SET_KEY, None)
    if ref is None:
        return table
    ppath, shared = _parameter_set(ref, model_path, src, "actuator")
    _merge_parameter_set(table, shared, set(ACTUATOR_FILE_KEYS), ppath, ref, src, "actuator")
    return table


def _scale_to_torque_level(table: dict, ref_torque, set_src: str, src: str) -> None:
    """Scale the set's load-proportional parameters (bristle stiffness and damping, viscous and
    stick damping: the torque-like fields other than the torque levels) from the set's
    ``reference_torque`` to this file's ``coulomb_torque``, in place. Friction proportional to the
    bearing normal load scales every one of them alike, so the pre-sliding angle T_c / sigma_0 and
    the law's shape stay those of the hardware; this is what the 3-D model does with the normal
    load (:meth:`taos.friction.FrictionLaw.scaled`), here applied to the planar torque level."""
    from .model_keys import torque_like_kinds
    from .units import DIMENSIONS

    ref = to_si(ref_torque, "torque", source=set_src, field=f"friction.{REFERENCE_TORQUE_KEY}", positive=True)
    if "coulomb_torque" not in table:
        raise InputError(src, "friction.coulomb_torque", "this condition's torque level (the parameter set is "
                         "scaled to it)", got="nothing (key missing)")
    level = to_si(table["coulomb_torque"], "torque", source=src, field="friction.coulomb_torque", nonnegative=True)
    kinds = torque_like_kinds(exclude=("coulomb_torque", "static_torque"))
    for key, kind in kinds.items():
        if key in table:
            v = to_si(table[key], kind, source=set_src, field=f"friction.{key}", nonnegative=True)
            table[key] = f"{v * level / ref!r} {DIMENSIONS[kind][1]}"


def _input_files(p: Path, raw: bytes, doc: Mapping) -> dict[str, tuple[str, str]]:
    """role -> (path, SHA-256) of the model file and the shared files it names (parameter sets,
    the 3-D ``[gimbal] stiffness_file`` when it exists; a missing one is the 3-D loader's error),
    each at the path the one reference rule resolves it to (:func:`taos.shipped.resolve_reference`):
    the file actually read."""
    from .errors import check_input_file
    from .results import file_sha256
    from .shipped import resolve_reference

    files = {"model": (str(p), hashlib.sha256(raw).hexdigest())}
    for sec in ("actuator", "friction"):
        ref = doc.get(sec, {}).get(PARAMETER_SET_KEY) if isinstance(doc.get(sec), Mapping) else None
        if isinstance(ref, str) and ref:
            q = resolve_parameter_set(ref, p, sec)
            files[f"{sec}_parameter_set"] = (str(q), file_sha256(q))
    gim = doc.get("gimbal")
    ref = gim.get("stiffness_file") if isinstance(gim, Mapping) else None
    if isinstance(ref, str) and ref:   # read only; a regular file of bounded size
        try:
            q = resolve_reference(ref, p, field="gimbal.stiffness_file", kind="model")
        except InputError:
            q = None   # the planar engine needs none: the 3-D loader reports it (taos.taos3d.model)
        if q is not None:
            check_input_file(q, "a stiffness matrix file (.npz or .csv)", field="gimbal.stiffness_file")
            files["stiffness_file"] = (str(q), file_sha256(q))
    return files


def combined_sha256(files: Mapping[str, tuple[str, str]]) -> str:
    """The model's recorded hash (``model_sha256``): SHA-256 of the lines ``role sha256`` of
    every input file, sorted by role (contents only: moving the files keeps it); a change to
    the model file or to any shared file it names (parameter sets, stiffness file) changes it.
    Per-file hashes are in :attr:`TvcModel.input_files` (``model_inputs`` in the outputs)."""
    text = "".join(f"{role} {files[role][1]}\n" for role in sorted(files))
    return hashlib.sha256(text.encode()).hexdigest()


def model_inputs(model: "TvcModel") -> dict:
    """``{role: {"file": path, "sha256": hex}}`` of a model's input files (provenance)."""
    return {role: {"file": f, "sha256": h} for role, (f, h) in model.input_files.items()}


def load_model(path: str | Path, friction: str | None = None, overrides: Mapping[str, Any] | None = None,
               *, source_bytes: bytes | None = None) -> TvcModel:
    """Load a model file. ``friction`` overrides the law (``--friction``), keeping torque levels.
    ``overrides``: ``{"section.key": TOML value}`` replacing (or adding) keys of the file before
    it is checked, exactly as if the file held them (``taos sweep``). ``source_bytes``: the file's
    contents as read before (a variant's reload, :meth:`TvcModel.with_values`); the files it names
    are resolved from ``path`` as always.

    Raises :class:`~taos.errors.InputError` (one line: file, field, expectation) on bad input.
    """
    if friction is not None:   # the argument named as such, its command-line flag in the message
        from .errors import as_argument
        from .friction import registry
        try:
            registry.params_of(friction, "argument", "friction")
        except InputError as e:
            raise as_argument(e, "friction", "--friction") from None
    if source_bytes is None:
        p = resolve(path, "model")
        raw, doc = read_toml(p, "a readable model file")
    else:
        from .errors import parse_toml

        p, raw = Path(path), source_bytes
        doc = parse_toml(raw, str(p))
    src = str(p)
    overrides = dict(overrides or {})
    from .variants import level_follows, with_overrides

    doc, late = with_overrides(level_follows(doc, overrides, src), overrides)
    _check_keys(doc, KNOWN_SECTIONS, src, "")
    if "name" in doc and not isinstance(doc["name"], str):
        raise InputError(src, "name", "a text name", got=repr(doc["name"])[:60])
    engine = parse_engine(doc, src)
    atab = actuator_table_with_parameter_set(_section(doc, "actuator", src), p, src) | late.get("actuator", {})
    actuator = parse_actuator({"actuator": atab}, src)
    st = _section(doc, "structure", src)
    _check_keys(st, {"load_stiffness", "load_damping_ratio", "load_stiffness_yaw"}, src, "structure")
    structure = Structure(_need(st, "load_stiffness", "stiffness", src, "structure", positive=True),
                          (_need(st, "load_damping_ratio", "dimensionless", src, "structure", nonnegative=True)
                           if "load_damping_ratio" in st else 0.0),
                          (_need(st, "load_stiffness_yaw", "stiffness", src, "structure", positive=True)
                           if "load_stiffness_yaw" in st else 0.0))
    ftab = friction_table_with_parameter_set(_section(doc, "friction", src), p, src) | late.get("friction", {})
    law = friction_from_table(ftab, src, model=friction)
    avionics = parse_avionics(doc, src)
    extra = {k: doc[k] for k in ("gimbal", "geometry") if k in doc}
    files = _input_files(p, raw, doc)
    from .bounds import check_model_bounds, check_model_plausible

    from .variants import variant_sha256

    check_model_bounds(src, engine, actuator, structure, avionics, ftab, extra)
    check_model_plausible(src, engine, actuator, structure)
    recorded = ((("friction.model", friction),) if friction is not None else ()) + tuple(overrides.items())
    return TvcModel(name=str(doc.get("name", p.stem)), engine=engine, actuator=actuator,
                    structure=structure, friction=law, avionics=avionics, source=src,
                    sha256=variant_sha256(combined_sha256(files), recorded), overrides=recorded,
                    base_sha256=combined_sha256(files), input_files=types.MappingProxyType(files),
                    friction_table=types.MappingProxyType(dict(ftab)),
                    extra=types.MappingProxyType(extra),
                    input_bytes=types.MappingProxyType(
                        {src: raw} | {f: read_toml(f, "a parameter set")[0] for r, (f, _) in files.items()
                                      if r.endswith("_parameter_set")}))
