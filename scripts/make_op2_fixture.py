"""Make the Nastran OP2 fixtures of tests/test_masv_op2.py and their pyNastran reference readings.

Run OUTSIDE the project venv, with pyNastran (1.4 needs numpy < 2)::

    python3.11 -m venv /tmp/pnv && /tmp/pnv/bin/pip install pyNastran
    /tmp/pnv/bin/python scripts/make_op2_fixture.py [--pynastran-models CLONE/models/beam_modes]

It writes into tests/data/op2/:

* ``beam_le.op2`` (little-endian) and ``beam_be.op2`` (big-endian), both with the
  PARAM,POST,-1 header: pyNastran's OP2 writer given the real normal modes of the axial bar of
  tests/test_masv_nengine.py (eight linear elements, consistent mass, tip mass, clamped at
  x = 0; the same constants, copied below because this script cannot import the project). The
  model is in centimetres and grams (CGS) with the bar along the FE y axis; ``beam_le`` has shapes
  normalised to a unit largest component (EIGRL NORM=MAX), ``beam_be`` mass-normalised
  (NORM=MASS). Grids 101..108 are the bar's nodes, 201..206 grounded points (zero shapes) for
  gimbals. pyNastran 1.4's writer skips the LAMA table (op2_writer.py ``skip_tables``), so these
  two files hold eigenvectors only (their generalised masses come from the configuration); it
  writes them as OUGV1 displacements of a real-eigenvalue analysis (table code 1, analysis
  code 2), which pyNastran reads back as mode shapes. Its big-endian output is broken (the
  header big-endian, the tables not), so ``beam_be.op2`` is ``beam_le.op2`` with every integer
  and real word byte-swapped and the character words (table names, tape code, IDENT words
  51-146) kept, :func:`to_big_endian`; pyNastran's reading of it (in the reference file) is
  the check that the result is a valid big-endian OP2.
* ``beam_64.op2``: ``beam_le.op2`` with 64-bit words (:func:`to_64bit`; pyNastran writes no
  64-bit OP2, its reading of this one is the check of the conversion).
* ``beam_split.op2``: ``beam_le.op2`` with each eigenvector data record split in two Fortran
  records (:func:`split_records`), as Nastran writes long records.
* ``beam_modes_m1.op2`` and ``beam_modes_m2.op2``, copied from pyNastran's
  models/beam_modes/ (``--pynastran-models``; BSD-3-Clause, see README.md): real Nastran
  SOL 103 output (PARAM,POST,-1 and -2) of a clamped rod with a tip mass, NORM=MAX, with LAMA.
* ``reference_pynastran.npz``: what pyNastran reads from each of these files (keys
  ``<stem>__<field>``: mode, eigenvalue, cycles, generalized_mass, generalized_stiffness from
  LAMA; grids, table, phi (n, G, 6) from the eigenvector table).
"""

from __future__ import annotations

import argparse
import math
import shutil
from pathlib import Path

import numpy as np
import scipy.linalg

OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "op2"
# tests/test_masv_nengine.py's bar (SI)
N_EL, L_M, EA_N, RHOA_KG_M, TIP_MASS_KG = 8, 6.0, 1.2e9, 80.0, 20000.0
KG_PER_G = 1e-3                     # the OP2 is in the CGS system: cm, g, s, dyn
PYNASTRAN_MODELS = ("beam_modes_m1.op2", "beam_modes_m2.op2")


def bar_modes():
    """Mass-normalised modes of the bar: omega^2 [rad^2/s^2], shapes (n, N_EL) [1/sqrt(kg)]."""
    le = L_M / N_EL
    K, M = np.zeros((N_EL + 1, N_EL + 1)), np.zeros((N_EL + 1, N_EL + 1))
    for e in range(N_EL):
        i = slice(e, e + 2)
        K[i, i] += EA_N / le * np.array([[1, -1], [-1, 1]])
        M[i, i] += RHOA_KG_M * le / 6 * np.array([[2, 1], [1, 2]])
    M[-1, -1] += TIP_MASS_KG
    w2, V = scipy.linalg.eigh(K[1:, 1:], M[1:, 1:])
    return w2, V.T


def write_beam_op2(path: Path, endian: bytes, post: int, norm_max: bool) -> None:
    from pyNastran.op2.op2 import OP2
    from pyNastran.op2.tables.lama_eigenvalues.lama_objects import RealEigenvalues
    from pyNastran.op2.tables.oug.oug_eigenvectors import RealEigenvectorArray

    w2, V = bar_modes()
    n = w2.size
    grids = np.array([100 + i for i in range(1, N_EL + 1)] + [200 + e for e in range(1, 7)])
    phi = np.zeros((n, grids.size, 6))
    phi[:, :N_EL, 1] = V * math.sqrt(KG_PER_G)              # mass-normalised in g, along FE y
    scale = np.abs(phi).reshape(n, -1).max(axis=1) if norm_max else np.ones(n)
    phi /= scale[:, None, None]                             # NORM=MAX (or NORM=MASS)
    gen_mass = 1.0 / scale ** 2                             # phi^T M phi of the NORM=MAX shapes [g]
    cycles = np.sqrt(w2) / (2 * math.pi)
    model = OP2(debug=None, mode="msc")
    node_gridtype = np.column_stack([grids, np.ones_like(grids)]).astype("int32")
    vec = RealEigenvectorArray.add_modal_case(
        "OUGV1", node_gridtype, phi.astype("float32"), 1, np.arange(1, n + 1), w2, cycles,
        is_sort1=True, title="AXIAL BAR", subtitle="MODES", label="")
    model.eigenvectors[1] = vec
    lama = RealEigenvalues("AXIAL BAR", "LAMA", nmodes=n)
    for i in range(n):
        lama.add_f06_line((i + 1, i + 1, w2[i], math.sqrt(w2[i]), cycles[i], gen_mass[i], gen_mass[i] * w2[i]), i)
    model.eigenvalues["AXIAL BAR"] = lama
    model.write_op2(str(path), post=post, endian=endian, nastran_format="msc")


def to_big_endian(le: bytes) -> bytes:
    """The little-endian OP2 ``le`` as big-endian: Fortran record lengths and every integer or
    real word swapped, character words kept (8-byte table names and labels, the tape code, the
    name of a table's -2 record, IDENT words 51-146: title, subtitle, label)."""
    import struct

    out, i = [], 0
    while i < len(le):
        n = struct.unpack("<i", le[i:i + 4])[0]
        d = le[i + 4:i + 4 + n]
        assert struct.unpack("<i", le[i + 4 + n:i + 8 + n])[0] == n
        w = np.frombuffer(d, dtype="<i4") if n % 4 == 0 else None
        if n == 8 or d == b"NASTRAN FORT TAPE ID CODE - ":
            body = d
        elif n == 28 and d[:8].strip().isalnum():
            body = d[:8] + w[2:].astype(">i4").tobytes()       # name(8 chars) + 5 ints
        elif n == 584:
            body = w[:50].astype(">i4").tobytes() + d[200:]    # IDENT: 50 words, then 96 words of text
        else:
            body = w.astype(">i4").tobytes()                   # ints and 32-bit reals alike
        out.append(struct.pack(">i", n) + body + struct.pack(">i", n))
        i += 8 + n
    return b"".join(out)


def to_64bit(le: bytes) -> bytes:
    """The little-endian 32-bit OP2 ``le`` written by :func:`write_beam_op2` (header and OUGV1
    only) with 64-bit words, as MSC Nastran writes them: Fortran record lengths stay 4 bytes;
    integers int64, reals float64; character words 4 characters and 4 blanks (tape code, label,
    IDENT title words 51-146), table names 8 characters and 8 blanks. Word types by record:
    markers, the date, the trailer and OUG grid/type words integers; IDENT words 6-7 (eigenvalue,
    cycles) and the OUG components reals."""
    import struct

    def ints(b):
        return np.frombuffer(b, dtype="<i4").astype("<i8").tobytes()

    def reals(b):
        return np.frombuffer(b, dtype="<f4").astype("<f8").tobytes()

    def chars(b):
        return b"".join(b[j:j + 4] + b"    " for j in range(0, len(b), 4))

    out, i, after_ident = [], 0, False
    while i < len(le):
        n = struct.unpack("<i", le[i:i + 4])[0]
        d = le[i + 4:i + 4 + n]
        if d == b"NASTRAN FORT TAPE ID CODE - " or d == b"XXXXXXXX":
            body = chars(d)
        elif n == 8:
            body = d + b" " * 8                                    # a table name
        elif n == 28 and d[:8].strip().isalnum():
            body = d[:8] + b" " * 8 + ints(d[8:])                  # name + 5 ints of a -2 record
        elif n == 584:
            body = ints(d[:20]) + reals(d[20:28]) + ints(d[28:200]) + chars(d[200:])
        elif after_ident and n > 4:                                # OUG data: 2 ints, 6 reals per grid
            g = np.frombuffer(d, dtype="<i4").reshape(-1, 8)
            body = np.hstack([g[:, :2].astype("<i8").view("<u8"),
                              g[:, 2:].view("<f4").astype("<f8").view("<u8")]).astype("<u8").tobytes()
        else:
            body = ints(d)
        if n > 4:
            after_ident = n == 584
        out.append(struct.pack("<i", len(body)) + body + struct.pack("<i", len(body)))
        i += 8 + n
    return b"".join(out)


def split_records(le: bytes) -> bytes:
    """The little-endian 32-bit OP2 ``le`` with every data record after an IDENT record (the
    OUG eigenvector data) written as two Fortran records, ``[n1] data1 [n2] data2``, the way
    Nastran splits a logical record longer than its buffer."""
    import struct

    recs, i = [], 0
    while i < len(le):
        n = struct.unpack("<i", le[i:i + 4])[0]
        recs.append(le[i + 4:i + 4 + n])
        i += 8 + n

    def rec(d):
        return struct.pack("<i", len(d)) + d + struct.pack("<i", len(d))

    out, after_ident = [], False
    for k, d in enumerate(recs):
        if after_ident and len(d) > 4 and len(d) % 8 == 0:
            h = (len(d) // 8) * 4                       # at a grid boundary when the length allows
            out[-1] = rec(struct.pack("<i", h // 4))     # the word count before it, now of the first part
            out += [rec(d[:h]), rec(struct.pack("<i", (len(d) - h) // 4)), rec(d[h:])]
        else:
            out.append(rec(d))
        if len(d) > 4:
            after_ident = len(d) == 584
    return b"".join(out)


def reference(paths) -> dict:
    from pyNastran.op2.op2 import read_op2

    out = {}
    for p in paths:
        m = read_op2(str(p), debug=None)
        (vec,) = list(m.eigenvectors.values()) or list(m.displacements.values())   # table code 7 or 1
        k = p.stem + "__"
        for lama in m.eigenvalues.values():
            out.update({k + "mode": lama.mode, k + "eigenvalue": lama.eigenvalues, k + "cycles": lama.cycles,
                        k + "generalized_mass": lama.generalized_mass,
                        k + "generalized_stiffness": lama.generalized_stiffness})
        out.update({k + "grids": vec.node_gridtype[:, 0], k + "table": np.array(vec.table_name),
                    k + "vector_eigenvalue": np.asarray(vec.eigns),
                    k + "vector_modes": np.asarray(vec.modes), k + "phi": vec.data})
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pynastran-models", type=Path, help="pyNastran's models/beam_modes folder (a checkout)")
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    write_beam_op2(OUT / "beam_le.op2", b"<", -1, norm_max=True)
    write_beam_op2(OUT / "beam_be.op2", b"<", -1, norm_max=False)
    (OUT / "beam_be.op2").write_bytes(to_big_endian((OUT / "beam_be.op2").read_bytes()))
    (OUT / "beam_64.op2").write_bytes(to_64bit((OUT / "beam_le.op2").read_bytes()))
    (OUT / "beam_split.op2").write_bytes(split_records((OUT / "beam_le.op2").read_bytes()))
    if args.pynastran_models:
        for name in PYNASTRAN_MODELS:
            shutil.copyfile(args.pynastran_models / name, OUT / name)
        print(f"copied {PYNASTRAN_MODELS} from {args.pynastran_models}")
    paths = sorted(OUT.glob("*.op2"))
    np.savez(OUT / "reference_pynastran.npz", **reference(paths))
    import pyNastran
    print(f"pyNastran {pyNastran.__version__}, numpy {np.__version__}: wrote {[p.name for p in paths]} and "
          "reference_pynastran.npz")


if __name__ == "__main__":
    main()
