"""MASV physics checks: reduction to the simplex model, series load path, mirror symmetry,
modal truncation, identity of the fast and dense frequency responses, loop margins."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from masv import analysis as an
from masv.config import ActuatorSpec, EngineSpec, make_config
from masv.structure import NODE_NAMES, ModalStructure, rigid_structure
from masv.synthetic import core_stage_specs, synthetic_structure
from masv.system import build_system
from taos.model import Structure, load_model
from taos.planar.simplex import simplex_state_space

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def hotfire():
    return load_model(ROOT / "models" / "rs25_hotfire.toml")


@pytest.fixture(scope="module")
def sym_structure():
    return synthetic_structure(n_internal=3, seed=1)


@pytest.fixture(scope="module")
def sym_system(hotfire, sym_structure):
    e, a = core_stage_specs(hotfire, sym_structure)
    return build_system(make_config(e, a, sym_structure, band_hz=(0.5, 20.0)))


def one_engine(model, axis="pitch", structure=None):
    e = EngineSpec("engine_1", model, "gimbal_1")
    a = ActuatorSpec(f"actuator_1_{axis}", "engine_1", axis, f"actuator_1_{axis}", (-1.0, 0.0, 0.0),
                     (0.0, 1.0, 0.0))
    return build_system(make_config([e], [a], structure))


@pytest.mark.parametrize("axis", ["pitch", "yaw"])
def test_one_engine_on_rigid_structure_reproduces_simplex(hotfire, axis):
    # MASV's load path carries no structural damping of its own (its modes carry modal damping):
    # compare with the simplex with the load-path damping (issue 12.6) off
    model = hotfire.replace(engine=dataclasses.replace(hotfire.engine, inertia_yaw_kgm2=9000.0),
                            structure=dataclasses.replace(hotfire.structure, load_damping_ratio=0.0))
    s = one_engine(model, axis)
    f = np.logspace(-2, 2.5, 200)
    xp, th = s.frf(f)
    h = simplex_state_space(model, axis).freqresp(f, "command_rad", ["x_p_m", "theta_rad"])
    # one definition of the block (taos.planar.simplex): equal to rounding (measured 1.5e-15)
    assert np.max(np.abs(xp[:, 0, 0] / h[:, 0] - 1)) < 1e-13
    assert np.max(np.abs(th[:, 0, 0] / h[:, 1] - 1)) < 1e-13
    # the assembled state space has the simplex's poles
    p1 = np.sort_complex(s.state_space().poles())
    p2 = np.sort_complex(simplex_state_space(model, axis).poles())
    assert np.max(np.abs(p1 - p2) / np.abs(p2)) < 1e-12


def test_four_engines_on_rigid_structure_do_not_couple(hotfire):
    e, a = core_stage_specs(hotfire, synthetic_structure(n_internal=0))
    s = build_system(make_config(e, a, None))
    xp, th = s.frf([0.5, 7.0, 20.0])
    off = ~np.eye(8, dtype=bool)
    assert np.all(xp[:, off] == 0) and np.all(th[:, off] == 0)


def test_modal_spring_in_series_with_load_stiffness(hotfire):
    """One mode k, m at the attach point along the line of action: kept only as static flexibility
    it is a spring in series with K_L, so the response is the simplex's with K_L k/(K_L + k)."""
    KL = hotfire.structure.load_stiffness_N_per_m
    k, m = 2.0 * KL, 1.0
    phi = np.zeros((1, 12, 6))
    phi[0, NODE_NAMES.index("actuator_1_pitch"), 0] = 1.0 / math.sqrt(m)
    st = ModalStructure(np.array([math.sqrt(k / m) / (2 * math.pi)]), np.array([0.005]), NODE_NAMES,
                        np.zeros((12, 3)), phi)
    series = hotfire.replace(structure=Structure(KL * k / (KL + k)))
    f = np.logspace(-1, 1.5, 100)
    ref = simplex_state_space(series, "pitch").freqresp(f, "command_rad", "x_p_m")
    static = one_engine(hotfire, structure=st.truncated(0.0)).frf(f)[0][:, 0, 0]
    assert np.max(np.abs(static / ref - 1)) < 1e-9
    dynamic = one_engine(hotfire, structure=st).frf(f)[0][:, 0, 0]   # mode at ~1.4 kHz: nearly static
    assert np.max(np.abs(dynamic / ref - 1)) < 2e-3
    notch = an.notch_frequencies(one_engine(hotfire, structure=st))["actuator_1_pitch"]["notch_hz"]
    assert notch == pytest.approx(an.notch_frequencies(one_engine(series))["actuator_1_pitch"]["notch_hz"], rel=1e-3)


@pytest.mark.parametrize("mass_in_modes", [True, False])
def test_block_elimination_equals_dense_state_space(hotfire, sym_structure, mass_in_modes):
    """Also with the engines' mass added at the gimbals (the modal mass matrix is then full)."""
    st = dataclasses.replace(sym_structure.truncated(40.0), engine_mass_in_modes=mass_in_modes)
    e, a = core_stage_specs(hotfire, st)
    s = build_system(make_config(e, a, st))   # with static correction
    f = np.array([0.3, 3.0, 7.0, 8.5, 15.0, 33.0])
    xp, th = s.frf(f)
    xd, td = s.frf_dense(f)
    assert np.max(np.abs(xp - xd)) < 1e-10 * np.max(np.abs(xd))
    assert np.max(np.abs(th - td)) < 1e-10 * np.max(np.abs(td))


Y_MIRROR = [2, 3, 0, 1, 6, 7, 4, 5]   # engines 1<->2, 3<->4 (y -> -y)
Z_MIRROR = [6, 7, 4, 5, 2, 3, 0, 1]   # engines 1<->4, 2<->3 (z -> -z)


def test_mirror_symmetric_structure_gives_symmetric_responses(sym_system):
    f = np.logspace(np.log10(0.5), np.log10(20.0), 60)
    xp, th = sym_system.frf(f)
    for H in (xp, th):
        d = np.abs(np.diagonal(H, axis1=1, axis2=2))
        assert np.max(np.abs(d[:, 0::2] - d[:, [0]]) / d[:, [0]]) < 1e-9       # all pitch actuators alike
        assert np.max(np.abs(d[:, 1::2] - d[:, [1]]) / d[:, [1]]) < 1e-9       # all yaw actuators alike
        scale = np.max(np.abs(H), axis=(1, 2))[:, None, None]
        for p in (Y_MIRROR, Z_MIRROR):
            assert np.max(np.abs(H[:, p][:, :, p] - H) / scale) < 1e-9
        assert np.max(np.abs(H[:, ~np.eye(8, dtype=bool)])) > 1e-6 * scale.max()  # the engines do couple
    c = an.coupling(sym_system, n_freq=100)
    for p in (Y_MIRROR, Z_MIRROR):
        assert np.allclose(c.engine_peak_db[np.ix_(p, p)], c.engine_peak_db, atol=1e-6)


def test_modes_above_three_times_band_change_piston_in_band_by_less_than_half_db(hotfire, sym_structure):
    e, a = core_stage_specs(hotfire, sym_structure)
    band_hi = 20.0
    full = build_system(make_config(e, a, sym_structure))
    cut = build_system(make_config(e, a, sym_structure.truncated(3 * band_hi)))
    assert cut.omega_rad_s.size < full.omega_rad_s.size
    f = np.logspace(np.log10(0.5), np.log10(band_hi), 200)
    x_full, _ = full.frf(f)
    x_cut, _ = cut.frf(f)
    d = np.abs(20 * np.log10(np.abs(np.diagonal(x_cut, axis1=1, axis2=2) / np.diagonal(x_full, axis1=1, axis2=2))))
    assert d.max() < 0.5
    # off-diagonal terms to within 0.5 dB of the diagonal level
    lvl = np.abs(np.diagonal(x_full, axis1=1, axis2=2)).max(axis=1)[:, None, None]
    assert np.max(np.abs(x_cut - x_full) / lvl) < 10 ** (0.5 / 20) - 1


def test_gain_margin_predicts_the_loop_gain_that_destabilises(hotfire):
    """L = T/(1-T) is proportional to the loop gain K_v, so raising K_v by the gain margin puts a
    closed-loop pole on the imaginary axis at the phase-crossover frequency."""
    s = one_engine(hotfire)
    (lm,) = an.actuator_loop_margins(s)
    assert math.isfinite(lm.gain_margin_db) and lm.gain_margin_db > 0 and lm.phase_margin_deg > 0
    act = dataclasses.replace(hotfire.actuator, loop_gain_per_s=hotfire.actuator.loop_gain_per_s
                              * 10 ** (lm.gain_margin_db / 20))
    p = one_engine(hotfire.replace(actuator=act)).state_space().poles()
    i = np.argmin(np.abs(p.real))
    assert abs(p[i].real) < 1e-3 * abs(p[i])
    assert abs(p[i].imag) / (2 * math.pi) == pytest.approx(lm.phase_crossover_hz, rel=1e-3)


def test_synthetic_core_stage_loops_stable_and_report(sym_system):
    eig = an.closed_loop_eigenvalues(sym_system)
    assert eig.stable
    eff = an.structure_effect(sym_system)
    assert eff["worst_phase_margin_deg"] > 0 and eff["worst_gain_margin_db"] > 0
    mp = an.modes_near_bandwidth(sym_system)
    assert 3 < mp.bandwidth_hz < 15 and np.all(mp.compliance_ratio >= 0)
    c = an.coupling(sym_system, n_freq=50)
    assert c.strongest_engine_to_engine["gain_db"] < 0


def test_rigid_structure_has_no_modes():
    st = rigid_structure()
    assert st.n_modes == 0 and st.phi.shape == (0, 12, 6)


@pytest.mark.parametrize("axis", ["pitch", "yaw"])
def test_structure_turning_about_the_gimbal_is_the_simplex_with_the_two_body_inertia(hotfire, axis):
    """An independent check of the coupling kinematics (the elongation and the gimbal-rotation
    rows): one mode that is a rigid rotation psi of the structure about the gimbal, about the
    actuator's rotation axis a, with no restoring stiffness (0 Hz). Its shape is written here
    from rigid-body kinematics, not by the code under test: rot = a / sqrt(I_s) at every node and
    u_P = rot x (P - G) (mass-normalised: structure inertia I_s about the gimbal axis).

    Physics: the actuator (attached to the structure) and the feedline spring see only the
    engine's rotation relative to the structure, phi = theta - psi (F_L = K_L (x_p - R phi),
    spring torque K_n phi), and the two bodies react on each other: J theta'' = R F_L - K_n phi,
    I_s psi'' = -(R F_L - K_n phi). So phi obeys the simplex equations with the two-body
    inertia J I_s / (J + I_s), the piston response is that simplex's, and the engine's own angle
    is theta = phi I_s / (J + I_s) (angular momentum J theta' + I_s psi' = 0)."""
    model = hotfire.replace(structure=dataclasses.replace(hotfire.structure, load_damping_ratio=0.0))
    J = model.engine.inertia(axis)
    I_s = 0.7 * J                       # a light structure: a strong effect
    R = model.actuator.moment_arm_m
    a = np.array([0.0, 1.0, 0.0]) if axis == "pitch" else np.array([0.0, 0.0, 1.0])
    n = np.array([-1.0, 0.0, 0.0])      # line of action, structure attach -> engine attach
    # attach point P with (P - G) x n = R a: a rotation about a extends the actuator by R theta
    p_attach = np.cross(n, a) * R + np.array([2.0, 0.0, 0.0])
    assert np.allclose(np.cross(p_attach, n), R * a)
    xyz = np.array([[0.0, 0.0, 0.0], p_attach])
    rot = a / math.sqrt(I_s)
    phi = np.zeros((1, 2, 6))
    for j, p in enumerate(xyz):
        phi[0, j, 0:3] = np.cross(rot, p)   # u_P = rot x (P - G), G at the origin
        phi[0, j, 3:6] = rot
    st = ModalStructure(np.zeros(1), np.zeros(1), ("gimbal_1", "attach"), xyz, phi)
    eng = EngineSpec("engine_1", model, "gimbal_1", cg_offset_m=(0.0, 0.0, 0.0))
    act = ActuatorSpec(f"actuator_1_{axis}", "engine_1", axis, "attach", tuple(n), tuple(a))
    s = build_system(make_config([eng], [act], st))
    f = np.logspace(-1, 2.3, 150)
    xp, th = s.frf(f)
    two_body = model.replace(engine=dataclasses.replace(
        model.engine, **{f"inertia_{axis}_kgm2": J * I_s / (J + I_s)}))
    h = simplex_state_space(two_body, axis).freqresp(f, "command_rad", ["x_p_m", "theta_rad"])
    # measured 1.4e-14 and 4.2e-12 (block elimination), 1.2e-14 and 1.3e-12 (dense)
    assert np.max(np.abs(xp[:, 0, 0] / h[:, 0] - 1)) < 1e-13
    assert np.max(np.abs(th[:, 0, 0] / (h[:, 1] * I_s / (J + I_s)) - 1)) < 2e-11
    xd, td = s.frf_dense(f)               # the assembled state space: the same
    assert np.max(np.abs(xd[:, 0, 0] / h[:, 0] - 1)) < 1e-13
    assert np.max(np.abs(td[:, 0, 0] / (h[:, 1] * I_s / (J + I_s)) - 1)) < 1e-11
