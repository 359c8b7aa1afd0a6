"""Every key a model file may hold, with its physical kind: one table for the loader
(:mod:`taos.model`), the variants (:mod:`taos.variants`) and the docs' key reference.

A kind is a key of :data:`taos.units.DIMENSIONS` (the unit a value must carry, parsed to SI);
``None`` marks a key holding text, a whole number, a switch or a list. The friction keys come
from the registered laws' parameter classes (:mod:`taos.friction`), so a new law's keys are
model keys without an edit here.
"""

from __future__ import annotations

from .errors import InputError

ACTUATOR_FIELDS = {  # key -> (kind, check)
    "moment_arm": ("length", "positive"),
    "piston_area": ("area", "positive"),
    "supply_pressure": ("pressure", "positive"),
    "oil_bulk_modulus": ("pressure", "positive"),
    "trapped_volume": ("volume", "positive"),
    "piston_mass": ("mass", "positive"),
    "piston_damping": ("damping", "nonnegative"),
    "loop_gain": ("rate", "positive"),
    "valve_natural_frequency": ("frequency", "positive"),
    "valve_damping_ratio": ("dimensionless", "positive"),
    "flow_pressure_coefficient": ("flow_pressure", "nonnegative"),
    "leakage_coefficient": ("flow_pressure", "nonnegative"),
    "pressure_feedback_gain": ("velocity_per_pressure", "nonnegative"),
    "pressure_feedback_time_constant": ("time", "nonnegative"),
    "max_rate": ("velocity", "positive"),
    "relief_pressure": ("pressure", "positive"),
    "relief_flow_coefficient": ("flow_pressure", "positive"),
    "rated_flow": ("flow", "nonnegative"),
    "pump_capacity": ("flow", "nonnegative"),
}
ACTUATOR_SI = {"moment_arm": "moment_arm_m", "piston_area": "piston_area_m2",
                "supply_pressure": "supply_pressure_Pa", "oil_bulk_modulus": "oil_bulk_modulus_Pa",
                "trapped_volume": "trapped_volume_m3", "piston_mass": "piston_mass_kg",
                "piston_damping": "piston_damping_Ns_per_m", "loop_gain": "loop_gain_per_s",
                "valve_natural_frequency": "valve_natural_frequency_hz",
                "valve_damping_ratio": "valve_damping_ratio",
                "flow_pressure_coefficient": "flow_pressure_coefficient_m3_per_s_Pa",
                "leakage_coefficient": "leakage_coefficient_m3_per_s_Pa",
                "pressure_feedback_gain": "pressure_feedback_gain_m_per_s_Pa",
                "pressure_feedback_time_constant": "pressure_feedback_time_constant_s",
                "max_rate": "max_rate_m_per_s", "relief_pressure": "relief_pressure_Pa",
                "relief_flow_coefficient": "relief_flow_coefficient_m3_per_s_Pa",
                "rated_flow": "rated_flow_m3_per_s", "pump_capacity": "pump_capacity_m3_per_s"}
_ENGINE_KINDS = {"mass": "mass", "inertia_pitch": "inertia", "inertia_yaw": "inertia",
                 "rotational_stiffness": "rotational_stiffness", "thrust": "force", "gimbal_range": "angle",
                 "hard_stop_stiffness": "rotational_stiffness", "hard_stop_damping_ratio": "dimensionless"}
_STRUCTURE_KINDS = {"load_stiffness": "stiffness", "load_damping_ratio": "dimensionless",
                    "load_stiffness_yaw": "stiffness"}
_GIMBAL_KINDS = {"friction_coefficient": "dimensionless", "bearing_radius": "length",
                 "line_load_stiffness": "stiffness", "stiffness_file": None,
                 "upper_stiffness_scale": "dimensionless", "lower_stiffness_scale": "dimensionless"}
#: keys whose value is not a physical quantity (text, whole numbers, switches, lists)
_PLAIN = {"friction.model", "friction.parameter_set", "actuator.parameter_set", "actuator.valve_order",
          "actuator.pressure_limited", "avionics.quantization_bits", "avionics.rounding",
          "avionics.crossover_command", "avionics.crossover_gain", "gimbal.stiffness_file",
          "geometry.pitch_structure_attach", "geometry.pitch_engine_attach", "geometry.yaw_structure_attach",
          "geometry.yaw_engine_attach", "geometry.engine_cg", "name", "description"}


def key_kind(dotted: str) -> str | None:
    """The physical kind (a key of :data:`taos.units.DIMENSIONS`) of model key ``dotted``
    (``"section.key"``), ``None`` for a key holding text, a whole number, a switch or a list;
    :class:`InputError` for a key no model file may hold."""
    from .friction import param_classes

    if dotted in _PLAIN:
        return None
    section, _, key = dotted.partition(".")
    kinds: dict[str, str | None] = {}
    if section == "engine":
        kinds = dict(_ENGINE_KINDS)
    elif section == "actuator":
        kinds = {k: kind for k, (kind, _) in ACTUATOR_FIELDS.items()}
    elif section == "structure":
        kinds = dict(_STRUCTURE_KINDS)
    elif section == "friction":
        import dataclasses

        kinds = {f.metadata["key"]: f.metadata["kind"] for cls in param_classes().values()
                 for f in dataclasses.fields(cls) if "key" in f.metadata}
    elif section == "avionics":
        kinds = {"command_range": "angle"}
    elif section == "gimbal":
        kinds = dict(_GIMBAL_KINDS)
    elif section == "geometry":
        kinds = {"engine_roll_inertia": "inertia"}
    if key not in kinds:
        known = sorted(f"{section}.{k}" for k in kinds) or ["engine.*, actuator.*, structure.*, friction.*, "
                                                              "avionics.*, gimbal.*, geometry.*"]
        raise InputError("model variant", dotted, "a model-file key (section.key), e.g. " + ", ".join(known[:8]),
                         got="a key no model file holds")
    return kinds[key]


def torque_like_kinds(exclude: tuple[str, ...] = ("coulomb_torque",)) -> dict[str, str]:
    """``[friction]`` key -> unit kind of every registered law's torque-like parameters (those
    proportional to the bearing normal load: torque levels, bristle stiffness and damping,
    viscous and stick damping), less ``exclude``: what follows the friction level."""
    import dataclasses

    from .friction import param_classes

    return {f.metadata["key"]: f.metadata["kind"] for cls in param_classes().values() for f in dataclasses.fields(cls)
            if f.metadata.get("torque_like") and f.metadata["key"] not in exclude}
