"""Reference pages generated from the code: the CLI from its argparse parsers, the model-file keys
from the code's own key tables (with an example value read from a shipped file)."""

from __future__ import annotations

import argparse
import os
import tomllib

# What each key means. The keys themselves, their order and their units come from the code;
# a key the code knows and this table does not is reported by the docs build (a warning, an
# error under -W), so a new key cannot go undocumented.
MEANINGS: dict[str, str] = {
    # [engine]
    "engine.mass": "engine mass m_e (the 3-D model's rigid body)",
    "engine.inertia_pitch": "engine inertia about the gimbal, pitch axis, J_n",
    "engine.inertia_yaw": "engine inertia about the gimbal, yaw axis, J_n",
    "engine.rotational_stiffness": "rotational stiffness K_n of feedlines and gravity about the gimbal",
    "engine.thrust": "thrust; sets the bearing normal load of the 3-D friction (0: hanging engine)",
    # [actuator]
    "actuator.moment_arm": "actuator moment arm R about the gimbal",
    "actuator.piston_area": "piston area A",
    "actuator.supply_pressure": "hydraulic supply pressure P_s",
    "actuator.oil_bulk_modulus": "effective oil bulk modulus beta",
    "actuator.trapped_volume": "oil volume V_t of both chambers and lines",
    "actuator.piston_mass": "moving mass M_p of piston, rod and end fittings",
    "actuator.piston_damping": "viscous damping B_p of seals and rod",
    "actuator.loop_gain": "position-loop gain K_v (piston velocity per position error)",
    "actuator.valve_natural_frequency": "servovalve natural frequency",
    "actuator.valve_damping_ratio": "servovalve damping ratio",
    "actuator.valve_order": "servovalve order, 1 or 2",
    "actuator.flow_pressure_coefficient": "flow-pressure coefficient K_c of the servovalve",
    "actuator.leakage_coefficient": "piston leakage coefficient C_l",
    "actuator.pressure_feedback_gain": "dynamic pressure feedback gain K_pf (optional)",
    "actuator.pressure_feedback_time_constant": "high-pass time constant of the pressure feedback",
    # [structure]
    "structure.load_stiffness": "load stiffness K_L: all compliance outside the actuator loop",
    "structure.load_damping_ratio": "structural damping ratio of the load path (finite notch depth)",
    "structure.load_stiffness_yaw": "the yaw axis' own load stiffness K_L,yaw (optional; absent: load_stiffness on both axes); the planar yaw axis and the 3-D yaw actuator line use it",
    "actuator.max_rate": "piston rate limit: valve flow saturation (time domain only)",
    "actuator.pressure_limited": "whether the load pressure is limited to the supply pressure (stall force): the valve's square-root law and the relief valve",
    "actuator.relief_pressure": "cracking pressure P_r of the cross-port relief valve (P_s to 1.5 P_s)",
    "actuator.relief_flow_coefficient": "flow coefficient K_r of the relief valve: Q_r = K_r (abs(P_L) - P_r)",
    "actuator.rated_flow": "servovalve rated flow Q_r: the duty cycle's limit on one actuator's peak valve flow (optional; 0: none; not simulated)",
    "actuator.pump_capacity": "hydraulic pump capacity Q_pump of one engine (both actuators): the duty cycle's limit on their mean flow (optional; 0: none)",
    "engine.gimbal_range": "gimbal range: the hard stops, modelled as a stiff damped contact",
    "engine.hard_stop_stiffness": "rotational stiffness of the hard-stop contact",
    "engine.hard_stop_damping_ratio": "damping ratio of the hard-stop contact",
    "friction.parameter_set": "the shared friction parameter set of the bearing (a TOML file)",
    "actuator.parameter_set": "the shared parameter set of the servoactuator hardware (a TOML file)",
    "vehicle.bending_frequency": "first bending mode frequency (0: no bending mode)",
    "vehicle.bending_damping_ratio": "damping ratio of the first bending mode",
    "vehicle.bending_gain": "bending-mode slope gain at the sensor and gimbal (rigid-body units)",
    # [friction]: the law ids and each law's keys and their meanings come from the friction registry
    # (friction_key_meanings: taos.friction.ids() and the laws' taos.friction.param(meaning=...))
    # [avionics]
    "avionics.quantization_bits": "bits of the flight-software command word",
    "avionics.command_range": "full range of the command word (LSB = range / 2^bits)",
    "avionics.rounding": "'truncate' or 'round' quantisation",
    "avionics.crossover_command": "command magnitudes of the servo-amplifier gain table",
    "avionics.crossover_gain": "servo-amplifier gain at each command magnitude",
    # [gimbal] (3-D)
    "gimbal.friction_coefficient": "bearing friction coefficient mu: derived key, checked against friction.coulomb_torque = mu N r_b (1 %), derived when absent",
    "gimbal.bearing_radius": "effective friction radius r_b of the spherical seat",
    "gimbal.stiffness_file": "FEM stiffness of the two gimbal halves (.npz in fem_data/)",
    "gimbal.line_load_stiffness": "load stiffness along the actuator lines outside the gimbal: derived key, from structure.load_stiffness with the gimbal in series when absent, checked (1 %) when given",
    "gimbal.upper_stiffness_scale": "factor on the upper FEM half's stiffness matrix (default 1: the FEM as computed; a 3-D fit's correction of the FEM)",
    "gimbal.lower_stiffness_scale": "factor on the lower FEM half's stiffness matrix (default 1)",
    # [geometry] (3-D)
    "geometry.pitch_structure_attach": "pitch actuator attach point on the structure (x, y, z)",
    "geometry.pitch_engine_attach": "pitch actuator attach point on the engine (x, y, z)",
    "geometry.yaw_structure_attach": "yaw actuator attach point on the structure (x, y, z)",
    "geometry.yaw_engine_attach": "yaw actuator attach point on the engine (x, y, z)",
    "geometry.engine_cg": "engine centre of mass in the gimbal frame (x, y, z)",
    "geometry.engine_roll_inertia": "engine inertia about its own axis through the c.g.",
    # flight file
    "vehicle.mass": "vehicle mass (reported)",
    "vehicle.pitch_inertia": "vehicle pitch inertia I_v about the c.g.",
    "vehicle.yaw_inertia": "vehicle yaw inertia I_v about the c.g.",
    "vehicle.engine_count": "number of engines n_e (all deflect alike)",
    "vehicle.thrust_per_engine": "thrust per engine T",
    "vehicle.gimbal_arm": "c.g. to gimbal-plane arm l_c",
    "vehicle.engine_mass": "engine mass m_e (tail-wags-dog)",
    "vehicle.engine_cg_offset": "gimbal to engine c.g. offset l_e",
    "vehicle.engine_inertia": "engine inertia about the gimbal J_n",
    "vehicle.aero_instability": "aerodynamic instability M_a (0 exo-atmospheric)",
    "fcs.attitude_gain": "attitude gain K_p",
    "fcs.integral_gain": "integral gain K_i",
    "fcs.rate_gain": "rate gain K_d",
    "fcs.lag_time_constant": "first-order lag tau of the command filter",
    "fcs.notch_frequency": "notch filter centre frequency (0: none)",
    "fcs.notch_zeta_num": "notch numerator damping ratio",
    "fcs.notch_zeta_den": "notch denominator damping ratio",
    "fcs.delay": "sensor and compute delay t_d",
    "fcs.pade_order": "order n of the (n, n) Pade approximant of the delay",
}

SECTION_TITLES = {
    "engine": "[engine]", "actuator": "[actuator]", "structure": "[structure]", "friction": "[friction]",
    "avionics": "[avionics]", "gimbal": "[gimbal] (3-D model, --engine taos)",
    "geometry": "[geometry] (3-D model, --engine taos)",
}


# -- CLI ----------------------------------------------------------------------------------------
def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for a in parser._actions:  # argparse keeps its subcommands here (no public accessor)
        if isinstance(a, argparse._SubParsersAction):
            return dict(a.choices)
    return {}


def cli_markdown(prog: str) -> str:
    """Markdown for every subcommand of ``prog`` ("taos" or "masv"), from the parser itself."""
    if prog == "taos":
        from taos.cli import build_parser
    else:
        from masv.cli import build_parser
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "100"
    try:
        parser = build_parser()
        out = [f"### {prog} (all commands)\n", f"```text\n{parser.format_help().rstrip()}\n```\n"]
        for name, sp in _subparsers(parser).items():
            out.append(f"### {prog} {name}\n")
            if sp.description:
                out.append(sp.description.strip() + "\n")
            out.append(f"```text\n{sp.format_help().rstrip()}\n```\n")
    finally:
        if old is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = old
    return "\n".join(out)


def cli_commands(prog: str) -> list[str]:
    if prog == "taos":
        from taos.cli import build_parser
    else:
        from masv.cli import build_parser
    return list(_subparsers(build_parser()))


# -- model-file keys ------------------------------------------------------------------------------
def _si(kind: str) -> str:
    from taos.units import DIMENSIONS
    return DIMENSIONS[kind][1]


def model_key_table() -> dict[str, list[tuple[str, str, str]]]:
    """section -> [(key, SI unit or kind, where the key comes from in the code)], from the code."""
    from taos import model as M
    from taos.taos3d import model as M3
    out: dict[str, list[tuple[str, str, str]]] = {}
    # [engine]: keys and kinds as parse_engine reads them; a file's unknown key is rejected by it
    out["engine"] = [("mass", _si("mass"), ""), ("inertia_pitch", _si("inertia"), ""),
                     ("inertia_yaw", _si("inertia"), ""), ("rotational_stiffness", _si("rotational_stiffness"), ""),
                     ("thrust", _si("force"), "optional"), ("gimbal_range", _si("angle"), "optional"),
                     ("hard_stop_stiffness", _si("rotational_stiffness"), "optional"),
                     ("hard_stop_damping_ratio", "1", "optional")]
    act = [("parameter_set", "path", "shared set")]
    act += [(k, _si(kind), chk) for k, (kind, chk) in M._ACTUATOR_FIELDS.items()]
    act.append(("valve_order", "1 or 2", "whole number"))
    if not any(k == "pressure_limited" for k, _, _ in act):
        act.append(("pressure_limited", "true or false", "optional"))
    out["actuator"] = act
    out["structure"] = [("load_stiffness", _si("stiffness"), "positive"), ("load_damping_ratio", "1", "optional"),
                        ("load_stiffness_yaw", _si("stiffness"), "optional, positive")]
    out["friction"] = [("model", "name", ""), ("parameter_set", "path", "shared set")] + friction_keys()
    out["avionics"] = [("quantization_bits", "bits", "0 to 32"), ("command_range", _si("angle"), "positive"),
                       ("rounding", "'truncate' / 'round'", ""), ("crossover_command", f"list, {_si('angle')}", ""),
                       ("crossover_gain", "list, 1", "")]
    out["gimbal"] = [(k, "", "") for k in sorted(M3.GIMBAL_KEYS)]
    out["geometry"] = [(k, "", "") for k in sorted(M3.GEOMETRY_KEYS)]
    return out


def friction_keys() -> list[tuple[str, str, str]]:
    """(key, SI unit, laws that use it) over the friction registry: each law's parameter class
    declares its model-file keys and units in its fields' metadata (taos.friction.param)."""
    import dataclasses

    from taos.friction import ids, params_of
    kinds: dict[str, str] = {}
    users: dict[str, list[str]] = {}
    for law_id in ids():
        for f in dataclasses.fields(params_of(law_id)):
            key = f.metadata["key"]
            kinds.setdefault(key, f.metadata["kind"])
            users.setdefault(key, []).append(law_id)
    return [(key, _si(kinds[key]), ", ".join(users[key])) for key in sorted(kinds)]


def friction_key_meanings() -> dict[str, str]:
    """``[friction]`` key -> meaning, from the friction registry: ``model`` lists the law ids
    (:func:`taos.friction.ids`), every other key has the meaning its law declares
    (``taos.friction.param(..., meaning=...)``; the first law declaring a shared key says it)."""
    import dataclasses

    from taos.friction import ids, params_of
    out = {"model": "friction law: " + ", ".join(ids()) + " (the ids of `taos.friction.ids()`)"}
    for law_id in ids():
        for f in dataclasses.fields(params_of(law_id)):
            if f.metadata.get("meaning"):
                out.setdefault(f.metadata["key"], f.metadata["meaning"])
    return out


def flight_key_table() -> dict[str, list[tuple[str, str, str]]]:
    from taos.flight import vehicle as V
    veh = [(k, unit, chk) for k, (_f, unit, chk) in V._VEHICLE_KEYS.items()]
    veh.insert(3, ("engine_count", "whole number", "positive"))
    fcs = [(k, unit, chk) for k, (_f, unit, chk) in V._FCS_KEYS.items()] + [("pade_order", "0 to 6", "")]
    return {"vehicle": veh, "fcs": fcs}


def _example(doc: dict, section: str, key: str) -> str:
    v = doc.get(section, {}).get(key)
    if v is None:
        return ""
    if isinstance(v, list):
        return "[" + ", ".join(str(x) for x in v) + "]"
    return str(v)


def _table(section: str, rows, doc: dict, example_file: str, missing: list[str]) -> list[str]:
    out = ["| key | SI unit / type | note (friction: laws that use it) | example | meaning |", "|---|---|---|---|---|"]
    from_laws = friction_key_meanings() if section == "friction" else {}
    for key, unit, note in rows:
        meaning = MEANINGS.get(f"{section}.{key}") or from_laws.get(key)
        if meaning is None:
            missing.append(f"{section}.{key}")
            meaning = ""
        ex = _example(doc, section, key)
        unit_md = f"`{unit}`" if any(c in unit for c in "*_^") else unit
        out.append(f"| `{key}` | {unit_md} | {note} | {('`' + ex + '`') if ex else ''} | {meaning} |")
    return out


def model_keys_markdown(missing: list[str]) -> str:
    """The model-file and flight-file key tables; keys without a meaning go to ``missing``."""
    from taos.shipped import models_dir
    mdir = models_dir()
    doc = tomllib.loads((mdir / "rs25_hotfire.toml").read_text(encoding="utf-8"))
    lines = ["## TVC model files (`models/rs25_*.toml`)\n",
             "Every value is a string with its unit (any unit pint converts to the SI unit shown); "
             "plain numbers only where the unit is 1. Examples from `models/rs25_hotfire.toml`.\n"]
    for section, rows in model_key_table().items():
        lines.append(f"### {SECTION_TITLES[section]}\n")
        lines += _table(section, rows, doc, "rs25_hotfire", missing)
        lines.append("")
    fdoc = tomllib.loads((mdir / "flight" / "core_stage.toml").read_text(encoding="utf-8"))
    lines += ["## Flight files (`models/flight/*.toml`)\n",
              "Top-level keys `name`, `description`, `axis` (pitch or yaw), `tvc_model` (the TVC model "
              "file it pairs with, relative to the flight file, else to the shipped `models/flight/`: the one rule "
              "of file references, below). Examples from `models/flight/core_stage.toml`.\n"]
    for section, rows in flight_key_table().items():
        lines.append(f"### [{section}]\n")
        lines += _table(section, rows, fdoc, "core_stage", missing)
        lines.append("")
    return "\n".join(lines)


def stale_meanings() -> list[str]:
    """Meanings of keys the code no longer has."""
    have = {f"{s}.{k}" for s, rows in {**model_key_table(), **flight_key_table()}.items() for k, _u, _n in rows}
    return sorted(set(MEANINGS) - have)
