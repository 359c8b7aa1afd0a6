"""Frame elements against beam vibration theory; thrust-structure modes and the MASV file contract."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from taos.fem import load_thrust_structure_modes, node_names, thrust_structure_modes
from taos.fem.frame import Frame, frame_modes, tube_section
from taos.fem.thrust_structure import ThrustStructureSpec, build_thrust_structure

ROOT = Path(__file__).resolve().parents[1]


def cantilever(L=2.0, n=20):
    sec = tube_section("t", 0.1, 0.005, 70e9, 26e9, 2700.0)
    fr = Frame()
    a, b = fr.node((0, 0, 0)), fr.node((L, 0, 0))
    fr.member(a, b, sec, L / n, up=(0, 0, 1))
    fr.fixed.add(a)
    return fr, sec


def test_cantilever_first_bending_frequency_matches_euler_bernoulli():
    fr, sec = cantilever()
    m = frame_modes(fr, 400.0)
    f1 = 1.875104 ** 2 / (2 * np.pi) * np.sqrt(sec.E_Pa * sec.Iy_m4 / (sec.rho_kg_m3 * sec.A_m2 * 2.0 ** 4))
    assert m.freq_hz[0] == pytest.approx(f1, rel=1e-3)
    assert m.freq_hz[1] == pytest.approx(f1, rel=1e-3)  # the other bending plane


def test_cantilever_first_torsion_frequency_matches_wave_solution():
    fr, sec = cantilever()
    m = frame_modes(fr, 1000.0)
    ft = np.sqrt(sec.G_Pa / sec.rho_kg_m3) / (4 * 2.0)
    assert np.min(np.abs(m.freq_hz - ft)) / ft < 2e-3


def test_modes_are_unit_modal_mass():
    spec = ThrustStructureSpec()
    fr = build_thrust_structure(spec)
    K, M, free = fr.assemble()
    m = frame_modes(fr, spec.f_max_hz)
    V = m.phi.reshape(m.phi.shape[0], -1).T[free]
    Mf, Kf = M[free][:, free], K[free][:, free]
    assert np.allclose(V.T @ (Mf @ V), np.eye(V.shape[1]), atol=1e-8)
    assert np.allclose(V.T @ (Kf @ V), np.diag((2 * np.pi * m.freq_hz) ** 2), rtol=1e-6, atol=1e-3)


def test_engine_section_local_modes_lie_between_10_and_50_hz():
    m = thrust_structure_modes()
    assert m.freq_hz.size >= 3
    assert 10.0 < m.freq_hz[0] < 50.0 and m.freq_hz[-1] <= 50.0
    assert np.all(m.damping_ratio == 0.005)


def test_shipped_mode_file_meets_the_masv_contract():
    d = load_thrust_structure_modes(ROOT / "fem_data" / "thrust_structure_modes.npz")
    n = d["freq_hz"].size
    assert list(d["node_names"]) == node_names()
    assert d["node_names"][0] == "gimbal_1" and d["node_names"][-1] == "actuator_4_yaw"
    assert d["phi"].shape == (n, 12, 6) and d["node_xyz_m"].shape == (12, 3)
    assert np.allclose(d["damping_ratio"], 0.005)
    # gimbal points on a 3.0 m square, aft of the cross-beams; actuators 0.8 m from the engine stations
    g = d["node_xyz_m"][:4]
    assert np.allclose(np.abs(g[:, 1:]), 1.5) and np.all(g[:, 0] < 0)
    for k in range(4):
        for j in (4 + 2 * k, 5 + 2 * k):
            assert np.linalg.norm(d["node_xyz_m"][j, 1:] - g[k, 1:]) == pytest.approx(0.8)
    assert (ROOT / "fem_data" / "thrust_structure_modes.toml").exists()


def test_shipped_modes_reproduce_from_the_generator():
    d = load_thrust_structure_modes(ROOT / "fem_data" / "thrust_structure_modes.npz")
    m = thrust_structure_modes()
    assert np.allclose(d["freq_hz"], m.freq_hz, rtol=1e-8)
    # compare mode shapes basis-free within groups of repeated frequencies (symmetric structure):
    # the projector V V^T of each group is unique
    f = m.freq_hz
    groups, start = [], 0
    for k in range(1, f.size + 1):
        if k == f.size or f[k] > f[k - 1] * (1 + 1e-6):
            groups.append(slice(start, k))
            start = k
    for g in groups:
        A = d["phi"][g].reshape(g.stop - g.start, -1)
        B = m.phi[g].reshape(g.stop - g.start, -1)
        assert np.allclose(A.T @ A, B.T @ B, atol=1e-8 * np.abs(B).max() ** 2)
