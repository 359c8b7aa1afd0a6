"""Engineering units at the edges, SI floats inside.

One pint registry for the whole package. Model files, CLI options and reports carry
strings such as ``"115000 lbf/in"`` or ``"144000 in*lbf"``; :func:`to_si` turns them into
plain SI floats after checking their dimension, and :func:`from_si` formats SI floats
back into engineering units for reports. :func:`parse_float_list` reads an option's
comma-separated list of numbers (``--freq-hz 0.5,1,2``) for both command lines.

Start-up: pint takes about a quarter of a second to import and set up, longer than a whole
``taos info``. So the registry (``ureg``, ``Q_``) is built on first use, with its parsed
definitions cached on disk by pint, and :func:`to_si` remembers what pint said about each
(unit, kind) pair it has seen: the unit's dimension matches the kind and SI = a * value + b
(``a``, ``b`` from pint). The table lives in the user cache directory, keyed by the installed
pint, so a later run converts a known unit without importing pint. Every value goes through
the same a * value + b whether the table was warm or cold, so results do not depend on it.
"""

from __future__ import annotations

import functools
import json
import math
import os
import re
from pathlib import Path

from .errors import InputError

# -- the unit table: every hand-written conversion factor of the package, once -----------------
# From the exact definitions (1 lbf = 4.4482216152605 N, 1 in = 0.0254 m; pint's are the same,
# its float arithmetic a few ulp away: tests/test_units_table.py checks each against pint). The
# derived factors are the float expressions below (within 2 ulp of the exact decimal value).

#: newtons per pound-force [N/lbf] (exact: 0.45359237 kg x 9.80665 m/s^2)
N_PER_LBF = 4.4482216152605
#: metres per inch [m/in] (exact)
M_PER_IN = 0.0254
#: stiffness, (N/m) per (lbf/in) [N/m per lbf/in] = N_PER_LBF / M_PER_IN
N_PER_M_PER_LBF_PER_IN = N_PER_LBF / M_PER_IN
#: torque, (N m) per (in lbf) [N m per in lbf] = N_PER_LBF * M_PER_IN
NM_PER_IN_LBF = N_PER_LBF * M_PER_IN
#: pressure, pascals per psi [Pa/psi] = N_PER_LBF / M_PER_IN^2
PA_PER_PSI = N_PER_LBF / (M_PER_IN * M_PER_IN)


@functools.cache
def _registry():
    """pint's default registry, its parsed definitions cached on disk (``cache_folder``, the
    user cache directory); plain when no cache can be used."""
    import pint

    try:
        ureg = pint.UnitRegistry(cache_folder=":auto:")
    except Exception:  # an unwritable or broken cache: parse the definitions as usual
        ureg = pint.UnitRegistry()
    return ureg


def __getattr__(name: str):
    """``ureg`` (the registry) and ``Q_`` (its Quantity), built on first use."""
    if name == "ureg":
        return _registry()
    if name == "Q_":
        return _registry().Quantity
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _Q(*args):
    return _registry().Quantity(*args)


_NUMBER_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s+([A-Za-z][^\s].*?|[A-Za-z]|1\s*/\s*[A-Za-z].*?)\s*$")

#: longest value text accepted ("115000 lbf/in" is 13 characters)
MAX_VALUE_TEXT = 64
_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
_POW = r"(?:\s*(?:\*\*|\^)\s*[-+]?\d{1,2})?"
#: the unit grammar: names joined by * and /, each with at most one small whole-number power
#: (``in*lbf``, ``kg*m**2``, ``m**3/s/Pa``, ``1/s``); no numbers elsewhere, no parentheses, no
#: chained powers: the text is parsed, never evaluated as an expression (``9**9**9`` would not end)
UNIT_GRAMMAR = re.compile(rf"^(?:1\s*/\s*)?{_NAME}{_POW}(?:\s*[*/]\s*{_NAME}{_POW})*$")
_VALUE = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d{1,3})?)\s*(.*?)\s*$")


def check_value_text(value: str, source: str, field: str, expected: str) -> str:
    """Refuse value text that is not a plain decimal number followed by an optional unit of
    :data:`UNIT_GRAMMAR`, or longer than :data:`MAX_VALUE_TEXT`; returns the unit text ('' for
    none). Run before pint sees a value, so that no text is ever evaluated as an expression."""
    v = _VALUE.match(value) if isinstance(value, str) and len(value) <= MAX_VALUE_TEXT else None
    if v is None or (v.group(2) and not UNIT_GRAMMAR.match(v.group(2))):
        raise InputError(source, field, expected, got=repr(value)[:MAX_VALUE_TEXT + 2])
    return v.group(2)


def check_unit_text(unit: str, source: str, field: str, expected: str = "a unit like 'deg' or 'lbf/in'") -> str:
    """Refuse unit text outside :data:`UNIT_GRAMMAR` (or longer than :data:`MAX_VALUE_TEXT`)
    before pint sees it; returns it stripped."""
    if not isinstance(unit, str) or len(unit) > MAX_VALUE_TEXT or not UNIT_GRAMMAR.match(unit.strip()):
        got = repr(unit)[:MAX_VALUE_TEXT + 2] if isinstance(unit, str) else repr(unit)[:40]
        raise InputError(source, field, expected + " (unit names joined by * and /, each with at most a "
                         "two-digit power)", got=got)
    return unit.strip()


def cache_folder() -> Path:
    """The folder of taos's own caches (``$XDG_CACHE_HOME/taos``, default ``~/.cache/taos``):
    derived tables, never an input of a run."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "taos"


@functools.cache
def _cache_file() -> Path | None:
    """The (unit, kind) table's file: keyed by the installed pint's location, size and time."""
    import importlib.util

    try:
        spec = importlib.util.find_spec("pint")
        st = os.stat(spec.origin)
    except Exception:
        return None
    key = f"{spec.origin}:{st.st_size}:{st.st_mtime_ns}"
    import hashlib

    return cache_folder() / f"units-{hashlib.sha256(key.encode()).hexdigest()[:16]}.json"


@functools.cache
def _table() -> dict:
    f = _cache_file()
    try:
        d = json.loads(f.read_text()) if f is not None else {}
        return d if isinstance(d, dict) else {}
    except Exception:
        return {}


def _remember(key: str, ab: tuple[float, float]) -> None:
    t = _table()
    t[key] = list(ab)
    f = _cache_file()
    if f is None:
        return
    try:
        f.parent.mkdir(parents=True, exist_ok=True)
        tmp = f.with_name(f"{f.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(t))
        os.replace(tmp, f)
    except OSError:  # a read-only home: convert through pint every time
        pass


def _affine(unit: str, kind: str) -> tuple[float, float] | None:
    """(a, b) with SI = a * value + b for ``unit`` of ``kind`` (pint's word, remembered), or
    None if pint does not know ``unit`` as a ``kind``."""
    key = f"{kind}|{unit}"
    ab = _table().get(key)
    if ab is not None:
        return float(ab[0]), float(ab[1])
    try:
        q1 = _Q(1.0, unit)
        if q1.dimensionality != _dimensionality(kind):
            return None
        si = DIMENSIONS[kind][1]
        b = float(_Q(0.0, unit).to(si).magnitude)
        a = float(q1.to(si).magnitude) - b
    except Exception:  # pint raises several error types for unknown or odd units
        return None
    if not (math.isfinite(a) and math.isfinite(b)):
        return None
    _remember(key, (a, b))
    return a, b

#: Named physical dimensions used by model-file fields: name -> (pint dimensionality
#: expressed by a reference unit, SI unit string, example shown in error messages).
DIMENSIONS: dict[str, tuple[str, str, str]] = {
    "length": ("m", "m", "'0.8 m'"),
    "mass": ("kg", "kg", "'3527 kg'"),
    "inertia": ("kg*m**2", "kg*m**2", "'12000 kg*m**2'"),
    "stiffness": ("N/m", "N/m", "'115000 lbf/in'"),
    "rotational_stiffness": ("N*m/rad", "N*m/rad", "'500000 N*m/rad'"),
    "torque": ("N*m", "N*m", "'144000 in*lbf'"),
    "force": ("N", "N", "'1860 kN'"),
    "pressure": ("Pa", "Pa", "'3000 psi'"),
    "area": ("m**2", "m**2", "'15 in**2'"),
    "volume": ("m**3", "m**3", "'200 in**3'"),
    "angle": ("rad", "rad", "'0.4 deg'"),
    "angular_velocity": ("rad/s", "rad/s", "'0.01 deg/s'"),
    "velocity": ("m/s", "m/s", "'0.01 m/s'"),
    "frequency": ("Hz", "Hz", "'120 Hz'"),
    "rate": ("1/s", "1/s", "'70 1/s'"),
    "time": ("s", "s", "'0.02 s'"),
    "damping": ("N*s/m", "N*s/m", "'20000 N*s/m'"),
    "rotational_damping": ("N*m*s/rad", "N*m*s/rad", "'1e6 N*m*s/rad'"),
    "flow": ("m**3/s", "m**3/s", "'20 gal/min'"),
    "flow_pressure": ("m**3/s/Pa", "m**3/s/Pa", "'1e-12 m**3/s/Pa'"),
    "velocity_per_pressure": ("m/s/Pa", "m/s/Pa", "'4e-8 m/s/Pa'"),
    "dimensionless": ("dimensionless", "1", "'0.95'"),
}


def _dimensionality(kind: str):
    return _Q(1.0, DIMENSIONS[kind][0]).dimensionality


def to_si(value: object, kind: str, *, source: str, field: str, positive: bool = False,
          nonnegative: bool = False) -> float:
    """Parse ``value`` (a string with unit, or a plain number for dimensionless fields) to SI.

    Parameters
    ----------
    value : str | float
        e.g. ``"115000 lbf/in"``. Plain numbers are accepted only for ``kind="dimensionless"``.
    kind : str
        A key of :data:`DIMENSIONS`.
    source, field : str
        Where the value came from, for the one-line error.
    positive, nonnegative : bool
        Extra range checks.

    Returns
    -------
    float
        The value in the SI unit of ``DIMENSIONS[kind][1]`` (angles in rad, frequencies in Hz).
    """
    ref, si_unit, example = DIMENSIONS[kind]
    expected = f"a {kind.replace('_', ' ')} with its unit, like {example}"
    if isinstance(value, bool):
        raise InputError(source, field, expected, got=repr(value))
    if isinstance(value, str):   # parsed here, never evaluated: a number and a unit of the grammar
        if not check_value_text(value, source, field, expected) and kind != "dimensionless":
            raise InputError(source, field, expected, got=f"{value!r} (no unit)")
    m = _NUMBER_UNIT.match(value) if isinstance(value, str) else None
    ab = _affine(m.group(2), kind) if m else None
    if kind == "dimensionless" and isinstance(value, (int, float)):
        out = float(value)
    elif ab is not None:   # "<number> <unit>": the remembered (or freshly asked) pint conversion
        out = ab[0] * float(m.group(1)) + ab[1]
    else:
        out = _to_si_pint(value, kind, expected, source, field)
    if not math.isfinite(out):
        raise InputError(source, field, expected + " (finite)", got=repr(value))
    if positive and not out > 0.0:
        raise InputError(source, field, f"a positive {kind.replace('_', ' ')}", got=repr(value))
    if nonnegative and out < 0.0:
        raise InputError(source, field, f"a non-negative {kind.replace('_', ' ')}", got=repr(value))
    return out


def _to_si_pint(value: object, kind: str, expected: str, source: str, field: str) -> float:
    """The general path of :func:`to_si`: pint parses the whole value."""
    import pint

    if isinstance(value, (int, float)):
        if kind != "dimensionless":
            raise InputError(source, field, expected, got=f"{value!r} (no unit)")
        q = _Q(float(value), "dimensionless")
    elif isinstance(value, str):
        try:
            q = _Q(value)
        except Exception:  # pint raises several error types for unparsable text
            raise InputError(source, field, expected, got=repr(value)) from None
        if not isinstance(q, pint.Quantity):
            q = _Q(float(q), "dimensionless")
    else:
        raise InputError(source, field, expected, got=repr(value))
    if q.dimensionality != _dimensionality(kind):
        raise InputError(source, field, expected, got=f"{value!r} ({q.dimensionality})")
    return float(q.to(DIMENSIONS[kind][1]).magnitude)


def from_si(value: float, si_unit: str, unit: str) -> float:
    """Convert an SI float to ``unit`` (e.g. ``from_si(k, 'N/m', 'lbf/in')``)."""
    return float(_Q(value, si_unit).to(unit).magnitude)


def parse_float_list(text: str, option: str, source: str = "command line") -> list[float]:
    """'0.1,0.5,1' -> [0.1, 0.5, 1.0] (a command-line option's list of numbers); refuses an empty
    list or item (a double or trailing comma),
    non-numeric, non-positive or non-finite items (:class:`~taos.errors.InputError` naming ``option``)."""
    if not isinstance(text, str) or not text.strip() or len(text) > 10000:
        raise InputError(source, option, "a comma-separated list of numbers like 0.1,0.5,1", got=repr(text)[:40])
    if any(not s.strip() for s in text.split(",")):
        raise InputError(source, option, "numbers separated by single commas (no empty item)", got=repr(text)[:60])
    try:
        vals = [float(s) for s in text.split(",")]
    except ValueError:
        raise InputError(source, option, "a comma-separated list of numbers like 0.1,0.5,1",
                         got=repr(text)) from None
    if not vals or not all(math.isfinite(v) and v > 0 for v in vals):
        raise InputError(source, option, "positive finite numbers", got=repr(text))
    return vals
