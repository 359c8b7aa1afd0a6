"""Reading, validating and writing FEM-derived data (stiffness matrices, modes, provenance).

Validation rules for a stiffness matrix K (SI blocks N/m, N/rad, N m/m, N m/rad):

* real numbers: a complex array (its imaginary part would be dropped), text, booleans or
  objects are refused, never cast;
* shape (6, 6) for a half with its bolted face held, (12, 12) free-free;
* finite (no NaN or infinity), every entry at most :data:`MAX_ENTRY` (1e15 SI) in magnitude;
* symmetric: max |K - K^T| <= 1e-6 max |K|;
* held (6x6): positive definite; free (12x12): positive semi-definite with exactly six
  (rigid-body) zero eigenvalues. Eigenvalues are judged on the diagonally scaled matrix
  D^-1/2 K D^-1/2 (D = diag K, which must be positive), so the mix of units does not matter:
  negative below -1e-8, zero below 1e-8 times the largest.

Every failure raises :class:`taos.errors.InputError` (one line: file, field, expected, got).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import re

import numpy as np

from ..errors import InputError

SYM_TOL = 1e-6
#: largest entry of a stiffness matrix [SI]: four orders of magnitude beyond a metre-long steel
#: bar (E A / L = 2e11 N/m) and the shipped gimbal halves (5.5e10); a larger one is a unit slip
#: and would overflow the symmetry and eigenvalue checks
MAX_ENTRY = 1e15
EIG_TOL = 1e-8
_SHAPES = {"held": (6, 6), "free": (12, 12)}


def validate_stiffness_matrix(K: object, *, source: str, field: str, kind: str) -> np.ndarray:
    """Check a stiffness matrix (rules in the module notes); return it as a float array.

    kind : ``'held'`` (6x6, positive definite) or ``'free'`` (12x12, PSD, 6 zero modes).
    """
    shape = _SHAPES[kind]
    what = "positive definite" if kind == "held" else "positive semi-definite with 6 rigid-body zero modes"
    A = _real_array(K, source, field, f"a real {shape[0]}x{shape[1]} matrix")
    if A.shape != shape:
        raise InputError(source, field, f"a {shape[0]}x{shape[1]} stiffness matrix", got=f"shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise InputError(source, field, "finite values", got=f"{int(np.sum(~np.isfinite(A)))} NaN/inf entries")
    scale = float(np.max(np.abs(A)))
    if scale > MAX_ENTRY:
        raise InputError(source, field, f"entries of at most {MAX_ENTRY:g} in SI (N/m, N/rad, N m/rad: the shipped "
                         "gimbal halves reach 5.5e10, a metre-long steel bar E A / L = 2e11 N/m)",
                         got=f"an entry of {scale:.3g}")
    asym = float(np.max(np.abs(A - A.T))) / scale if scale > 0 else 0.0
    if scale == 0.0:
        raise InputError(source, field, f"a {what} stiffness matrix", got="all zeros")
    if asym > SYM_TOL:
        raise InputError(source, field, "a symmetric matrix (max|K-K^T|/max|K| <= 1e-6)", got=f"asymmetry {asym:.3g}")
    d = np.diag(A)
    if np.any(d <= 0.0):
        raise InputError(source, field, f"a {what} matrix (positive diagonal)",
                         got=f"diagonal entry {int(np.argmin(d))} = {d.min():.6g}")
    s = 1.0 / np.sqrt(d)
    ev = np.linalg.eigvalsh(0.5 * (A + A.T) * np.outer(s, s))
    top = float(ev.max())
    if ev.min() < -EIG_TOL * top:
        raise InputError(source, field, f"a {what} matrix", got=f"negative eigenvalue {ev.min() / top:.3g} (scaled)")
    nzero = int(np.sum(ev < EIG_TOL * top))
    want = 0 if kind == "held" else 6
    if nzero != want:
        raise InputError(source, field, f"a {what} matrix", got=f"{nzero} zero eigenvalues")
    return 0.5 * (A + A.T)


def _real_array(K: object, source: str, field: str, expected: str) -> np.ndarray:
    """``K`` as a float array, refused (one line) unless it holds real numbers: a complex array
    (its imaginary part would be dropped silently), text, booleans or objects are no stiffness."""
    raw = K if isinstance(K, np.ndarray) else None
    if raw is None:
        try:
            raw = np.asarray(K)
        except (TypeError, ValueError):
            raise InputError(source, field, expected, got=type(K).__name__) from None
    if raw.dtype.kind not in "fiu":
        got = {"c": "complex values", "b": "booleans", "U": "text", "S": "bytes", "O": "objects"}.get(
            raw.dtype.kind, f"dtype {raw.dtype}")
        raise InputError(source, field, expected, got=got)
    return raw.astype(float)


@dataclass(frozen=True)
class GimbalStiffness:
    """A validated pair of gimbal-half stiffness matrices (one load condition).

    K_upper, K_lower : (6, 6) at the bearing centre with the bolted face held [SI blocks];
    K_upper_free, K_lower_free : (12, 12) free-free (bearing point, then bolted face) or None;
    ref_points_m : (3, 3) bearing centre, upper bolted face, lower bolted face [m] or None;
    condition : 'hanging', 'thrust' or '' (unknown); source : the file read.
    """

    K_upper: np.ndarray
    K_lower: np.ndarray
    K_upper_free: np.ndarray | None
    K_lower_free: np.ndarray | None
    ref_points_m: np.ndarray | None
    condition: str
    source: str


def _read_csv(path: Path) -> np.ndarray:
    from ..errors import check_input_file

    check_input_file(path, "a stiffness matrix file (.npz or .csv)")
    try:
        return np.loadtxt(path, delimiter=",", comments="#", ndmin=2)
    except (ValueError, UnicodeDecodeError) as exc:
        # the reason, never the file's text: a stiffness_file may point at any file of the user's
        row = re.search(r"at row (\d+)", str(exc))
        raise InputError(str(path), "matrix", "comma-separated numbers",
                         got="text that is not numbers" + (f" (row {row.group(1)})" if row else "")) from None


def read_npz(path: str | Path, field: str = "(file)") -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` file (no pickled objects); :class:`InputError` (one line) when
    it is not a readable NumPy archive, holds pickled/object data, or is empty."""
    import zipfile

    src = str(path)
    from ..errors import check_input_file

    check_input_file(path, "a NumPy .npz archive", field=field)
    try:
        with np.load(path, allow_pickle=False) as z:
            if not hasattr(z, "files"):
                raise InputError(src, field, "a NumPy .npz archive of matrices", got="a single .npy array")
            data = {k: z[k] for k in z.files}
    except InputError:
        raise
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError) as e:
        raise InputError(src, field, "a NumPy .npz archive of numeric matrices (no pickled objects)",
                         got=" ".join(str(e).split())[:100]) from None
    if not data:
        raise InputError(src, field, "a NumPy .npz archive of matrices", got="an empty archive")
    return data


def load_stiffness_matrix(path: str | Path, *, kind: str = "held", field: str = "K") -> np.ndarray:
    """Load one stiffness matrix from CSV (rows of comma-separated numbers, '#' comments)
    or NPZ (key ``field``) and validate it (see :func:`validate_stiffness_matrix`)."""
    path = Path(path)
    if not path.exists():
        raise InputError(str(path), field, "an existing .csv or .npz file", got="no such file")
    if path.suffix.lower() == ".npz":
        z = read_npz(path, field)
        if field not in z:
            raise InputError(str(path), field, "the key present", got=f"keys {sorted(z)}")
        A = z[field]
    else:
        A = _read_csv(path)
    return validate_stiffness_matrix(A, source=str(path), field=field, kind=kind)


def load_gimbal_stiffness(path: str | Path) -> GimbalStiffness:
    """Load and validate a gimbal stiffness pair.

    NPZ: keys ``K_upper``, ``K_lower`` (6x6, required), ``K_upper_free``, ``K_lower_free``
    (12x12, optional), ``ref_points_m`` (3x3, optional), ``condition`` (optional).
    CSV: 12 rows x 6 columns, K_upper stacked over K_lower ('#' comment lines allowed).
    """
    path = Path(path)
    src = str(path)
    if not path.exists():
        raise InputError(src, "K_upper", "an existing .npz or .csv file", got="no such file")
    if path.suffix.lower() == ".npz":
        data = read_npz(path, "K_upper")
        for key in ("K_upper", "K_lower"):
            if key not in data:
                raise InputError(src, key, "a 6x6 stiffness matrix", got="missing key")
        Ku = validate_stiffness_matrix(data["K_upper"], source=src, field="K_upper", kind="held")
        Kl = validate_stiffness_matrix(data["K_lower"], source=src, field="K_lower", kind="held")
        free = {}
        for key in ("K_upper_free", "K_lower_free"):
            free[key] = (validate_stiffness_matrix(data[key], source=src, field=key, kind="free")
                         if key in data else None)
        refs = None
        if "ref_points_m" in data:
            refs = _real_array(data["ref_points_m"], src, "ref_points_m", "a finite 3x3 array of points [m]")
            if refs.shape != (3, 3) or not np.all(np.isfinite(refs)):
                raise InputError(src, "ref_points_m", "a finite 3x3 array of points [m]", got=f"shape {refs.shape}")
        cond = str(data["condition"]) if "condition" in data else ""
        return GimbalStiffness(Ku, Kl, free["K_upper_free"], free["K_lower_free"], refs, cond, src)
    A = _read_csv(path)
    if A.shape != (12, 6):
        raise InputError(src, "matrix", "12 rows x 6 columns (K_upper over K_lower)", got=f"shape {A.shape}")
    Ku = validate_stiffness_matrix(A[:6], source=src, field="K_upper (rows 1-6)", kind="held")
    Kl = validate_stiffness_matrix(A[6:], source=src, field="K_lower (rows 7-12)", kind="held")
    return GimbalStiffness(Ku, Kl, None, None, None, "", src)


def _toml_value(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        f = float(v)
        if not math.isfinite(f):
            raise ValueError("non-finite value in provenance")
        return repr(f)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def write_toml(path: str | Path, tables: Mapping[str, Mapping[str, object]], header: str = "") -> None:
    """Write {section: {key: value}} as TOML (top-level keys under section '')."""
    out = [f"# {line}" for line in header.splitlines()] if header else []
    top = tables.get("", {})
    out += [f"{k} = {_toml_value(v)}" for k, v in top.items()]
    for sec, kv in tables.items():
        if sec == "":
            continue
        out += ["", f"[{sec}]"] + [f"{k} = {_toml_value(v)}" for k, v in kv.items()]
    Path(path).write_text("\n".join(out) + "\n")


MODE_KEYS = ("freq_hz", "damping_ratio", "node_names", "node_xyz_m", "phi")


def load_thrust_structure_modes(path: str | Path) -> dict[str, np.ndarray]:
    """Load fem_data/thrust_structure_modes.npz and check its contract (shapes, finiteness)."""
    src = str(path)
    if not Path(path).is_file():
        raise InputError(src, "(file)", "an existing .npz mode file", got="no such file")
    data = read_npz(path)
    for k in MODE_KEYS:
        if k not in data:
            raise InputError(src, k, "present (thrust-structure mode file contract)", got="missing key")
    n = data["freq_hz"].shape[0]
    checks = {"damping_ratio": (n,), "node_names": (12,), "node_xyz_m": (12, 3), "phi": (n, 12, 6)}
    for k, shp in checks.items():
        if data[k].shape != shp:
            raise InputError(src, k, f"shape {shp}", got=f"shape {data[k].shape}")
    for k in ("freq_hz", "damping_ratio", "node_xyz_m", "phi"):
        if not np.all(np.isfinite(data[k])):
            raise InputError(src, k, "finite values", got="NaN/inf")
    if np.any(data["freq_hz"] <= 0) or np.any(np.diff(data["freq_hz"]) < 0):
        raise InputError(src, "freq_hz", "positive, non-decreasing frequencies")
    return data
