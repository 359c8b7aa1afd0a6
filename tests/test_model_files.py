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
    assert ambient.friction.coulomb_torque_Nm == pytest.approx(144000 * 4.4482216152605 * 0.0254, rel=1e-9)
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
    for name in ("coulomb-switching", "coulomb-smooth", "dahl", "lugre", "none"):
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
