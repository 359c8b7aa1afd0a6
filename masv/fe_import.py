"""Import mode shapes from finite-element results: Universal File dataset 55, Nastran punch and OP2.

A MASV configuration names its structure's nodes and the FE grid ids they are
(``[structure.nodes]``, format in ``docs/reference/masv_files.md``); the importer reads the
normal modes of the FE file, keeps the named grids' six components, and returns a
:class:`masv.structure.ModalStructure` in MASV's units and frame. Checked at import:

* **Normalisation.** MASV's shapes are mass-normalised (phi_i^T M phi_i = 1). Each mode is
  divided by sqrt(m_i), m_i its generalised mass in the FE file's units: the file's own (UFF 55
  record 8 "modal mass", the OP2's LAMA generalised masses: ``modal_mass = "file"``) or the configuration's (``modal_mass`` a
  number or a list, e.g. 1 for Nastran's default EIGRL NORM=MASS). A missing, zero, negative or
  non-finite generalised mass is an InputError: shapes normalised otherwise (NORM=MAX, unit
  displacement) cannot be used without their masses.
* **Units.** With u = phi q and the kinetic energy 1/2 |q'|^2, a mass-normalised translation
  is numerically 1/sqrt(mass) and a rotation 1/sqrt(mass length^2). An FE model in the length
  unit L (``length_unit``, L_si metres) and the mass unit M (``mass_unit``, M_si kg) therefore
  converts as::

      phi_translation,SI = phi_translation,FE / sqrt(M_si)
      phi_rotation,SI    = phi_rotation,FE / (sqrt(M_si) L_si)

  (frequencies need no conversion: time is in seconds in every consistent FE unit system).
  Both units are required for an FE file; their dimensions are checked (pint).
* **Frame.** ``fe_to_vehicle`` (3 x 3, rows the vehicle x, y, z axes written in the FE frame,
  default the identity) turns each node's translations and rotations into the vehicle frame;
  it must be orthonormal (checked, 1e-6).
* **Modes.** Elastic modes only: frequencies must be positive (rigid-body modes, f below
  ``min_frequency``, default 1e-3 Hz, are dropped and counted in the provenance).

Formats:

* **UFF 55** (``.uff``/``.unv``; read by pyuff, datasets 55 with analysis type 2 "normal mode"):
  record 7 ``freq`` [Hz], ``modal_m`` generalised mass, ``modal_damp_vis`` viscous damping
  ratio (``damping_ratio = "file"``); ``node_nums`` and ``r1``..``r6`` the components in the
  FE frame (three components per node: rotations zero).
* **Nastran punch** (``.pch``/``.pun``; ``DISP(PUNCH) = ALL`` in a SOL 103 run, sort 1): blocks
  ``$EIGENVECTOR`` ... ``$EIGENVALUE = lambda MODE = i`` followed by a line per grid
  ``<id> G <T1> <T2> <T3>`` and its ``-CONT- <R1> <R2> <R3>`` (free-field, the 80-column line
  counter ignored); lambda = (2 pi f)^2 [rad^2/s^2]. The punch file holds no generalised
  masses: ``modal_mass`` must be given (1 for NORM=MASS).
* **Nastran OP2** (``.op2``; ``DISP = ALL`` in a SOL 103 run, ``PARAM,POST,-1`` or ``-2``, 32- or
  64-bit words, either byte order; read by ``masv._op2``): the real eigenvector table (BOUGV1 in the
  basic frame when present, else OUGV1/OUG1) and, when present, the LAMA eigenvalue table whose
  generalised masses are the file's (``modal_mass = "file"``, the default with a LAMA table);
  lambda = (2 pi f)^2 [rad^2/s^2]; no damping.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Mapping

import numpy as np

from taos.errors import InputError, check_keys
from taos.units import to_si

from ._op2 import read_op2_modes
from .structure import ModalStructure, validate_modes

#: file suffixes of each FE format
UFF_SUFFIXES = (".uff", ".unv")
PUNCH_SUFFIXES = (".pch", ".pun", ".punch")
OP2_SUFFIXES = (".op2",)
FE_SUFFIXES = UFF_SUFFIXES + PUNCH_SUFFIXES + OP2_SUFFIXES
#: keys of [structure] that only an FE file takes
FE_KEYS = {"nodes", "length_unit", "mass_unit", "modal_mass", "fe_to_vehicle", "min_frequency"}


def is_fe_file(path) -> bool:
    return Path(path).suffix.lower() in FE_SUFFIXES


def read_uff55(path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Normal modes of a Universal File: (freq_hz (n,) [Hz], modal mass (n,) [FE units],
    viscous damping ratio (n,) [-], grid ids (G,), shapes (n, G, 6) [FE units]). Datasets 55
    of analysis type 2 only; every mode must list the same grids."""
    src = str(path)
    try:
        import pyuff
        sets = pyuff.UFF(src).read_sets()
    except FileNotFoundError:
        raise InputError(src, "(file)", "an existing Universal File", got="no such file") from None
    except Exception as e:  # noqa: BLE001 - pyuff raises bare Exceptions on bad files
        raise InputError(src, "(file)", "a readable Universal File (datasets 55)",
                         got=(str(e).splitlines() or [type(e).__name__])[0][:80]) from None
    sets = [sets] if isinstance(sets, dict) else list(sets)
    modes = [s for s in sets if s.get("type") == 55 and s.get("analysis_type") == 2]
    if not modes:
        raise InputError(src, "dataset 55", "normal-mode datasets 55 (analysis type 2)", got="none")
    grids = np.asarray(modes[0]["node_nums"], dtype=np.int64)
    n, G = len(modes), grids.size
    phi = np.zeros((n, G, 6))
    freq, mass, zeta = np.zeros(n), np.zeros(n), np.zeros(n)
    for i, m in enumerate(modes):
        if not np.array_equal(np.asarray(m["node_nums"], dtype=np.int64), grids):
            raise InputError(src, f"dataset 55 #{i + 1}.node_nums", "the same nodes in every mode")
        for c in range(6):
            r = m.get(f"r{c + 1}")
            if r is not None:
                phi[i, :, c] = np.real(np.asarray(r, float))
        freq[i], mass[i], zeta[i] = float(m["freq"]), float(m.get("modal_m", 0.0)), float(m.get("modal_damp_vis", 0.0))
    return freq, mass, zeta, grids, phi


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"


def read_punch(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Real eigenvectors of a Nastran punch file: (freq_hz (n,) [Hz], grid ids (G,), shapes
    (n, G, 6) [FE units]); module docstring for the layout."""
    src = str(path)
    try:
        lines = Path(path).read_text(errors="replace").splitlines()
    except FileNotFoundError:
        raise InputError(src, "(file)", "an existing Nastran punch file", got="no such file") from None
    except OSError as e:
        raise InputError(src, "(file)", "a readable Nastran punch file", got=type(e).__name__) from None
    modes: list[tuple[float, dict[int, np.ndarray]]] = []
    in_vec, cur, last = False, None, None
    for ln, raw in enumerate(lines, 1):
        line = raw[:72].rstrip()
        if line.startswith("$"):
            key = line[1:].strip().upper()
            if key.startswith("EIGENVECTOR"):
                in_vec = True
            elif key.startswith(("DISPLACEMENTS", "VELOCITY", "ACCELERATION", "SPCF", "OLOADS", "ELEMENT")):
                in_vec = False
            elif in_vec and key.startswith("EIGENVALUE"):
                m = re.match(rf"EIGENVALUE\s*=\s*({_NUM})\s+MODE\s*=\s*(\d+)", key)
                if not m:
                    raise InputError(src, f"line {ln}", "'$EIGENVALUE = <lambda> MODE = <n>'", got=raw.strip()[:60])
                cur = {}
                modes.append((float(m.group(1).replace("D", "E")), cur))
            continue
        if not in_vec or cur is None or not line.strip():
            continue
        f = line.split()
        try:
            if f[0] == "-CONT-":
                if last is None:
                    raise ValueError
                last[3:6] = [float(v.replace("D", "E")) for v in f[1:4]]
                last = None
            else:
                if len(f) < 5 or f[1] not in ("G", "S"):
                    raise ValueError
                last = np.zeros(6)
                last[0:3] = [float(v.replace("D", "E")) for v in f[2:5]]
                cur[int(f[0])] = last
        except (ValueError, IndexError):
            raise InputError(src, f"line {ln}", "'<grid> G <T1> <T2> <T3>' or '-CONT- <R1> <R2> <R3>'",
                             got=raw.strip()[:60]) from None
    if not modes:
        raise InputError(src, "$EIGENVECTOR", "real eigenvector blocks (DISP(PUNCH) of a SOL 103 run)", got="none")
    grids = np.array(sorted(modes[0][1]), dtype=np.int64)
    phi = np.zeros((len(modes), grids.size, 6))
    for i, (_, d) in enumerate(modes):
        if sorted(d) != grids.tolist():
            raise InputError(src, f"MODE {i + 1}", "the same grids in every mode")
        phi[i] = np.array([d[g] for g in grids.tolist()])
    lam = np.array([lm for lm, _ in modes])
    return np.sqrt(np.maximum(lam, 0.0)) / (2.0 * math.pi), grids, phi


def _unit_scale(st: Mapping, key: str, kind: str, src: str) -> float:
    v = st.get(key)
    if not isinstance(v, str) or not v.strip():
        raise InputError(src, f"structure.{key}", f"the FE file's unit of {kind}, like 'm', 'in', 'mm' or "
                         "'kg', 'lbf*s**2/in', 'tonne'", got="nothing (key missing)" if v is None else repr(v))
    return to_si(f"1 {v.strip()}", kind, source=src, field=f"structure.{key}", positive=True)


def _rotation(st: Mapping, src: str) -> np.ndarray:
    v = st.get("fe_to_vehicle")
    if v is None:
        return np.eye(3)
    try:
        T = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        T = np.zeros(0)
    if T.shape != (3, 3) or not np.all(np.isfinite(T)) or not np.allclose(T @ T.T, np.eye(3), atol=1e-6):
        raise InputError(src, "structure.fe_to_vehicle", "an orthonormal 3 x 3 matrix (rows: vehicle axes in "
                         "the FE frame)", got=repr(v)[:60])
    return T


def _nodes(st: Mapping, src: str) -> tuple[list[str], list[int], np.ndarray]:
    tab = st.get("nodes")
    if not isinstance(tab, Mapping) or not tab:
        raise InputError(src, "structure.nodes", "a [structure.nodes] table: name = {grid = <id>, xyz = "
                         "['x m', 'y m', 'z m']}", got="nothing (section missing)" if tab is None else repr(tab)[:60])
    names, ids, xyz = [], [], []
    for name, t in tab.items():
        f = f"structure.nodes.{name}"
        if not isinstance(t, Mapping):
            raise InputError(src, f, "a table {grid = <id>, xyz = ['x m', 'y m', 'z m']}", got=repr(t)[:60])
        check_keys(t, {"grid", "xyz"}, src, f)
        g = t.get("grid")
        if not isinstance(g, int) or isinstance(g, bool) or g <= 0:
            raise InputError(src, f"{f}.grid", "a positive integer FE grid (node) id", got=repr(g))
        p = t.get("xyz")
        if not isinstance(p, list) or len(p) != 3:
            raise InputError(src, f"{f}.xyz", "three lengths (vehicle frame) like ['0 m', '1.5 m', '0 m']",
                             got=repr(p))
        names.append(str(name))
        ids.append(g)
        xyz.append([to_si(c, "length", source=src, field=f"{f}.xyz[{i}]") for i, c in enumerate(p)])
    if len(set(ids)) != len(ids):
        raise InputError(src, "structure.nodes", "distinct grid ids", got="a grid named twice")
    return names, ids, np.asarray(xyz)


def load_fe_modes(path: Path, st: Mapping, src: str) -> tuple[ModalStructure, dict]:
    """Read the FE file ``path`` as configured by the [structure] table ``st`` of the
    configuration ``src`` (module docstring) and return (the structure in MASV units and frame,
    import provenance: format, units, scale factors, normalisation, dropped rigid modes)."""
    fsrc = str(path)
    suffix = Path(path).suffix.lower()
    names, ids, xyz = _nodes(st, src)
    L = _unit_scale(st, "length_unit", "length", src)
    M = _unit_scale(st, "mass_unit", "mass", src)
    T = _rotation(st, src)
    fmin = to_si(st.get("min_frequency", "1e-3 Hz"), "frequency", source=src, field="structure.min_frequency",
                 nonnegative=True)
    if suffix in UFF_SUFFIXES:
        freq, file_mass, zeta, grids, phi = read_uff55(path)
        fmt = "uff55"
    elif suffix in OP2_SUFFIXES:
        op2 = read_op2_modes(path, grids=ids)
        freq, file_mass, grids, phi = op2.freq_hz, op2.generalised_mass, op2.grids, op2.phi
        zeta, fmt = np.zeros(freq.size), "nastran-op2"
    else:
        freq, grids, phi = read_punch(path)
        file_mass, zeta, fmt = None, np.zeros(freq.size), "nastran-punch"
    mm = st.get("modal_mass", "file" if file_mass is not None else None)
    if mm == "file":
        if file_mass is None:
            raise InputError(src, "structure.modal_mass", f"the generalised masses (the {fmt} file has none): 1 "
                             "for EIGRL NORM=MASS, or a list", got='"file"')
        gm, how = file_mass, "file"
    elif mm is None:
        raise InputError(src, "structure.modal_mass", f"the generalised masses (the {fmt} file has none): 1 for "
                         "EIGRL NORM=MASS, or a list", got="nothing (key missing)")
    else:
        try:
            gm = np.broadcast_to(np.asarray(mm, dtype=float), freq.shape).copy()
        except (TypeError, ValueError):
            raise InputError(src, "structure.modal_mass", f"\"file\", a number or a list of {freq.size} numbers",
                             got=repr(mm)[:60]) from None
        how = "configuration"
    if not np.all(np.isfinite(gm)) or np.any(gm <= 0):
        bad = gm[~(np.isfinite(gm) & (gm > 0))][0]
        raise InputError(src if how == "configuration" else fsrc, "modal_mass",
                         "positive generalised masses (mass-normalised shapes have 1)", got=repr(float(bad)))
    keep = freq > fmin
    col = {g: i for i, g in enumerate(grids.tolist())}
    for name, g in zip(names, ids):
        if g not in col:
            raise InputError(src, f"structure.nodes.{name}.grid", f"a grid of {Path(fsrc).name}", got=str(g))
    sel = [col[g] for g in ids]
    p = phi[keep][:, sel, :] / np.sqrt(gm[keep])[:, None, None]
    p = np.concatenate([p[..., 0:3] @ T.T / math.sqrt(M), p[..., 3:6] @ T.T / (math.sqrt(M) * L)], axis=-1)
    s = validate_modes(freq[keep], zeta[keep], names, xyz, p, source=fsrc, required_nodes=())
    prov = {"format": fmt, "length_unit_m": L, "mass_unit_kg": M, "generalised_mass_from": how,
            "generalised_mass_range": [float(gm[keep].min()), float(gm[keep].max())] if keep.any() else [],
            "rigid_modes_dropped": int((~keep).sum()), "grids": dict(zip(names, ids))}
    if fmt == "nastran-op2":
        prov["op2_table"] = op2.table
    return s, prov
