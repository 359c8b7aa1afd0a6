"""MASV for N engines from FE results: a beam FE model written here (independent of MASV),
its modes as an .npz modal file, a Universal File 55 and a Nastran punch file in other unit
systems and frames; N = 1, 2, 6 engines sharing its tip give the closed-form coupling."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from masv.config import load_config
from masv.system import build_system
from taos.errors import InputError
from taos.model import load_model
from taos.planar.simplex import simplex_state_space

ROOT = Path(__file__).resolve().parents[1]
MODEL = (ROOT / "models" / "rs25_hotfire.toml").as_posix()
N_EL = 8                    # axial bar elements, fixed at x = 0, tip at x = L
L_M, EA_N, RHOA_KG_M = 6.0, 1.2e9, 80.0
TIP_MASS_KG = 20000.0
ALPHA, BETA = 0.4, 1.0e-5   # Rayleigh damping C = alpha M + beta K [1/s, s]
GRID0 = 100                 # FE grid ids: bar nodes 101.., grounded gimbal points 201..
IN_M, LBF_S2_IN_KG = 0.0254, 4.4482216152605 / 0.0254


def beam_fe():
    """Axial bar (linear elements, consistent mass) with a tip mass: free-DOF M, K [kg, N/m]."""
    le = L_M / N_EL
    n = N_EL + 1
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(N_EL):
        i = slice(e, e + 2)
        K[i, i] += EA_N / le * np.array([[1, -1], [-1, 1]])
        M[i, i] += RHOA_KG_M * le / 6 * np.array([[2, 1], [1, 2]])
    M[-1, -1] += TIP_MASS_KG
    return M[1:, 1:], K[1:, 1:]


def beam_modes():
    """Mass-normalised modes of the bar: freq [Hz], Rayleigh damping ratios, shapes (n, N_EL)."""
    M, K = beam_fe()
    w2, V = scipy.linalg.eigh(K, M)
    w = np.sqrt(w2)
    return w / (2 * math.pi), ALPHA / (2 * w) + BETA * w / 2, V.T


def tip_receptance(f_hz):
    """u_tip / F_tip [m/N] of the FE model itself (direct solve, no modes)."""
    M, K = beam_fe()
    out = []
    for f in np.atleast_1d(f_hz):
        w = 2 * math.pi * f
        out.append(np.linalg.solve(K - w * w * M + 1j * w * (ALPHA * M + BETA * K), np.eye(K.shape[0]))[-1, -1])
    return np.array(out)


def gimbal_names(n):
    return [f"gimbal_{e + 1}" for e in range(n)]


def gimbal_xyz(n):
    return [(0.0, 2.0 * math.cos(2 * math.pi * e / n), 2.0 * math.sin(2 * math.pi * e / n)) for e in range(n)]


def write_npz(path, n_eng):
    f, z, V = beam_modes()
    names = ["tip"] + gimbal_names(n_eng)
    phi = np.zeros((f.size, len(names), 6))
    phi[:, 0, 0] = V[:, -1]
    np.savez(path, freq_hz=f, damping_ratio=z, node_names=np.array(names),
             node_xyz_m=np.array([(L_M, 0.0, 0.0)] + gimbal_xyz(n_eng)), phi=phi)


def fe_shapes(n_eng, along=0):
    """Grid ids and shapes (n, G, 6) with the bar's axial motion on component ``along``."""
    f, z, V = beam_modes()
    ids = [GRID0 + i for i in range(1, N_EL + 1)] + [200 + e + 1 for e in range(n_eng)]
    phi = np.zeros((f.size, len(ids), 6))
    phi[:, :N_EL, along] = V
    return f, z, np.array(ids), phi


def write_uff(path, n_eng, gen_mass=4.0):
    """The modes in mm and tonne, axial along FE z, each shape scaled to generalised mass ``gen_mass``."""
    import pyuff
    f, z, ids, phi = fe_shapes(n_eng, along=2)
    phi = phi * math.sqrt(1000.0) * math.sqrt(gen_mass)   # mass-normalised in tonne, then m_i = gen_mass
    sets = []
    for i in range(f.size):
        d = {"type": 55, "model_type": 1, "analysis_type": 2, "data_ch": 2, "spec_data_type": 8, "data_type": 2,
             "n_data_per_node": 6, "load_case": 1, "mode_n": i + 1, "freq": f[i], "modal_m": gen_mass,
             "modal_damp_vis": z[i], "modal_damp_his": 0.0, "node_nums": ids.astype(float),
             "id1": "beam", "id2": "mode", "id3": "x", "id4": "x", "id5": "x"}
        d.update({f"r{c + 1}": phi[i, :, c] for c in range(6)})
        sets.append(d)
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")


def write_punch(path, n_eng):
    """The modes as Nastran punches them (EIGRL NORM=MASS) in inch and lbf s^2/in."""
    f, _, ids, phi = fe_shapes(n_eng, along=0)
    phi = phi * math.sqrt(LBF_S2_IN_KG)          # mass-normalised in lbf s^2/in (translations)
    lines = ["$TITLE   = BEAM", "$SUBTITLE=", "$LABEL   =", "$EIGENVECTOR", "$REAL OUTPUT", "$SUBCASE ID = 1"]
    for i in range(f.size):
        lines.append(f"$EIGENVALUE = {(2 * math.pi * f[i]) ** 2:14.7E}  MODE = {i + 1:5d}")
        for g in range(ids.size):
            t, r = phi[i, g, :3], phi[i, g, 3:]
            lines.append(f"{ids[g]:10d}       G     {t[0]:13.6E}     {t[1]:13.6E}     {t[2]:13.6E}")
            lines.append(f"-CONT-                  {r[0]:13.6E}     {r[1]:13.6E}     {r[2]:13.6E}")
    Path(path).write_text("\n".join(f"{ln:<72}{k + 1:8d}" for k, ln in enumerate(lines)) + "\n")


def config(tmp_path, n_eng, modes, structure_extra="", fe_nodes=False, damping='"file"'):
    lines = ['name = "beam"', "[structure]", f'modes = "{modes}"', f"damping_ratio = {damping}", structure_extra]
    if fe_nodes:
        lines.append("[structure.nodes]")
        lines.append(f'tip = {{grid = {GRID0 + N_EL}, xyz = ["{L_M} m", "0 m", "0 m"]}}')
        for e, (n, p) in enumerate(zip(gimbal_names(n_eng), gimbal_xyz(n_eng))):
            lines.append(f'{n} = {{grid = {200 + e + 1}, xyz = ["{p[0]} m", "{p[1]} m", "{p[2]} m"]}}')
    lines += ["[band]", 'low = "0.5 Hz"', 'high = "30 Hz"']
    for e, n in enumerate(gimbal_names(n_eng)):
        lines += ["[[engine]]", f'name = "engine_{e + 1}"', f'model = "{MODEL}"', f'gimbal_node = "{n}"',
                  'cg_offset = ["0 m", "0 m", "0 m"]',
                  "[[actuator]]", f'name = "actuator_{e + 1}"', f'engine = "engine_{e + 1}"', 'axis = "pitch"',
                  'attach_node = "tip"', "direction = [-1.0, 0.0, 0.0]", "rotation_axis = [0.0, 1.0, 0.0]"]
    p = tmp_path / f"beam_{n_eng}.toml"
    p.write_text("\n".join(lines) + "\n")
    return p


def analytic(n_eng, f_hz):
    """Closed form for N identical engines on the tip: F_L = G_fc c + G_fe e, e = h sum F_L,
    so for a command on engine j, e = h G_fc c / (1 - N h G_fe); theta_i = G_tc delta_ij c + G_te e."""
    m = load_model(MODEL)
    m = m.replace(structure=dataclasses.replace(m.structure, load_damping_ratio=0.0))
    ss = simplex_state_space(m, "pitch", structure_inputs=True)
    s = 2j * math.pi * np.asarray(f_hz)
    ic, ie = ss.input_index("command_rad"), ss.input_index("elongation_m")
    of, ot = ss.output_index("load_force_N"), ss.output_index("theta_rad")
    G = np.array([ss.C @ np.linalg.solve(si * np.eye(ss.A.shape[0]) - ss.A, ss.B) + ss.D for si in s])
    h = tip_receptance(f_hz)
    e = h * G[:, of, ic] / (1 - n_eng * h * G[:, of, ie])
    return G[:, ot, ic] + G[:, ot, ie] * e, G[:, ot, ie] * e     # direct, cross


@pytest.mark.parametrize("n_eng", [1, 2, 6])
def test_n_engines_on_a_beam_give_the_analytic_coupling(tmp_path, n_eng):
    write_npz(tmp_path / "beam.npz", n_eng)
    cfg = load_config(config(tmp_path, n_eng, "beam.npz"))
    assert len(cfg.engines) == n_eng and cfg.structure.n_modes == N_EL
    f = np.array([1.0, 3.0, 7.0, 12.0, 20.0])
    _, th = build_system(cfg).frf(f)
    direct, cross = analytic(n_eng, f)
    assert np.allclose(th[:, 0, 0], direct, rtol=1e-6, atol=1e-9)
    if n_eng > 1:
        assert np.max(np.abs(cross)) > 1e-2          # the coupling is not negligible
        for i in range(1, n_eng):
            assert np.allclose(th[:, i, 0], cross, rtol=1e-6, atol=1e-9)


def test_uff_and_punch_round_trip_into_the_same_modes(tmp_path):
    n = 2
    write_npz(tmp_path / "beam.npz", n)
    write_uff(tmp_path / "beam.unv", n)
    write_punch(tmp_path / "beam.pch", n)
    ref = load_config(config(tmp_path, n, "beam.npz")).structure
    uff = load_config(config(tmp_path, n, "beam.unv", 'length_unit = "mm"\nmass_unit = "tonne"\n'
                             "fe_to_vehicle = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]", fe_nodes=True))
    pch = load_config(config(tmp_path, n, "beam.pch", 'length_unit = "in"\nmass_unit = "lbf*s**2/in"\n'
                             "modal_mass = 1.0", fe_nodes=True, damping="0.02"))
    for cfg, tol in ((uff, 2e-5), (pch, 2e-6)):
        st = cfg.structure
        assert st.node_names == ref.node_names and np.allclose(st.node_xyz_m, ref.node_xyz_m)
        assert np.allclose(st.freq_hz, ref.freq_hz, rtol=tol)
        assert np.allclose(st.phi, ref.phi, rtol=tol, atol=tol * np.abs(ref.phi).max())
    assert np.allclose(uff.structure.damping_ratio, ref.damping_ratio, rtol=1e-4)
    assert uff.structure_import["generalised_mass_from"] == "file"
    assert uff.structure_import["generalised_mass_range"] == pytest.approx([4.0, 4.0])
    assert pch.structure_import["format"] == "nastran-punch"
    f = [2.0, 9.0]
    npz = load_config(config(tmp_path, n, "beam.npz", damping="0.02"))
    assert np.allclose(build_system(pch).frf(f)[1], build_system(npz).frf(f)[1], rtol=1e-5)


@pytest.mark.parametrize("extra,field", [
    ('length_unit = "kg"\nmass_unit = "tonne"', "structure.length_unit"),
    ('mass_unit = "tonne"', "structure.length_unit"),
    ('length_unit = "in"\nmass_unit = "lbf*s**2/in"', "structure.modal_mass"),
    ('length_unit = "in"\nmass_unit = "lbf*s**2/in"\nmodal_mass = -1.0', "modal_mass"),
    ('length_unit = "in"\nmass_unit = "lbf*s**2/in"\nmodal_mass = 1.0', "structure.damping_ratio"),
    ('length_unit = "in"\nmass_unit = "lbf*s**2/in"\nmodal_mass = 1.0\nfe_to_vehicle = [[1, 0, 0], [1, 0, 0], '
     "[0, 0, 1]]", "structure.fe_to_vehicle"),
])
def test_bad_fe_import_is_one_line_input_error(tmp_path, extra, field):
    write_punch(tmp_path / "beam.pch", 1)
    with pytest.raises(InputError) as e:
        load_config(config(tmp_path, 1, "beam.pch", extra, fe_nodes=True))
    assert e.value.field == field and "\n" not in str(e.value)


def test_fe_grid_missing_and_fe_keys_on_npz_are_input_errors(tmp_path):
    write_punch(tmp_path / "beam.pch", 1)
    p = config(tmp_path, 1, "beam.pch", 'length_unit = "in"\nmass_unit = "lbf*s**2/in"\nmodal_mass = 1.0',
               fe_nodes=True)
    p.write_text(p.read_text().replace(f"grid = {GRID0 + N_EL}", "grid = 999"))
    with pytest.raises(InputError) as e:
        load_config(p)
    assert e.value.field == "structure.nodes.tip.grid"
    write_npz(tmp_path / "beam.npz", 1)
    with pytest.raises(InputError) as e:
        load_config(config(tmp_path, 1, "beam.npz", 'length_unit = "m"'))
    assert e.value.field == "structure.length_unit"


def test_more_than_eight_engines_is_an_input_error(tmp_path):
    write_npz(tmp_path / "beam.npz", 9)
    with pytest.raises(InputError) as e:
        load_config(config(tmp_path, 9, "beam.npz"))
    assert e.value.field == "engine"
