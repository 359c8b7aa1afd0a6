"""MASV files and command line: modal-file and config validation (one-line InputError, exit 2),
the ``masv freqresp`` JSON contract, and a config round trip through a modal file."""

from __future__ import annotations

import dataclasses
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

from masv.cli import main
from masv.config import load_config
from masv.structure import NODE_NAMES, load_modes
from masv.synthetic import synthetic_structure
from taos.errors import InputError

from . import _forkserver

ROOT = Path(__file__).resolve().parents[1]
RIGID = ROOT / "models" / "masv" / "core_stage_rigid.toml"


def write_modes(path, **override):
    st = synthetic_structure(n_internal=1, n_modes=20)
    d = {"freq_hz": st.freq_hz, "damping_ratio": st.damping_ratio, "node_names": np.array(NODE_NAMES),
         "node_xyz_m": st.node_xyz_m, "phi": st.phi}
    d.update(override)
    d = {k: v for k, v in d.items() if v is not None}
    np.savez(path, **d)
    return st


def config_text(modes="modes.npz", extra=""):
    text = (RIGID.read_text().replace('modes = "rigid"', f'modes = "{modes}"\n{extra}')
            .replace('model = "../rs25_hotfire.toml"', f'model = "{(ROOT / "models" / "rs25_hotfire.toml").as_posix()}"'))
    return text


@pytest.mark.parametrize("override,field", [
    ({"freq_hz": np.r_[np.nan, np.ones(19)]}, "freq_hz"),
    ({"freq_hz": -np.ones(20)}, "freq_hz"),
    ({"phi": np.zeros((20, 12, 3))}, "phi"),
    ({"node_names": np.array(["gimbal_1"] * 12)}, "node_names"),
    ({"node_names": np.array([n.replace("gimbal_4", "gimbal_9") for n in NODE_NAMES])}, "node_names"),
    ({"damping_ratio": np.ones(3)}, "damping_ratio"),
    ({"node_xyz_m": None}, "node_xyz_m"),
])
def test_bad_modal_file_is_one_line_input_error(tmp_path, override, field):
    p = tmp_path / "modes.npz"
    write_modes(p, **override)
    with pytest.raises(InputError) as e:
        load_modes(p, required_nodes=NODE_NAMES)   # the SLS layout's nodes (a configuration names its own)
    assert e.value.field == field and "\n" not in str(e.value)


def test_config_with_modal_file_round_trip(tmp_path):
    st = write_modes(tmp_path / "modes.npz")
    (tmp_path / "c.toml").write_text(config_text(extra='damping_ratio = 0.01\nmax_frequency = "100 Hz"'))
    cfg = load_config(tmp_path / "c.toml")
    assert cfg.structure.n_modes == int(np.sum(st.freq_hz <= 100.0))
    assert np.all(cfg.structure.damping_ratio == 0.01)
    a = cfg.actuators[0]   # rotation axis from the geometry: (attach - gimbal) x direction
    assert np.allclose(a.rotation_axis, [0.0, -1.0, 0.0])
    # engine c.g.: the model's [geometry] engine_cg (0, 0, -1.5 m) placed 1.5 m aft (-x); the
    # FEM-style default adds the engine mass at the gimbal
    assert np.allclose(cfg.engines[0].cg_vector_m, [-1.5, 0.0, 0.0]) and not cfg.structure.engine_mass_in_modes
    text = config_text(extra="engine_mass_in_modes = true").replace(
        'gimbal_node = "gimbal_1"', 'gimbal_node = "gimbal_1"\ncg_offset = ["-1.2 m", "0 m", "0.1 m"]')
    (tmp_path / "c.toml").write_text(text)
    cfg = load_config(tmp_path / "c.toml")
    assert np.allclose(cfg.engines[0].cg_vector_m, [-1.2, 0.0, 0.1]) and cfg.structure.engine_mass_in_modes


@pytest.mark.parametrize("edit,field", [
    (lambda t: t.replace('axis = "yaw"', 'axis = "roll"', 1), "actuator[1].axis"),
    (lambda t: t.replace('high = "20 Hz"', 'high = "20 m"'), "band.high"),
    (lambda t: t.replace('engine = "engine_2"', 'engine = "engine_7"', 1), "actuator[2].engine"),
    (lambda t: t.replace("direction = [-1.0, 0.0, 0.0]", "direction = [0.0, 0.0, 0.0]", 1), "actuator[0].direction"),
    (lambda t: t.replace('attach_node = "actuator_1_yaw"', 'attach_node = "nowhere"'), "actuator[1].attach_node"),
    (lambda t: t.replace("damping_ratio = 0.005", "damping_ratio = -1"), "structure.damping_ratio"),
    (lambda t: t.replace("damping_ratio = 0.005", 'damping_ratio = 0.005\nengine_mass_in_modes = "yes"'),
     "structure.engine_mass_in_modes"),
    (lambda t: t.replace('gimbal_node = "gimbal_1"', 'gimbal_node = "gimbal_1"\ncg_offset = ["-1.5 m", "0 m"]'),
     "engine[0].cg_offset"),
    (lambda t: t.replace('gimbal_node = "gimbal_2"', 'gimbal_node = "gimbal_2"\ncg_offset = ["-1.5 s", "0 m", "0 m"]'),
     "engine[1].cg_offset[0]"),
])
def test_bad_config_is_one_line_input_error(tmp_path, edit, field):
    write_modes(tmp_path / "modes.npz")
    (tmp_path / "c.toml").write_text(edit(config_text(extra="damping_ratio = 0.005")))
    with pytest.raises(InputError) as e:
        load_config(tmp_path / "c.toml")
    assert e.value.field == field and "\n" not in str(e.value)


def test_cli_freqresp_json_contract(capsys):
    assert main(["freqresp", str(RIGID), "--freq-hz", "0.5,7,12", "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["freq_hz"] == [0.5, 7.0, 12.0] and len(d["actuators"]) == 8
    for part in ("piston", "engine"):
        g = np.asarray(d[part]["gain_db"])
        assert g.shape == (8, 8, 3) and np.asarray(d[part]["phase_deg"]).shape == (8, 8, 3)
    assert d["piston"]["gain_db"][0][1] == [-400.0] * 3   # rigid structure: no coupling


def test_cli_bad_input_exits_2_with_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(RIGID.read_text().replace('low = "0.5 Hz"', 'low = "fast"'))
    # python -m masv.cli as a new process (forked from the test process's fork server, tests/_forkserver.py)
    r = _forkserver.run([sys.executable, "-m", "masv.cli", "coupling", str(bad)], os.getcwd(), timeout=None)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "band.low" in r.stderr


def test_cli_modes_and_coupling_with_modal_file(tmp_path, capsys):
    write_modes(tmp_path / "modes.npz")
    (tmp_path / "c.toml").write_text(config_text())
    assert main(["modes", str(tmp_path / "c.toml"), "--json", str(tmp_path / "m.json")]) == 0
    m = json.loads((tmp_path / "m.json").read_text())
    assert m["n_modes"] == 20 and "near_bandwidth" in m
    assert main(["coupling", str(tmp_path / "c.toml"), "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["closed_loop"]["stable"] is True and len(d["margins"]["loops"]) == 8


@pytest.mark.slow
def test_plots_save_png(tmp_path):
    from masv import analysis as an
    from masv.config import load_config
    from masv.plotting import plot_actuator_vs_simplex, plot_coupling_matrix, plot_gain_grid, save
    from masv.system import build_system
    from taos.planar.freqresp import linear_freqresp

    s = build_system(load_config(RIGID))
    f = np.logspace(-1, 1.5, 30)
    fr = an.frequency_response(s, f)
    # the grid of engine 1's two actuators (2 x 2 panels, coupling included): the same drawing code
    # as the whole 8 x 8 grid at a sixteenth of its matplotlib cost
    two = dataclasses.replace(fr, actuators=fr.actuators[:2], piston=fr.piston[:, :2, :2], engine=fr.engine[:, :2, :2])
    save(plot_gain_grid(two, kind="piston"), tmp_path / "grid.png")
    model = s.config.engines[0].model
    save(plot_actuator_vs_simplex(fr, "actuator_1_pitch", linear_freqresp(model, f, "pitch")), tmp_path / "one.png")
    save(plot_coupling_matrix(an.coupling(s, n_freq=20)), tmp_path / "c.svg")
    assert all((tmp_path / n).stat().st_size > 1000 for n in ("grid.png", "one.png", "c.svg"))


def test_cli_modes_lists_the_shipped_structure_modes_in_the_files_band(tmp_path, capsys):
    """Issue 17: ``masv modes models/masv/core_stage.toml`` printed an empty table (its 14.548 Hz
    pair fell outside bandwidth x/÷ 2 and the file's [band] was ignored)."""
    import tomllib

    shipped = ROOT / "models" / "masv" / "core_stage.toml"
    meta = tomllib.loads((ROOT / "fem_data" / "thrust_structure_modes.toml").read_text())["modes"]["freq_hz"]
    assert main(["modes", str(shipped)]) == 0
    out = capsys.readouterr().out
    rows = [ln.split() for ln in out.splitlines()[2:]]
    assert [float(r[1]) for r in rows] == pytest.approx(meta, abs=1e-3)       # every shipped mode listed
    assert [r[4] for r in rows] == ["yes", "yes", "no", "no", "no"]           # in the file's 0.5-20 Hz band
    assert main(["modes", str(shipped), "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)["near_bandwidth"]
    assert d["band_hz"] == [0.5, 20.0] and d["band_source"] == "config [band]"
    assert [m["freq_hz"] for m in d["modes"]] == pytest.approx(meta[:2], abs=1e-3)
    # another [band] selects other modes
    text = shipped.read_text().replace('low = "0.5 Hz"', 'low = "15 Hz"').replace('high = "20 Hz"', 'high = "30 Hz"')
    text = text.replace('"../../fem_data/', f'"{(ROOT / "fem_data").as_posix()}/').replace(
        '"../rs25_hotfire.toml"', f'"{(ROOT / "models" / "rs25_hotfire.toml").as_posix()}"')
    (tmp_path / "c.toml").write_text(text)
    assert main(["modes", str(tmp_path / "c.toml"), "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)["near_bandwidth"]
    assert [m["freq_hz"] for m in d["modes"]] == pytest.approx(meta[2:4], abs=1e-3)


def test_cli_tvse_rigid_has_no_loop_and_json(tmp_path, capsys):
    assert main(["tvse", str(RIGID), "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["tvse"]) == 8
    assert all(r["margin"]["gain_margin_db"] is None and r["margin"]["phase_margin_deg"] is None for r in d["tvse"])


def test_cli_tvse_plot_of_the_shipped_core_stage(tmp_path, capsys):
    shipped = ROOT / "models" / "masv" / "core_stage.toml"
    assert main(["tvse", str(shipped), "--plot", str(tmp_path / "tvse.png")]) == 0
    out = capsys.readouterr().out
    assert out.count("peak +") == 8 and (tmp_path / "tvse.png").stat().st_size > 1000
