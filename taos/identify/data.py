"""Test data import: vectoring time histories from CSV or HDF5, validated, in SI.

What the Green Run team had (seed paper sec. 2): FCS pitch and yaw commands, piston
positions, and engine angles from string pots that carry an unknown constant offset (no
absolute reference). :func:`load_test_data` reads such a record into :class:`TestData`.

Signals (canonical names, unit kind)::

    time [time], pitch_command, yaw_command [angle], pitch_piston, yaw_piston [length],
    pitch_engine, yaw_engine [angle]; optional hydraulic signals: pitch_load_pressure,
    yaw_load_pressure [pressure] (P_L), pitch_spool, yaw_spool [velocity] (servovalve
    opening as its no-load piston rate K_q x_v / A, as :class:`taos.planar.simulate.TimeHistory`
    records it), supply_pressure [pressure]

CSV layout: optional leading ``#`` lines holding TOML metadata (``# condition = "hot fire"``,
``# engine_angle_reference = "relative"``, ``# synthetic = true``, ``# test_date = 2026-03-09``: the
date of the test, a TOML date or ISO-8601 text, which orders a test series in ``taos compare
--records``), then a header row whose
columns are ``signal [unit]`` (``pitch_command [deg]``), then numbers. Or any column names
with a sidecar TOML beside the file (``run.csv`` + ``run.toml``) that says it is the record's
sidecar by naming it (``sidecar_for``, :data:`SIDECAR_MARK`; a TOML of the same stem without it,
such as a command profile, is never read as the sidecar)::

    sidecar_for = "run.csv"
    condition = "ambient"
    engine_angle_reference = "relative"     # or "absolute"
    [columns]
    t = {signal = "time", unit = "s"}
    cmd_p = {signal = "pitch_command", unit = "deg"}

HDF5: a ``taos simulate`` :class:`~taos.planar.simulate.TimeHistory` file (``/t_s``, ``/<axis>/...``,
engine angles absolute), or root datasets named by signal with a ``unit`` attribute and the
metadata as root attributes.

Validation: time strictly increasing (reversed or repeated samples are refused), every value
finite, all columns the same length, at least 16 samples, every axis with a command has its
piston; engine angles for all commanded axes or none. Irregular sampling (spread of the
sample interval above 0.1 % of its median) is resampled by linear interpolation onto the
median interval (``resampled`` says so). Errors are one line: ``InputError(file, column,
expected, got)``; nothing is written by reading.
"""

from __future__ import annotations

import datetime as _dt
import io
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from taos.errors import InputError
from taos.bounds import MAX_DATA_SAMPLES, MAX_RESAMPLE_FACTOR
from taos.planar.runfile import SIGNAL_LIMITS  # noqa: F401  (largest magnitude of a signal by unit kind, and why)
from taos.results import atomic_write

AXES = ("pitch", "yaw")
#: canonical signal name -> (unit kind, SI unit, example unit)
SIGNALS = {
    "time": ("time", "s", "'s'"),
    "pitch_command": ("angle", "rad", "'deg'"),
    "yaw_command": ("angle", "rad", "'deg'"),
    "pitch_piston": ("length", "m", "'in'"),
    "yaw_piston": ("length", "m", "'in'"),
    "pitch_engine": ("angle", "rad", "'deg'"),
    "yaw_engine": ("angle", "rad", "'deg'"),
    "pitch_load_pressure": ("pressure", "Pa", "'psi'"),
    "yaw_load_pressure": ("pressure", "Pa", "'psi'"),
    "pitch_spool": ("velocity", "m/s", "'in/s'"),
    "yaw_spool": ("velocity", "m/s", "'in/s'"),
    "supply_pressure": ("pressure", "Pa", "'psi'"),
}
#: optional per-axis hydraulic signals: (signal suffix, TestData field, CSV unit)
HYDRAULIC = (("load_pressure", "load_pressure_Pa", "psi"), ("spool", "spool_flow_m_s", "in/s"))
MIN_SAMPLES = 16
IRREGULAR_TOL = 1e-3
#: sample rate of a record [Hz]: test-stand DAQs record 100 Hz to 100 kHz; a rate outside
#: 1 Hz .. 1 MHz is a time column in the wrong unit (ms read as s, or the reverse)
SAMPLE_RATE_HZ = (1.0, 1e6)
#: longest record [s]: three times the longest documented run (taos.bounds.MAX_DURATION_S)
MAX_RECORD_S = 3e4


@dataclass(frozen=True, eq=False)
class TestData:
    """A validated vectoring record (SI; arrays (n_axes, n)).

    ``engine_rad`` is None when no engine angles were recorded; ``engine_absolute`` False means
    the engine angles carry an unknown constant offset (string pots), so their DC level (the
    0 Hz engine gain) is unobservable. ``condition`` ("ambient", "hot fire", ...) and
    ``synthetic`` come from the file's metadata.
    """

    __test__ = False  # not a pytest class

    source: str
    t_s: np.ndarray
    axes: tuple[str, ...]
    command_rad: np.ndarray
    piston_m: np.ndarray
    engine_rad: np.ndarray | None
    engine_absolute: bool = False
    condition: str = ""
    synthetic: bool = False
    resampled: bool = False
    metadata: dict = field(default_factory=dict)
    load_pressure_Pa: np.ndarray | None = None
    spool_flow_m_s: np.ndarray | None = None
    supply_pressure_Pa: np.ndarray | None = None

    @property
    def sample_rate_hz(self) -> float:
        return float(1.0 / np.median(np.diff(self.t_s)))

    def window(self, t0_s: float, t1_s: float) -> "TestData":
        """The samples with t0_s <= t <= t1_s [s] (a segment of the record; same metadata)."""
        from dataclasses import replace

        m = (self.t_s >= t0_s) & (self.t_s <= t1_s)
        opt = lambda a: None if a is None else np.asarray(a)[..., m]  # noqa: E731
        return replace(self, t_s=self.t_s[m], command_rad=self.command_rad[:, m], piston_m=self.piston_m[:, m],
                       engine_rad=opt(self.engine_rad), load_pressure_Pa=opt(self.load_pressure_Pa),
                       spool_flow_m_s=opt(self.spool_flow_m_s), supply_pressure_Pa=opt(self.supply_pressure_Pa))

    def axis_index(self, axis: str) -> int:
        if axis not in self.axes:
            raise InputError(self.source, f"{axis}_command", f"a {axis} command column", got="none")
        return self.axes.index(axis)

    def to_csv(self, path, digits: int = 8, piston_unit: str = "in", angle_unit: str = "deg") -> None:
        """Write this record as CSV with a TOML-comment header and ``signal [unit]`` columns
        (atomically)."""
        from taos.units import Q_

        pf = float(Q_(1.0, "m").to(piston_unit).magnitude)
        af = float(Q_(1.0, "rad").to(angle_unit).magnitude)
        cols, names = [self.t_s], ["time [s]"]
        for i, ax in enumerate(self.axes):
            cols.append(self.command_rad[i] * af)
            names.append(f"{ax}_command [{angle_unit}]")
            cols.append(self.piston_m[i] * pf)
            names.append(f"{ax}_piston [{piston_unit}]")
            if self.engine_rad is not None:
                cols.append(self.engine_rad[i] * af)
                names.append(f"{ax}_engine [{angle_unit}]")
            for sig, fld, unit in HYDRAULIC:
                if getattr(self, fld) is not None:
                    cols.append(getattr(self, fld)[i] / float(Q_(1.0, unit).to(SIGNALS[f"{ax}_{sig}"][1]).magnitude))
                    names.append(f"{ax}_{sig} [{unit}]")
        if self.supply_pressure_Pa is not None:
            cols.append(self.supply_pressure_Pa / float(Q_(1.0, "psi").to("Pa").magnitude))
            names.append("supply_pressure [psi]")
        meta = {"condition": self.condition, "synthetic": self.synthetic,
                "engine_angle_reference": "absolute" if self.engine_absolute else "relative",
                **{k: v for k, v in self.metadata.items() if isinstance(v, (str, int, float, bool, _dt.date))}}
        buf = io.StringIO()
        for k, v in meta.items():
            buf.write(f"# {k} = {_toml_value(v)}\n")
        buf.write(",".join(names) + "\n")
        np.savetxt(buf, np.column_stack(cols), delimiter=",", fmt=f"%.{digits}g")
        text = buf.getvalue()
        atomic_write(path, lambda p: p.write_text(text))


def _toml_value(v) -> str:
    if isinstance(v, _dt.date):   # a TOML date or date-time literal
        return v.isoformat()
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    return '"' + str(v).replace("\\", "\\\\").replace('"', '\\"') + '"'


def unit_factor(unit: str, signal: str, source: str, column: str) -> float:
    """SI factor of ``unit`` for ``signal`` (e.g. 'deg' for an angle -> pi/180)."""
    kind, si, example = SIGNALS[signal]
    from taos.units import Q_, check_unit_text

    check_unit_text(unit, source, column, f"a {kind} unit like {example}")
    try:
        q = Q_(1.0, unit)
        ok = q.dimensionality == Q_(1.0, si).dimensionality
    except Exception:  # pint raises several error types for unknown units
        ok = False
    if not ok:
        raise InputError(source, column, f"a {kind} unit like {example}", got=repr(unit))
    return float(q.to(si).magnitude)


def _split_header(name: str) -> tuple[str, str | None]:
    """'pitch_command [deg]' -> ('pitch_command', 'deg')."""
    name = name.strip()
    if name.endswith("]") and "[" in name:
        base, unit = name[:-1].split("[", 1)
        return base.strip(), unit.strip()
    return name, None


#: metadata keys the loader reads; other metadata is kept as free-form provenance, but a key
#: close to one of these (a typo such as ``conditon``) is refused with the nearest suggested
META_KEYS = {"condition", "synthetic", "engine_angle_reference", "description", "test_date"}


def _check_meta(meta: dict, src: str, sidecar: bool, typos: bool = True) -> None:
    """The metadata keys the loader reads of the right type; with ``typos``, a key close to one
    of them refused (an HDF5 run's provenance attributes are not checked for those)."""
    from taos.errors import nearest

    known = META_KEYS | ({"columns", SIDECAR_MARK} if sidecar else set())
    for k in (meta if typos else ()):
        if k not in known:
            guess = nearest(k, known)
            if guess is not None:
                raise InputError(src, k, f"a known key (did you mean {guess!r}?)", got="an unknown key")
    if "synthetic" in meta and not isinstance(meta["synthetic"], bool):
        raise InputError(src, "synthetic", "true or false", got=repr(meta["synthetic"])[:60])
    if "test_date" in meta:
        _test_date(meta["test_date"], src)
    for k in ("condition", "engine_angle_reference", "description"):
        if k in meta and not isinstance(meta[k], str):
            raise InputError(src, k, "a text value", got=repr(meta[k])[:60])


def _test_date(v, src: str):
    """The ``test_date`` metadata as a :class:`datetime.date` or :class:`datetime.datetime`
    (a TOML date or date-time, or ISO-8601 text), else InputError."""
    import datetime as dt

    if isinstance(v, (dt.date, dt.datetime)):
        return v
    if isinstance(v, str):
        try:
            return dt.datetime.fromisoformat(v) if "T" in v or " " in v.strip() else dt.date.fromisoformat(v)
        except ValueError:
            pass
    raise InputError(src, "test_date", "a date like 2026-03-14 (ISO 8601, or a TOML date)", got=repr(v)[:60])


def record_date(data: "TestData"):
    """The record's ``test_date`` (:class:`datetime.date`/``datetime``) or None."""
    v = data.metadata.get("test_date")
    return None if v is None else _test_date(v, data.source)


#: the key by which a TOML beside a record says it is that record's sidecar: its value is the
#: record's file name (``sidecar_for = "run.csv"``); a TOML of the same stem without it (a
#: command profile ``run.toml`` beside ``run.csv``) is not read as the sidecar
SIDECAR_MARK = "sidecar_for"


def _sidecar(path: Path, sidecar: Path) -> dict | None:
    """The sidecar TOML of record ``path`` (``sidecar``, same stem) parsed, when it exists and
    says it is this record's sidecar (:data:`SIDECAR_MARK` naming ``path``'s file name); None
    when there is none or it does not say so; InputError when it names another record."""
    from taos.errors import parse_toml, read_input_bytes

    if not sidecar.exists():
        return None
    side = parse_toml(read_input_bytes(sidecar, "a readable sidecar TOML file"), str(sidecar))
    if SIDECAR_MARK not in side:
        return None
    mark = side.pop(SIDECAR_MARK)
    if mark != path.name:
        raise InputError(str(sidecar), SIDECAR_MARK, f"the file name of the record it describes, {path.name!r}",
                         got=repr(mark)[:60])
    return side


def _read_csv(path: Path, src: str) -> tuple[dict, dict, dict]:
    """Returns (metadata, {signal: array SI}, {signal: column label}). Streams the numbers
    (``numpy.loadtxt`` on the open file), so memory stays near the size of the array itself."""
    from taos.errors import check_input_file

    check_input_file(path, "a readable CSV text file")
    try:
        f = open(path, encoding="utf-8")
    except OSError as e:
        raise InputError(src, "(file)", "a readable CSV text file", got=e.strerror) from None
    with f:
        meta_lines, k, header_line = [], 0, None
        try:
            for line in f:
                if line.startswith("#") or not line.strip():
                    meta_lines.append(line.lstrip("#").strip())
                    k += 1
                    continue
                header_line = line
                break
        except UnicodeDecodeError as e:
            raise InputError(src, "(file)", "a readable CSV text file", got=str(e)[:80]) from None
        if header_line is None:
            raise InputError(src, "(header)", "a header row of column names like 'time [s],pitch_command [deg],...'",
                             got="no rows")
        from taos.errors import parse_toml

        meta = parse_toml("\n".join(meta_lines).encode("utf-8"), src)
        _check_meta(meta, src, sidecar=False)
        header = [h.strip() for h in header_line.split(",")]
        dup = next((h for i, h in enumerate(header) if h in header[:i]), None)
        if dup is not None:
            raise InputError(src, dup, "each column name once in the header", got="a repeated column name")
        if any(not h for h in header):
            raise InputError(src, "(header)", "a name for every column", got=f"an empty name in column "
                             f"{header.index('') + 1}")
        sidecar = path.with_suffix(".toml")
        mapping: dict[str, tuple[str, str]] = {}
        side = _sidecar(path, sidecar)
        if side is not None:
            _check_meta(side, str(sidecar), sidecar=True)
            cols = side.pop("columns", {})
            if not isinstance(cols, dict):
                raise InputError(str(sidecar), "columns", "a [columns] table of {signal = '...', unit = '...'}",
                                 got=repr(cols)[:60])
            meta.update(side)
            for col, spec in cols.items():
                if not isinstance(spec, dict) or "signal" not in spec or "unit" not in spec:
                    raise InputError(str(sidecar), f"columns.{col}", "a table {signal = '...', unit = '...'}",
                                     got=repr(spec)[:60])
                from taos.errors import check_keys
                check_keys(spec, {"signal", "unit"}, str(sidecar), f"columns.{col}")
                if spec["signal"] not in SIGNALS:
                    raise InputError(str(sidecar), f"columns.{col}.signal", "one of " + ", ".join(SIGNALS),
                                     got=repr(spec["signal"]))
                if not isinstance(spec["unit"], str):
                    raise InputError(str(sidecar), f"columns.{col}.unit", "a unit name like 'deg'", got=repr(spec["unit"]))
                if col not in header:
                    raise InputError(src, col, f"a column named {col!r} (from {sidecar.name})", got="no such column")
                mapping[col] = (spec["signal"], str(spec["unit"]))
        else:
            for h in header:
                base, unit = _split_header(h)
                if base in SIGNALS:
                    if unit is None:
                        raise InputError(src, h, f"a unit in brackets like '{base} [{SIGNALS[base][2][1:-1]}]'",
                                         got="no unit")
                    mapping[h] = (base, unit)
            if not mapping and sidecar.exists():   # a TOML beside it that does not say it is the sidecar
                raise InputError(src, "(header)", f"columns named 'signal [unit]' ({sidecar.name} beside it is not "
                                 f"read as its sidecar: it has no {SIDECAR_MARK} = {path.name!r})",
                                 got="no known signal column")
        try:
            with warnings.catch_warnings():   # a header without rows: refused below by its sample count
                warnings.filterwarnings("ignore", "loadtxt: input contained no data")
                arr = np.loadtxt(f, delimiter=",", dtype=float, ndmin=2, comments=None)
        except (ValueError, UnicodeDecodeError) as e:
            raise InputError(src, "(rows)", f"{len(header)} comma-separated numbers per row",
                             got=" ".join(str(e).split())[:120]) from None
    if arr.size == 0:
        arr = np.zeros((0, len(header)))
    if arr.shape[1] != len(header):
        raise InputError(src, "(rows)", f"{len(header)} columns as in the header", got=f"{arr.shape[1]}")
    if arr.shape[0] > MAX_DATA_SAMPLES:
        raise InputError(src, "(rows)", f"at most {MAX_DATA_SAMPLES} samples", got=str(arr.shape[0]))
    out, labels = {}, {}
    for col, (sig, unit) in mapping.items():
        j = header.index(col)
        fct = unit_factor(unit, sig, src, col)
        x = arr[:, j]
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise InputError(src, col, "finite numbers in every row", got=f"{x[bad[0]]} at data row {bad[0] + 1}")
        if sig in out:
            raise InputError(src, col, f"one column for {sig}", got="a second one")
        out[sig] = x * fct
        labels[sig] = col
    return meta, out, labels


def _read_hdf5(path: Path, src: str) -> tuple[dict, dict, dict]:
    """Returns (metadata, {signal: array SI}, {signal: dataset name}). Every dataset read through
    the run-file reader (:mod:`taos.planar.runfile`: stored in the file, real, 1-D, finite; a
    ``taos simulate`` run validated whole, as ``taos view`` reads it)."""
    from taos.planar.runfile import dataset, has, open_hdf5, text_attr

    with open_hdf5(path, src, "a readable HDF5 file") as h5:
        out, labels = {}, {}
        if "axes" in h5.attrs and has(h5, "t_s", src):  # a taos simulate TimeHistory
            from taos.planar.runfile import read_run
            from taos.planar.simulate import TimeHistory

            run = read_run(h5, src, TimeHistory.ARRAYS, TimeHistory.OPTIONAL_ARRAYS)   # the whole run, as taos view reads it
            out["time"], labels["time"] = run["t_s"], "/t_s"
            for i, ax in enumerate(run["axes"]):
                for sig, name in (("command", "command_rad"), ("piston", "piston_m"), ("engine", "engine_rad"),
                                  ("load_pressure", "load_pressure_Pa"), ("spool", "spool_flow_m_s")):
                    if name in run:
                        out[f"{ax}_{sig}"], labels[f"{ax}_{sig}"] = run[name][i], f"/{ax}/{name}"
                if "supply_pressure_Pa" in run and "supply_pressure" not in out:
                    out["supply_pressure"] = run["supply_pressure_Pa"][i]
                    labels["supply_pressure"] = f"/{ax}/supply_pressure_Pa"
            meta = {k: (v.decode("utf-8", "replace") if isinstance(v, bytes) else v)   # the root attributes
                    for k, v in h5.attrs.items() if k != "moment_arm_m"}
            meta["moment_arm_m"] = float(run["moment_arm_m"])   # (validated by read_run)
            meta.setdefault("engine_angle_reference", "absolute")
            meta.setdefault("synthetic", True)
        else:
            meta = {k: (v.decode("utf-8", "replace") if isinstance(v, bytes) else v) for k, v in h5.attrs.items()}
            for sig in SIGNALS:
                if has(h5, sig, src):
                    x = dataset(h5, sig, src)
                    ds = h5[sig]
                    if "unit" not in ds.attrs:
                        raise InputError(src, "/" + sig, "a 'unit' attribute like " + SIGNALS[sig][2], got="none")
                    unit = text_attr(ds, "unit", src + ": /" + sig)
                    out[sig] = x * unit_factor(unit, sig, src, "/" + sig)
                    labels[sig] = "/" + sig
    meta = {k: (str(v) if isinstance(v, np.str_) else bool(v) if isinstance(v, np.bool_) else v) for k, v in meta.items()}
    _check_meta(meta, src, sidecar=False, typos=False)
    return meta, out, labels


def load_test_data(path: str | Path, *, resample: bool = True) -> TestData:
    """Read and validate a vectoring record (CSV or HDF5, see the module docstring).

    Parameters
    ----------
    path : str | Path
        ``.csv`` (with ``signal [unit]`` headers or a sidecar ``.toml``) or ``.h5``/``.hdf5``.
    resample : bool
        Resample irregular time stamps onto the median interval (else refuse them).
    """
    from taos.bounds import check_flag
    from taos.errors import check_input_file

    check_flag(resample, "resample")
    check_input_file(path, "a readable data file (.csv or .h5)")   # a path, not None or a number
    p = Path(path)
    src = str(path)
    if not p.exists():
        raise InputError(src, "(file)", "an existing data file", got="no such file")
    from taos.errors import check_input_file

    check_input_file(p, "a readable data file (.csv or .h5)")
    if p.suffix.lower() in (".h5", ".hdf5"):
        meta, sig, labels = _read_hdf5(p, src)
    elif p.suffix.lower() in (".csv", ".txt"):
        meta, sig, labels = _read_csv(p, src)
    else:
        raise InputError(src, "(file)", "a .csv or .h5 file", got=repr(p.suffix))
    if "time" not in sig:
        raise InputError(src, "time", "a time column like 'time [s]'", got="none")
    t = sig["time"]
    n = t.size
    for s, x in sig.items():
        if x.size != n:
            raise InputError(src, labels[s], f"{n} samples like the time column", got=str(x.size))
    if n < MIN_SAMPLES:
        raise InputError(src, labels["time"], f"at least {MIN_SAMPLES} samples", got=str(n))
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        i = bad[0]
        raise InputError(src, labels["time"], "strictly increasing time",
                         got=f"{t[i + 1]:.9g} s after {t[i]:.9g} s at sample {i + 1}")
    _check_record_sanity(src, t, sig, labels)
    axes = tuple(ax for ax in AXES if f"{ax}_command" in sig)
    if not axes:
        raise InputError(src, "pitch_command", "a pitch_command or yaw_command column", got="none")
    for ax in axes:
        if f"{ax}_piston" not in sig:
            raise InputError(src, f"{ax}_piston", f"a piston position column for the commanded {ax} axis",
                             got="none")
    has_engine = [f"{ax}_engine" in sig for ax in axes]
    if any(has_engine) and not all(has_engine):
        missing = axes[has_engine.index(False)]
        raise InputError(src, f"{missing}_engine", "engine angles for every commanded axis or none", got="none")
    ref = str(meta.get("engine_angle_reference", "relative"))
    if ref not in ("relative", "absolute"):
        raise InputError(src, "engine_angle_reference", "'relative' or 'absolute'", got=repr(ref))
    resampled = False
    med = float(np.median(dt))
    if (dt.max() - dt.min()) > IRREGULAR_TOL * med:
        if not resample:
            raise InputError(src, labels["time"], f"a regular sample interval (spread below {IRREGULAR_TOL:.0e})",
                             got=f"intervals from {dt.min():.6g} s to {dt.max():.6g} s")
        n_new = (t[-1] - t[0]) / med + 1
        if not n_new <= MAX_RESAMPLE_FACTOR * n:
            j = int(np.argmax(dt))
            raise InputError(src, labels["time"], f"time stamps spanning at most {MAX_RESAMPLE_FACTOR:g} x the "
                             f"samples at the median interval {med:.6g} s (resampling would need {n_new:.3g} samples)",
                             got=f"{t[j + 1]:.9g} s after {t[j]:.9g} s at sample {j + 1}")
        tn = t[0] + med * np.arange(int(math.floor((t[-1] - t[0]) / med)) + 1)
        sig = {s: (tn if s == "time" else np.interp(tn, t, x)) for s, x in sig.items()}
        t = tn
        resampled = True
    stack = lambda kind: np.vstack([sig[f"{ax}_{kind}"] for ax in axes])  # noqa: E731
    hyd = {}
    for name, fld, _ in HYDRAULIC:
        have = [f"{ax}_{name}" in sig for ax in axes]
        if any(have) and not all(have):
            miss = axes[have.index(False)]
            raise InputError(src, f"{miss}_{name}", f"{name} for every commanded axis or none", got="none")
        hyd[fld] = stack(name) if all(have) else None
    return TestData(supply_pressure_Pa=sig.get("supply_pressure"), **hyd,
                    source=src, t_s=t, axes=axes, command_rad=stack("command"), piston_m=stack("piston"),
                    engine_rad=stack("engine") if all(has_engine) else None,
                    engine_absolute=(ref == "absolute"), condition=str(meta.get("condition", "")),
                    synthetic=bool(meta.get("synthetic", False)), resampled=resampled,
                    metadata={k: v for k, v in meta.items()
                              if k not in ("condition", "synthetic", "engine_angle_reference")})


def _check_record_sanity(src: str, t, sig: dict, labels: dict) -> None:
    """The record's sample rate within :data:`SAMPLE_RATE_HZ`, its length within
    :data:`MAX_RECORD_S`, and every signal within :data:`SIGNAL_LIMITS` (time strictly
    increasing is checked before)."""
    half = float(t[-1]) / 2 - float(t[0]) / 2   # the span halved: finite for any finite times
    lo, hi = SAMPLE_RATE_HZ
    rate = (t.size - 1) / (2 * half) if half < MAX_RECORD_S else 0.0   # (a span beyond the record bound: refused below)
    if not lo <= rate <= hi:
        raise InputError(src, labels["time"], f"a sample rate from {lo:g} to {hi:g} Hz (a time column in "
                         "seconds as its unit says)", got=f"{(t.size - 1) / 2 / half:.4g} Hz")
    if 2 * half > MAX_RECORD_S:
        raise InputError(src, labels["time"], f"a record of at most {MAX_RECORD_S:g} s", got=f"{2 * half:.4g} s")
    for name, x in sig.items():
        kind = SIGNALS[name][0]
        if kind in SIGNAL_LIMITS and x.size:
            lim, why = SIGNAL_LIMITS[kind]
            i = int(np.argmax(np.abs(x)))
            if abs(x[i]) > lim:
                raise InputError(src, labels[name], f"magnitudes of at most {lim:g} {SIGNALS[name][1]} ({why})",
                                 got=f"{x[i]:.4g} {SIGNALS[name][1]} at sample {i}")


def from_time_history(th, *, engine_offset_rad=None, condition: str = "", source: str = "<simulation>",
                      synthetic: bool = True) -> TestData:
    """A :class:`TestData` view of a :class:`~taos.planar.simulate.TimeHistory` (engine angles
    absolute unless an ``engine_offset_rad`` per axis is added, which makes them relative)."""
    eng = np.asarray(th.engine_rad, float)
    if engine_offset_rad is not None:
        eng = eng + np.asarray(engine_offset_rad, float).reshape(-1, 1)
    return TestData(source=source, t_s=np.asarray(th.t_s, float), axes=tuple(th.axes),
                    command_rad=np.asarray(th.command_rad, float), piston_m=np.asarray(th.piston_m, float),
                    engine_rad=eng, engine_absolute=engine_offset_rad is None, condition=condition,
                    synthetic=synthetic, metadata={"moment_arm_m": float(th.moment_arm_m)},
                    load_pressure_Pa=getattr(th, "load_pressure_Pa", None),
                    spool_flow_m_s=getattr(th, "spool_flow_m_s", None),
                    supply_pressure_Pa=None if getattr(th, "supply_pressure_Pa", None) is None
                    else np.asarray(th.supply_pressure_Pa)[0])
