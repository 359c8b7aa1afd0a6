"""Nastran OP2 import (masv._op2, masv.fe_import): the reader equals pyNastran's reading of
real Nastran SOL 103 files and of pyNastran-written files of the bar of test_masv_nengine
(tests/data/op2, made by scripts/make_op2_fixture.py), and the bar's OP2 imports into the same
modes and coupling as its punch, UFF and .npz files."""

from __future__ import annotations

import math
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

from masv._op2 import read_op2_modes
from masv.config import load_config
from masv.fe_import import load_fe_modes
from masv.system import build_system
from taos.errors import InputError

from taos.units import M_PER_IN, N_PER_LBF

from .test_masv_nengine import N_EL, beam_modes, config, write_npz, write_punch, write_uff

DATA = Path(__file__).resolve().parent / "data" / "op2"
REF = np.load(DATA / "reference_pynastran.npz")
FILES = ["beam_le", "beam_be", "beam_64", "beam_split", "beam_modes_m1", "beam_modes_m2"]
#: rows: vehicle x, y, z in the FE frame of beam_*.op2 (bar along FE y)
FE_TO_VEHICLE = "[[0, 1, 0], [1, 0, 0], [0, 0, -1]]"


@pytest.mark.parametrize("stem", FILES)
def test_op2_reader_equals_pynastran(stem):
    m = read_op2_modes(DATA / f"{stem}.op2")
    r = {k.split("__", 1)[1]: REF[k] for k in REF.files if k.startswith(stem + "__")}
    assert m.endian == (">" if stem == "beam_be" else "<")
    assert m.word_bytes == (8 if stem == "beam_64" else 4)
    assert m.table == str(r["table"])
    assert np.array_equal(m.mode, r["vector_modes"])
    assert np.array_equal(m.grids, r["grids"])
    # float32 words in the file: the same numbers, bit for bit
    assert np.array_equal(m.eigenvalue_rad2_s2, np.asarray(r["vector_eigenvalue"], float))
    assert np.array_equal(m.phi, r["phi"].astype(float))
    if "generalized_mass" in r:
        assert np.array_equal(m.mode, r["mode"])
        assert np.array_equal(m.generalised_mass, r["generalized_mass"].astype(float))
        assert np.array_equal(m.generalised_stiffness, r["generalized_stiffness"].astype(float))
        assert np.allclose(m.freq_hz, r["cycles"], rtol=1e-6)
    else:
        assert m.generalised_mass is None


def test_real_nastran_post1_and_post2_files_give_the_same_modes():
    a, b = read_op2_modes(DATA / "beam_modes_m1.op2"), read_op2_modes(DATA / "beam_modes_m2.op2")
    assert a.phi.shape == (10, 12, 6)
    for f in ("mode", "eigenvalue_rad2_s2", "generalised_mass", "grids", "phi"):
        assert np.array_equal(getattr(a, f), getattr(b, f))


def test_real_nastran_lama_masses_normalise_the_shapes():
    """modal_mass defaults to the file's LAMA generalised masses; SI scaling of the module docstring."""
    lbf_s2_in_kg = N_PER_LBF / M_PER_IN
    st = {"nodes": {"root": {"grid": 2, "xyz": ["0 m", "0 m", "0 m"]}, "tip": {"grid": 11, "xyz": ["1 m", "0 m", "0 m"]}},
          "length_unit": "in", "mass_unit": "lbf*s**2/in"}
    s, prov = load_fe_modes(DATA / "beam_modes_m1.op2", st, "test.toml")
    m = read_op2_modes(DATA / "beam_modes_m1.op2")
    assert prov["format"] == "nastran-op2" and prov["op2_table"] == "OUGV1"
    assert prov["generalised_mass_from"] == "file"
    assert prov["generalised_mass_range"] == pytest.approx([m.generalised_mass.min(), m.generalised_mass.max()])
    k = np.argsort(m.freq_hz, kind="stable")
    cols = [list(m.grids).index(2), list(m.grids).index(11)]
    raw = m.phi[k][:, cols] / np.sqrt(m.generalised_mass[k])[:, None, None]
    assert np.allclose(s.freq_hz, m.freq_hz[k], rtol=1e-12)
    assert np.allclose(s.phi[..., :3], raw[..., :3] / math.sqrt(lbf_s2_in_kg), rtol=1e-12, atol=0)
    assert np.allclose(s.phi[..., 3:], raw[..., 3:] / (math.sqrt(lbf_s2_in_kg) * M_PER_IN), rtol=1e-12, atol=0)


def _op2_config(tmp_path, stem, extra):
    shutil.copyfile(DATA / f"{stem}.op2", tmp_path / f"{stem}.op2")
    p = config(tmp_path, 2, f"{stem}.op2", 'length_unit = "cm"\nmass_unit = "g"\n'
               f"fe_to_vehicle = {FE_TO_VEHICLE}\n" + extra, fe_nodes=True, damping="0.02")
    return p


def test_op2_round_trips_into_the_punch_uff_and_npz_modes(tmp_path):
    n = 2
    write_npz(tmp_path / "beam.npz", n)
    write_uff(tmp_path / "beam.unv", n)
    write_punch(tmp_path / "beam.pch", n)
    ref = load_config(config(tmp_path, n, "beam.npz", damping="0.02"))
    pch = load_config(config(tmp_path, n, "beam.pch", 'length_unit = "in"\nmass_unit = "lbf*s**2/in"\n'
                             "modal_mass = 1.0", fe_nodes=True, damping="0.02"))
    uff = load_config(config(tmp_path, n, "beam.unv", 'length_unit = "mm"\nmass_unit = "tonne"\n'
                             "fe_to_vehicle = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]", fe_nodes=True, damping="0.02"))
    # beam_le (CGS): NORM=MAX shapes, so m_i = 1 / max|phi_i|^2 of the mass-normalised shape in g
    _, _, V = beam_modes()
    gm = 1.0 / (np.abs(V).max(axis=1) * math.sqrt(1e-3)) ** 2
    le = load_config(_op2_config(tmp_path, "beam_le", f"modal_mass = {gm.tolist()}"))
    be = load_config(_op2_config(tmp_path, "beam_be", "modal_mass = 1.0"))
    w64 = load_config(_op2_config(tmp_path, "beam_64", f"modal_mass = {gm.tolist()}"))
    assert le.structure_import["format"] == be.structure_import["format"] == "nastran-op2"
    for cfg in (le, be, w64):
        st = cfg.structure
        assert st.n_modes == N_EL and st.node_names == ref.structure.node_names
        # measured: float32 OP2 words against .npz and punch 3e-8 (freq) and 2e-8 (shapes, of the
        # largest); the UFF's own rounding 3.4e-6 and 3e-7
        for other, tf, tp in ((ref, 1e-7, 1e-7), (pch, 1e-7, 1e-7), (uff, 1e-5, 1e-6)):
            o = other.structure
            assert np.allclose(st.freq_hz, o.freq_hz, rtol=tf, atol=0)
            assert np.allclose(st.phi, o.phi, rtol=0, atol=tp * np.abs(o.phi).max())
    f = [1.0, 2.0, 9.0, 20.0]
    th_pch = build_system(pch).frf(f)[1]
    for cfg in (le, be, w64):
        th = build_system(cfg).frf(f)[1]
        assert np.allclose(th, th_pch, rtol=0, atol=1e-8 * np.abs(th_pch).max())     # measured 2e-9
        assert np.abs(th[:, 1, 0]).max() > 1e-2          # the engines couple through the bar


def _patched(tmp_path, stem, edit) -> Path:
    b = bytearray((DATA / f"{stem}.op2").read_bytes())
    edit(b)
    p = tmp_path / f"{stem}_bad.op2"
    p.write_bytes(bytes(b))
    return p


def _first_ident(b) -> int:
    """Offset of the first IDENT word of beam_le's OUGV1 table."""
    return b.index(struct.pack("<i", 584), b.index(b"OUGV1   ")) + 4


@pytest.mark.parametrize("case,expect", [
    ("complex", "complex eigenvectors"),
    ("sort2", "SORT2"),
    ("truncated", "byte"),
    ("length", "Fortran record"),
    ("text", "first record length"),
    ("64bit_header_only", "real eigenvector table"),
    ("no_vectors", "real eigenvector table"),
    ("missing", "existing"),
])
def test_bad_op2_is_one_line_input_error(tmp_path, case, expect):
    src = (DATA / "beam_le.op2").read_bytes()
    if case == "complex":
        p = _patched(tmp_path, "beam_le", lambda b: b.__setitem__(slice(_first_ident(b), _first_ident(b) + 4),
                                                                   struct.pack("<i", 92)))
    elif case == "sort2":
        p = _patched(tmp_path, "beam_le", lambda b: b.__setitem__(slice(_first_ident(b) + 4, _first_ident(b) + 8),
                                                                   struct.pack("<i", 2001)))
    elif case == "truncated":
        p = tmp_path / "t.op2"
        p.write_bytes(src[:len(src) // 2])
    elif case == "length":
        p = _patched(tmp_path, "beam_le", lambda b: b.__setitem__(slice(_first_ident(b) - 4, _first_ident(b)),
                                                                   struct.pack("<i", 580)))
    elif case == "text":
        p = tmp_path / "t.op2"
        p.write_text("$EIGENVECTOR\n")
    elif case == "64bit_header_only":
        p = tmp_path / "t.op2"
        p.write_bytes(struct.pack("<iqi", 8, 3, 8))
    elif case == "no_vectors":
        p = tmp_path / "t.op2"
        p.write_bytes(src[:src.index(b"OUGV1   ") - 16])     # the header only, cut before the table
    else:
        p = tmp_path / "none.op2"
    with pytest.raises(InputError) as e:
        read_op2_modes(p)
    assert expect in str(e.value) and "\n" not in str(e.value) and str(p) in str(e.value)


@pytest.mark.parametrize("extra,field", [
    ("", "structure.modal_mass"),                                        # no LAMA: masses required
    ("modal_mass = [1.0, 2.0]", "structure.modal_mass"),                 # one per mode (8)
    ("modal_mass = 0.0", "modal_mass"),
])
def test_op2_configuration_errors(tmp_path, extra, field):
    p = _op2_config(tmp_path, "beam_be", extra)
    with pytest.raises(InputError) as e:
        load_config(p)
    assert e.value.field == field and "\n" not in str(e.value)


def test_op2_grid_missing_and_damping_file_are_input_errors(tmp_path):
    p = _op2_config(tmp_path, "beam_be", "modal_mass = 1.0")
    p.write_text(p.read_text().replace("grid = 201", "grid = 999"))
    with pytest.raises(InputError) as e:
        load_config(p)
    assert e.value.field == "structure.nodes.gimbal_1.grid"
    p = _op2_config(tmp_path, "beam_be", "modal_mass = 1.0")
    p.write_text(p.read_text().replace("damping_ratio = 0.02", 'damping_ratio = "file"'))
    with pytest.raises(InputError) as e:
        load_config(p)
    assert e.value.field == "structure.damping_ratio"


def test_masv_cli_reads_an_op2_configuration(tmp_path, capsys):
    from masv.cli import main

    p = _op2_config(tmp_path, "beam_be", "modal_mass = 1.0")
    assert main(["modes", str(p)]) == 0
    assert f"{N_EL} modes" in capsys.readouterr().out
    bad = _op2_config(tmp_path, "beam_le", "")
    assert main(["modes", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "structure.modal_mass" in err[0]


def test_grid_selection_keeps_the_named_grids_only():
    full = read_op2_modes(DATA / "beam_modes_m1.op2")
    sel = read_op2_modes(DATA / "beam_modes_m1.op2", grids=[11, 2, 999])
    cols = [list(full.grids).index(2), list(full.grids).index(11)]
    assert sel.grids.tolist() == [2, 11]
    assert np.array_equal(sel.phi, full.phi[:, cols]) and np.array_equal(sel.generalised_mass, full.generalised_mass)


@pytest.mark.parametrize("stem", ["beam_le", "beam_be", "beam_64", "beam_modes_m1"])
def test_corrupted_op2_reads_or_is_one_line_input_error(tmp_path, stem):
    """Random byte edits, aligned small words and truncations: the reader returns or raises
    InputError (one line), never another exception (a 1200-case run: 604 errors, 596 reads)."""
    src = (DATA / f"{stem}.op2").read_bytes()
    order = "big" if stem == "beam_be" else "little"
    rng = np.random.default_rng(42)
    p = tmp_path / "fuzz.op2"
    for i in range(60):
        b = bytearray(src)
        kind = i % 3
        if kind == 0:
            for _ in range(int(rng.integers(1, 6))):
                b[int(rng.integers(len(b)))] = int(rng.integers(256))
        elif kind == 1:
            b = b[:int(rng.integers(len(b)))]
        else:
            j = 4 * int(rng.integers(len(b) // 4))
            b[j:j + 4] = int(rng.integers(-10, 600)).to_bytes(4, order, signed=True)
        p.write_bytes(bytes(b))
        try:
            read_op2_modes(p, grids=[2, 11, 101, 108, 201] if i % 2 else None)
        except InputError as e:
            assert "\n" not in str(e)
