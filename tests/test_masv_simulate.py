"""MASV nonlinear time domain (masv.timedomain, masv.simulate): one engine on a rigid structure is `taos simulate`;
friction, avionics and limits off, sine dwells are the linear MASV frequency response; the
structure's energy balance closes; the command line writes the run with provenance."""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import numpy as np
import pytest

from masv.cli import main
from masv.config import ActuatorSpec, EngineSpec, load_config, make_config
from masv.timedomain import simulate
from masv.system import build_system
from taos.model import load_model
from taos.planar.simulate import simulate as taos_simulate
from taos.profiles import SineDwell, load_profile

from .test_masv_nengine import config, write_npz

ROOT = Path(__file__).resolve().parents[1]


def test_one_engine_on_a_rigid_structure_is_taos_simulate():
    m = load_model(ROOT / "models" / "rs25_hotfire.toml").with_values({"structure.load_damping_ratio": 0.0})
    cfg = make_config([EngineSpec("e1", m, "gimbal_1", (0.0, 0.0, 0.0))],
                      [ActuatorSpec("a1", "e1", "pitch", "actuator_1_pitch", (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0))])
    p = load_profile(ROOT / "models" / "profiles" / "step_pitch.toml")
    h = simulate(cfg, p, duration_s=2.0)
    ref = taos_simulate(m, p, duration_s=2.0, threads=1)
    scale = np.abs(ref.engine_rad[0]).max()
    assert np.abs(h.engine_rad[0] - ref.engine_rad[0]).max() <= 1e-9 * scale
    assert np.abs(h.piston_m[0] - ref.piston_m[0]).max() <= 1e-9 * np.abs(ref.piston_m[0]).max()
    assert np.abs(h.gimbal_torque_Nm[0] - ref.friction_torque_Nm[0]).max() <= 1e-6 * np.abs(
        ref.friction_torque_Nm[0]).max()
    assert np.allclose(h.friction_state_rad[0], ref.friction_state_rad[0], rtol=0, atol=1e-12)
    assert h.provenance["engines"]["e1"]["model_sha256"] == m.sha256


def _fourier(y, t, f):
    return 2 * np.mean(y * np.exp(-2j * math.pi * f * t))


@pytest.mark.parametrize("f_hz", [2.0, 9.0])
def test_linear_limit_sine_dwell_equals_masv_freqresp(tmp_path, f_hz):
    write_npz(tmp_path / "beam.npz", 2)
    cfg = load_config(config(tmp_path, 2, "beam.npz"))
    amp, settle, meas = 1e-3, 3.0, 1.0
    dwell = SineDwell(amp, f_hz, cycles=int(round((settle + meas) * f_hz)))
    dt = 1.0 / (f_hz * round(1.0 / (f_hz * 1e-4)))     # <= 1e-4 s (the bar's top mode), whole steps a cycle
    h = simulate(cfg, {"actuator_1": dwell}, duration_s=dwell.duration_s, dt_s=dt, record_every=1,
                 friction="none", avionics=False, limits=False)
    sel = h.t_s >= dwell.duration_s - meas - 1e-12
    sel[-1] = False
    _, th = build_system(load_config(config(tmp_path, 2, "beam.npz"))).frf([f_hz])
    for i in range(2):
        got = _fourier(h.engine_rad[i, sel], h.t_s[sel], f_hz) / (-1j * amp)     # sin = Im e^{jwt}
        ref = th[0, i, 0]
        assert abs(20 * math.log10(abs(got) / abs(ref))) < 0.05
        assert abs(math.degrees(np.angle(got / ref))) < 0.5


def test_structure_energy_balance_closes_without_damping(tmp_path):
    write_npz(tmp_path / "beam.npz", 2)
    cfg = load_config(config(tmp_path, 2, "beam.npz", damping="0.0"))
    p = SineDwell(2e-3, 6.0, cycles=6)
    h = simulate(cfg, {"actuator_1": p, "actuator_2": SineDwell(-1e-3, 4.0, cycles=4)}, duration_s=1.2,
                 dt_s=1e-4, record_every=1, friction="none")
    st = cfg.structure
    w = st.omega_rad_s
    E = 0.5 * (np.sum(h.modal_qdot ** 2, axis=0) + np.sum((w[:, None] * h.modal_q) ** 2, axis=0))
    # generalised force: the load paths push the tip (e_k = u_tip) with F_L,k
    tip = st.phi[:, st.node_index("tip"), 0]
    P = np.sum(h.load_force_N, axis=0) * (tip @ h.modal_qdot)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(h.t_s))])
    assert E.max() > 1.0
    assert np.abs(E - work).max() < 1e-4 * E.max()


def test_masv_simulate_cli_writes_the_run(tmp_path, capsys):
    write_npz(tmp_path / "beam.npz", 2)
    c = config(tmp_path, 2, "beam.npz")
    prof = tmp_path / "p.toml"
    prof.write_text((ROOT / "models" / "profiles" / "step_pitch.toml").read_text())
    out = tmp_path / "run.h5"
    assert main(["simulate", str(c), "--profile", str(prof), "--out", str(out), "--duration", "0.5",
                 "--actuator-profile", f"actuator_2={prof}", "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["provenance"]["engine"] == "masv-nonlinear" and d["provenance"]["config_sha256"]
    with h5py.File(out) as f:
        assert f["actuators/actuator_1/engine_rad"].shape == f["t_s"].shape
        assert f["modes/q"].shape[0] == 8
    bad = tmp_path / "bad.h5"
    assert main(["simulate", str(c), "--profile", str(prof), "--out", str(bad),
                 "--actuator-profile", "nope=" + str(prof)]) == 2
    assert not bad.exists()
