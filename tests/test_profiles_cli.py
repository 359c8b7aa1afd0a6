"""Command profiles and the simulate / freqresp command line."""

from __future__ import annotations

import json
import math

import h5py
import numpy as np
import pytest

from taos.errors import InputError
from taos.profiles import Circular, Multisine, SineSweep, load_profile

from .conftest import MODELS, run_cli

DEG = math.pi / 180


def test_schroeder_multisine_has_low_crest_factor():
    """Schroeder phases keep the crest factor of a flat multisine near sqrt(2) (Schroeder 1970)."""
    f = tuple(0.1 * k for k in range(1, 21))
    ms = Multisine(0.4 * DEG, f, 10.0)
    t = np.linspace(0, 10, 200001)
    y = ms(t)
    assert np.max(np.abs(y)) == pytest.approx(0.4 * DEG, rel=1e-3)
    crest = np.max(np.abs(y)) / np.sqrt(np.mean(y ** 2))
    assert crest < 2.0   # zero phases would give sqrt(2 N) = 6.3


def test_log_sweep_instantaneous_frequency():
    sw = SineSweep(1.0, 0.1, 10.0, 20.0)
    t = np.linspace(0, 20, 400001)
    y = sw(t)
    zc = t[1:][np.diff(np.signbit(y)) != 0]
    f_inst = 0.5 / np.diff(zc)
    t_mid = 0.5 * (zc[1:] + zc[:-1])
    expect = 0.1 * np.exp(np.log(100) * t_mid / 20)
    assert np.max(np.abs(f_inst / expect - 1)[t_mid > 2]) < 0.02


def test_circular_profile_is_two_axis():
    c = Circular(0.4 * DEG, 1.0, 4)
    y = c(np.linspace(1, 3, 1001))
    np.testing.assert_allclose(np.hypot(y[0], y[1]), 0.4 * DEG, rtol=1e-12)


def test_shipped_profiles_load():
    gr = load_profile(MODELS / "profiles" / "greenrun_two_axis.toml")
    t = np.linspace(0, gr.duration_s, 100001)
    y = gr(t)
    assert y.shape[0] == 2 and np.degrees(np.abs(y).max()) == pytest.approx(0.8, rel=1e-3)
    for name in ("step_pitch", "multiramp_pitch", "circular"):
        assert load_profile(MODELS / "profiles" / f"{name}.toml").duration_s > 0


def test_bad_profile_names_field(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text('type = "sine_dwell"\namplitude = "0.4 deg"\nfrequency = "1 m"\n')
    with pytest.raises(InputError, match="profile.frequency: expected a frequency"):
        load_profile(p)


def test_simulate_cli_writes_hdf5_with_provenance(tmp_path):
    out = tmp_path / "run.h5"
    r = run_cli("simulate", MODELS / "rs25_hotfire.toml", "--profile", MODELS / "profiles" / "circular.toml",
                "--out", out)
    assert r.returncode == 0, r.stderr
    with h5py.File(out) as h5:
        assert h5.attrs["axes"] == "pitch,yaw"
        assert len(h5.attrs["model_sha256"]) == 64
        assert json.loads(h5.attrs["solver"])["dt_s"] == 2e-4
        assert h5.attrs["package_version"]
        eng = h5["pitch/engine_rad"][()]
        assert np.all(np.isfinite(eng)) and np.degrees(np.abs(eng).max()) > 0.2


def test_freqresp_cli_json_contract():
    r = run_cli("freqresp", MODELS / "rs25_ambient.toml", "--freq-hz", "0.1,0.5,1,2,5", "--amplitude-deg", "0.4",
                "--friction", "dahl", "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["freq_hz"] == [0.1, 0.5, 1, 2, 5] and d["amplitude_deg"] == pytest.approx(0.4)
    for key in ("piston", "engine"):
        assert len(d[key]["gain_db"]) == 5 and len(d[key]["phase_deg"]) == 5
    lin = json.loads(run_cli("freqresp", MODELS / "rs25_ambient.toml", "--freq-hz", "1", "--linear",
                             "--json", "-").stdout)
    assert lin["amplitude_deg"] is None


def test_freqresp_bad_frequency_list(tmp_path):
    out = tmp_path / "f.json"
    r = run_cli("freqresp", MODELS / "rs25_ambient.toml", "--freq-hz", "1,abc", "--json", out)
    assert r.returncode == 2 and "--freq-hz" in r.stderr and not out.exists()


@pytest.mark.slow
def test_engine_taos_on_the_command_line(tmp_path):
    """--engine taos: the 3-D model's linear response has the hot-fire notch, and simulate writes
    the 3-D extras (bearing slip, gimbal-half deflections) beside the common arrays."""
    r = run_cli("freqresp", MODELS / "rs25_hotfire.toml", "--freq-hz", "1,6.93,10", "--engine", "taos", "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["piston"]["gain_db"][1] < d["piston"]["gain_db"][0] - 20
    out = tmp_path / "t.h5"
    r = run_cli("simulate", MODELS / "rs25_hotfire.toml", "--engine", "taos", "--profile",
                MODELS / "profiles" / "circular.toml", "--out", out)
    assert r.returncode == 0, r.stderr
    with h5py.File(out) as h5:
        assert h5.attrs["engine"] == "taos" and "bearing_slip_rad" in h5["taos"]
        assert np.all(np.isfinite(h5["yaw/engine_rad"][()]))
