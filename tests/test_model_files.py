"""Model files: the model-file key contract, units through pint, and bad input."""

from __future__ import annotations

import json
import math
import tomllib

import pytest

from taos.errors import InputError
from taos.model import load_model
from taos.units import to_si

from .conftest import MODELS, run_cli

CONTRACT = {
    "engine": ["mass", "inertia_pitch", "inertia_yaw", "rotational_stiffness"],
    "actuator": ["moment_arm"],
    "structure": ["load_stiffness"],
    "friction": ["model", "coulomb_torque"],
    "avionics": ["quantization_bits", "command_range", "rounding"],
}


@pytest.mark.parametrize("name", ["rs25_ambient", "rs25_hotfire", "rs25_flight"])
def test_shipped_model_has_contract_keys(name):
    doc = tomllib.loads((MODELS / f"{name}.toml").read_text())
    for sec, keys in CONTRACT.items():
        for k in keys:
            assert k in doc[sec], f"{name}: [{sec}] {k}"
    m = load_model(MODELS / f"{name}.toml")
    assert m.sha256 and len(m.sha256) == 64


def test_public_figures_in_SI(ambient, hotfire):
    lbf_in = 4.4482216152605 / 0.0254
    assert ambient.structure.load_stiffness_N_per_m == pytest.approx(115000 * lbf_in, rel=1e-9)
    assert hotfire.structure.load_stiffness_N_per_m == pytest.approx(205000 * lbf_in, rel=1e-9)
    flight = load_model(MODELS / "rs25_flight.toml")  # the paper's bounding flight torque (sec. 3.2)
    assert flight.friction.coulomb_torque_Nm == pytest.approx(144000 * 4.4482216152605 * 0.0254, rel=1e-9)
    assert math.degrees(ambient.avionics.lsb_rad) == pytest.approx(0.005, rel=0.05)


def test_unit_parse_rejects_wrong_dimension():
    with pytest.raises(InputError) as e:
        to_si("115000 lbf", "stiffness", source="f.toml", field="structure.load_stiffness")
    assert "f.toml: structure.load_stiffness: expected a stiffness" in str(e.value)


def _broken(tmp_path, old, new):
    text = (MODELS / "rs25_ambient.toml").read_text()
    assert old in text
    p = tmp_path / "broken.toml"
    p.write_text(text.replace(old, new, 1))
    return p


BAD = [
    ('load_stiffness = "115000 lbf/in"', 'load_stiff = "115000 lbf/in"', "structure.load_stiff"),
    ('load_stiffness = "115000 lbf/in"', 'load_stiffness = "115000 lbf"', "structure.load_stiffness"),
    ('load_stiffness = "115000 lbf/in"', 'load_stiffness = "-115000 lbf/in"', "structure.load_stiffness"),
    ('model = "modified-lugre"', 'model = "stiction-magic"', "friction.model"),
    ('moment_arm = "0.8 m"', '', "actuator.moment_arm"),
]


@pytest.mark.parametrize("old,new,field", BAD, ids=["missing-key", "wrong-unit", "negative", "unknown-friction",
                                                      "missing-arm"])
def test_bad_model_file_one_line_exit_2_no_output(tmp_path, old, new, field):
    p = _broken(tmp_path, old, new)
    out = tmp_path / "info.json"
    r = run_cli("info", p, "--json", out)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert str(p) in lines[0] and field in lines[0] and "expected" in lines[0]
    assert not out.exists()
    sim_out = tmp_path / "run.h5"
    r = run_cli("simulate", p, "--profile", MODELS / "profiles" / "step_pitch.toml", "--out", sim_out)
    assert r.returncode == 2 and not sim_out.exists()


def test_unknown_friction_on_command_line(tmp_path):
    r = run_cli("info", MODELS / "rs25_ambient.toml", "--friction", "magic", "--json", "-")
    assert r.returncode == 2 and "--friction" in r.stderr and r.stdout == ""


def test_friction_swap_keeps_torque_levels(ambient):
    from taos.friction import ids

    for name in ids():
        law = ambient.with_friction(name).friction
        assert law.name == name
        assert law.coulomb_torque_Nm == ambient.friction.coulomb_torque_Nm


def test_info_json_contract():
    r = run_cli("info", MODELS / "rs25_ambient.toml", "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    for k in ("load_resonance_hz", "breakaway_deflection_deg", "oil_column_stiffness_N_per_m", "notch_frequency_hz"):
        assert isinstance(d[k], float)
    assert d["parameters"]["structure"]["load_stiffness_N_per_m"] > 0


RS25 = ["rs25_ambient", "rs25_hotfire", "rs25_flight"]


def test_one_friction_parameter_set_for_the_one_gimbal_bearing():
    """Issue 12.1: the ambient, hot-fire and flight files describe one gimbal bearing, so its law
    parameters (bristle stiffness and damping, Stribeck, vibration, regularisation) come from one
    shared file that none of them repeats, and every law built from the three files carries the
    same parameters; only the torque levels differ."""
    from taos.friction import LAWS
    docs = {n: tomllib.loads((MODELS / f"{n}.toml").read_text()) for n in RS25}
    shared = tomllib.loads((MODELS / "friction" / "rs25_gimbal.toml").read_text())["friction"]
    assert {"bristle_stiffness", "bristle_damping", "stribeck_velocity", "vibration_velocity",
            "regularization_velocity"} <= set(shared)
    for n, d in docs.items():
        assert d["friction"]["parameter_set"] == "friction/rs25_gimbal.toml", n
        assert not set(d["friction"]) & set(shared), n
    # the load-proportional parameters (torque-like: bristle stiffness and damping, viscous and
    # stick damping) scale with the torque level, as the 3-D model scales them with the normal
    # load; divided by the torque level they are one set, and the others are identical
    import dataclasses
    for law in LAWS:
        laws = [load_model(MODELS / f"{n}.toml", friction=law).friction for n in RS25]
        params = [{f.name: (getattr(x, f.name) / x.coulomb_torque_Nm if f.metadata["torque_like"]
                            else getattr(x, f.name)) for f in dataclasses.fields(x)} for x in laws]
        for a in params[1:]:
            assert a.keys() == params[0].keys() and all(a[k] == pytest.approx(params[0][k], rel=1e-12)
                                                        for k in a), law
    lugre = load_model(MODELS / "rs25_flight.toml", friction="lugre").friction
    assert lugre.bristle_stiffness_Nm_per_rad == pytest.approx(1.3e7)  # the Green Run value, at 144,000 in-lbf


def test_model_file_may_not_override_the_shared_friction_set(tmp_path):
    text = (MODELS / "rs25_flight.toml").read_text()
    p = tmp_path / "flight.toml"
    p.write_text(text.replace('parameter_set = "friction/rs25_gimbal.toml"',
                              f'parameter_set = "{(MODELS / "friction" / "rs25_gimbal.toml").as_posix()}"\n'
                              'bristle_stiffness = "2.2e7 N*m/rad"'))
    with pytest.raises(InputError) as e:
        load_model(p)
    assert "friction.bristle_stiffness" in str(e.value) and "parameter set" in str(e.value)


def test_one_actuator_parameter_set_for_the_one_servoactuator():
    """Issue 24: the three files describe one TVC servoactuator, so its hardware (piston, oil,
    servovalve, loop gain, dynamic pressure feedback, rate limit) comes from one shared file
    that none of them repeats; each keeps the installation key moment_arm (the DESIGN.md
    contract) and the modelling switch pressure_limited, which the set may not carry."""
    from taos.model import ACTUATOR_FILE_KEYS
    docs = {n: tomllib.loads((MODELS / f"{n}.toml").read_text()) for n in RS25}
    shared = tomllib.loads((MODELS / "actuators" / "tvc_actuator.toml").read_text())["actuator"]
    assert {"loop_gain", "pressure_feedback_gain", "pressure_feedback_time_constant", "piston_area",
            "flow_pressure_coefficient", "valve_natural_frequency"} <= set(shared)
    assert not set(shared) & ACTUATOR_FILE_KEYS
    for n, d in docs.items():
        assert d["actuator"]["parameter_set"] == "actuators/tvc_actuator.toml", n
        assert set(d["actuator"]) == {"parameter_set"} | ACTUATOR_FILE_KEYS, n
    acts = [load_model(MODELS / f"{n}.toml").actuator for n in RS25]
    assert acts[0] == acts[1] == acts[2]
    assert acts[0].loop_gain_per_s == 20.0 and acts[0].pressure_feedback_gain_m_per_s_Pa == pytest.approx(1e-8)


def test_model_file_may_not_override_the_shared_actuator_set(tmp_path):
    text = (MODELS / "rs25_hotfire.toml").read_text()
    p = tmp_path / "hot.toml"
    old = 'parameter_set = "actuators/tvc_actuator.toml"'
    assert old in text
    p.write_text(text.replace(old, old + '\nloop_gain = "40 1/s"'))
    with pytest.raises(InputError) as e:
        load_model(p)
    assert "actuator.loop_gain" in str(e.value) and "parameter set" in str(e.value)
    # a copied model file still finds the shipped set (relative to the shipped models folder)
    p.write_text(text)
    assert load_model(p).actuator == load_model(MODELS / "rs25_hotfire.toml").actuator
    # the set may not carry the installation: moment_arm stays in each model file
    bad = tmp_path / "set.toml"
    bad.write_text((MODELS / "actuators" / "tvc_actuator.toml").read_text() + 'moment_arm = "0.9 m"\n')
    p.write_text(text.replace(old, f'parameter_set = "{bad.as_posix()}"'))
    with pytest.raises(InputError) as e:
        load_model(p)
    assert "actuator.moment_arm" in str(e.value) and str(bad) in str(e.value)


@pytest.mark.parametrize("name", RS25)
def test_planar_friction_level_is_mu_N_rb_as_in_taos(name):
    """Issue 12.1: the planar torque level follows the bearing normal load exactly as the 3-D
    TAOS model computes it (mu N r_b; N the thrust, or the engine weight when hanging): the
    hanging ambient engine carries 1.5 % of the flight friction."""
    from taos.taos3d import load_taos_model
    m = load_model(MODELS / f"{name}.toml")
    t3 = load_taos_model(MODELS / f"{name}.toml")
    assert m.friction.coulomb_torque_Nm == pytest.approx(t3.coulomb_torque_Nm, rel=1e-3)
    assert m.friction.static_torque_Nm == pytest.approx(m.friction.coulomb_torque_Nm, rel=1e-12)
    g = tomllib.loads((MODELS / f"{name}.toml").read_text())["gimbal"]
    assert g["friction_coefficient"] == 0.0649 and g["bearing_radius"] == "0.110 m"
