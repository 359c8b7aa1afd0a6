"""A sweep's definition: the swept model-file keys, their values, and the design over them.

``--set section.key=V1,V2,...`` lists values of one model-file key, each written as in the model
file: a number with its unit in the unit grammar of :mod:`taos.units` (``115000 lbf/in``), a
plain number (``0.005``, ``12``), or a word (``dahl``, ``true``). ``--set section.key=LO:HI``
gives a range instead (two numbers with units of one dimension), for a Latin hypercube.

* **grid** (no ``--samples``): every combination of the listed values (ranges refused);
* **latin-hypercube** (``--samples N``): N points, one per stratum of each key
  (:class:`scipy.stats.qmc.LatinHypercube`, seeded): a range is sampled uniformly between its
  ends (whole numbers when both ends are whole numbers without unit), a list by picking the
  value of the stratum;
* **sobol** (``--sensitivity sobol --samples N``): Saltelli's design of N (k + 2) points over the
  ranges (uniform), for first-order and total Sobol' indices of every metric
  (:mod:`taos.montecarlo.sensitivity`, SALib).

Each point of the design is a set of overrides ``{"section.key": TOML value}`` that the model
loader (:func:`taos.model.load_model`) writes into the file before checking it, so a swept
value is checked exactly as the file's own would be. The design's factors (the engine's
:class:`taos.montecarlo.engine.Design`) are the values as numbers in the unit of the key's first
value (a word: its index in the list).

Bounds, checked before any model is built: :data:`MAX_KEYS` keys, :data:`MAX_VALUES` values a
key, :data:`MAX_POINTS` points (grid) or samples.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
import tomllib
from dataclasses import dataclass

import numpy as np

from taos.errors import InputError

MAX_KEYS = 6
MAX_VALUES = 500
MAX_POINTS = 10_000
MAX_TEXT = 4000
DESIGNS = ("grid", "latin-hypercube", "sobol")
_KEY = re.compile(r"^[a-z][a-z0-9_]*\.[a-z][a-z0-9_]*$")
_NUM_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d{1,3})?)\s+(\S.*?)\s*$")
_WHERE = "command line"


@dataclass(frozen=True)
class SweptKey:
    """One swept model-file key. ``items``: the values as TOML values for the loader (a list),
    or the two ends of a range; ``numbers``: the same as numbers in ``unit`` (a word: its index);
    ``texts``: each value as shown; ``words``: the values are words (no unit, no order)."""

    key: str
    items: tuple
    numbers: tuple[float, ...]
    texts: tuple[str, ...]
    unit: str
    is_range: bool = False
    words: bool = False
    integer: bool = False

    def to_dict(self) -> dict:
        d = {"key": self.key, "unit": self.unit}
        return d | ({"range": list(self.numbers)} if self.is_range else {"values": list(self.texts)})


def _bad(key: str, expected: str, got: str) -> InputError:
    return InputError(_WHERE, f"--set {key}", expected, got=repr(got)[:80])


def _item(text: str, key: str) -> tuple[object, float | None, str]:
    """(TOML value for the loader, number or None for a word, unit text) of one listed value."""
    s = text.strip()
    if not s:
        raise _bad(key, "values separated by single commas (no empty value)", text)
    try:
        v = tomllib.loads(f"v = {s}")["v"]
    except tomllib.TOMLDecodeError:
        v = s
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        if not math.isfinite(v):
            raise _bad(key, "finite values", s)
        return v, float(v), ""
    if isinstance(v, (list, dict)) or not isinstance(v, (str, bool)):
        raise _bad(key, "a number with its unit, a plain number or a word (no arrays or tables)", s)
    m = _NUM_UNIT.match(v) if isinstance(v, str) else None
    if m is None:
        return v, None, ""
    from taos.units import check_unit_text

    unit = check_unit_text(m.group(2), _WHERE, f"--set {key}")
    num = float(m.group(1))
    if not math.isfinite(num):
        raise _bad(key, "finite values", s)
    return f"{m.group(1)} {unit}", num, unit


def _in_unit(num: float, unit: str, unit0: str, key: str, text: str) -> float:
    """``num`` ``unit`` expressed in ``unit0`` (refused when the dimensions differ)."""
    if unit == unit0:
        return num
    from taos.units import Q_

    try:
        return float(Q_(num, unit or "dimensionless").to(unit0 or "dimensionless").magnitude)
    except Exception:  # pint: undefined unit or another dimension
        raise _bad(key, f"values of one dimension (the first is in {unit0 or 'no unit'})", text) from None


def parse_set(text: str) -> SweptKey:
    """``section.key=V1,V2,...`` or ``section.key=LO:HI`` -> :class:`SweptKey` (module docstring)."""
    if not isinstance(text, str) or len(text) > MAX_TEXT:
        raise InputError(_WHERE, "--set", f"section.key=V1,V2,... of at most {MAX_TEXT} characters",
                         got=repr(text)[:60])
    key, sep, rest = text.partition("=")
    key = key.strip()
    if not sep or not _KEY.match(key):
        raise InputError(_WHERE, "--set", "section.key=V1,V2,... or section.key=LO:HI (a model-file key, "
                         "e.g. structure.load_stiffness='100000 lbf/in,115000 lbf/in')", got=repr(text)[:80])
    if ":" in rest:
        parts = rest.split(":")
        if len(parts) != 2:
            raise _bad(key, "a range LO:HI (two values)", rest)
        (v0, n0, u0), (v1, n1, u1) = (_item(p, key) for p in parts)
        if n0 is None or n1 is None:
            raise _bad(key, "a range of two numbers (words have no range: list them)", rest)
        hi = _in_unit(n1, u1, u0, key, rest)
        if not hi > n0:
            raise _bad(key, "a range LO:HI with HI above LO", rest)
        whole = isinstance(v0, int) and isinstance(v1, int)
        return SweptKey(key, (v0, v1), (n0, hi), (parts[0].strip(), parts[1].strip()), u0, is_range=True,
                        integer=whole)
    parsed = [_item(p, key) for p in rest.split(",")]
    if len(parsed) > MAX_VALUES:
        raise _bad(key, f"at most {MAX_VALUES} values", f"{len(parsed)} values")
    words = any(n is None for _, n, _ in parsed)
    texts = tuple(p.strip() for p in rest.split(","))
    if words:
        numbers = tuple(float(i) for i in range(len(parsed)))
        unit = "(choice)"
    else:
        unit = parsed[0][2]
        numbers = tuple(_in_unit(n, u, unit, key, t) for (_, n, u), t in zip(parsed, texts))
    if len(set(numbers if not words else texts)) != len(parsed):
        raise _bad(key, "each value once", rest)
    return SweptKey(key, tuple(v for v, _, _ in parsed), numbers, texts, unit, words=words)


@dataclass(frozen=True)
class SweepDesign:
    """The points of a sweep: ``factors`` (n, keys) as numbers, ``overrides`` one
    ``{key: TOML value}`` per point, ``texts`` one ``{key: text}`` per point, ``shape`` the grid's
    (None for a Latin hypercube)."""

    keys: tuple[SweptKey, ...]
    design: str
    factors: np.ndarray
    overrides: tuple[dict, ...]
    texts: tuple[dict, ...]
    shape: tuple[int, ...] | None
    seed: int

    @property
    def n(self) -> int:
        return len(self.overrides)

    def to_dict(self) -> dict:
        return {"design": self.design, "keys": [k.to_dict() for k in self.keys], "points": self.n,
                "shape": None if self.shape is None else list(self.shape), "seed": self.seed}

    def sha256(self) -> str:
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


def _check_keys(keys: list[SweptKey]) -> None:
    if not 1 <= len(keys) <= MAX_KEYS:
        raise InputError(_WHERE, "--set", f"one to {MAX_KEYS} swept keys", got=f"{len(keys)}")
    seen = set()
    for k in keys:
        if k.key in seen:
            raise InputError(_WHERE, f"--set {k.key}", "each key once (list its values in one --set)",
                             got="the key twice")
        seen.add(k.key)


def _text(k: SweptKey, value: float) -> tuple[object, str]:
    """(TOML value, text) of a sampled number of range ``k``."""
    if k.integer:
        return int(value), str(int(value))
    txt = f"{float(value)!r} {k.unit}".strip()
    return (txt if k.unit else float(value)), txt


def _sobol_design(keys: list[SweptKey], base: int, seed: int) -> SweepDesign:
    """Saltelli's design for first-order and total Sobol' indices over the ranges of ``keys``
    (:func:`taos.montecarlo.sensitivity.design`): ``base`` (a power of two) times (k + 2) points."""
    from taos.montecarlo import sensitivity

    bad = [k for k in keys if not k.is_range or k.integer]
    if bad:
        raise InputError(_WHERE, f"--set {bad[0].key}", "a range LO:HI of real values for Sobol' indices",
                         got="a list" if not bad[0].is_range else "whole-number ends")
    n = base * (len(keys) + 2)
    if base < 2 or base & (base - 1) or n > MAX_POINTS:
        raise InputError(_WHERE, "--samples", f"a power of two N with N (k + 2) at most {MAX_POINTS} points "
                         "(Saltelli's design)", got=f"{base} ({n} points)")
    prob = {"num_vars": len(keys), "names": [k.key for k in keys], "bounds": [list(k.numbers) for k in keys],
            "dists": ["unif"] * len(keys)}
    factors = sensitivity.design("sobol", prob, base, seed=seed)
    pairs = [[_text(k, v) for k, v in zip(keys, row)] for row in factors]
    over = tuple({k.key: p[0] for k, p in zip(keys, row)} for row in pairs)
    texts = tuple({k.key: p[1] for k, p in zip(keys, row)} for row in pairs)
    return SweepDesign(tuple(keys), "sobol", np.asarray(factors, float), over, texts, None, seed)


def make_design(keys: list[SweptKey], samples: int | None = None, seed: int = 0,
                sensitivity: str | None = None) -> SweepDesign:
    """The grid of ``keys`` (``samples`` None), a Latin hypercube of ``samples`` points, or
    (``sensitivity="sobol"``) Saltelli's design of ``samples`` base points over the ranges."""
    _check_keys(keys)
    if sensitivity is not None:
        if sensitivity != "sobol":
            raise InputError(_WHERE, "--sensitivity", "sobol", got=repr(sensitivity))
        if samples is None:
            raise InputError(_WHERE, "--sensitivity", "--samples N too (N base points, a power of two)",
                             got="no --samples")
        if not 0 <= seed < 2 ** 32:
            raise InputError(_WHERE, "--seed", "a whole number from 0 to 2**32 - 1", got=str(seed))
        return _sobol_design(keys, samples, seed)
    if samples is None:
        rng = [k for k in keys if k.is_range]
        if rng:
            raise InputError(_WHERE, f"--set {rng[0].key}", "listed values for a grid (a range LO:HI is "
                             "sampled: give --samples N)", got="a range")
        shape = tuple(len(k.items) for k in keys)
        n = math.prod(shape)
        if n > MAX_POINTS:
            raise InputError(_WHERE, "--set", f"a grid of at most {MAX_POINTS} points", got=f"{n} points")
        idx = list(itertools.product(*(range(s) for s in shape)))
        factors = np.array([[k.numbers[i] for k, i in zip(keys, row)] for row in idx], float).reshape(n, len(keys))
        over = tuple({k.key: k.items[i] for k, i in zip(keys, row)} for row in idx)
        texts = tuple({k.key: k.texts[i] for k, i in zip(keys, row)} for row in idx)
        return SweepDesign(tuple(keys), "grid", factors, over, texts, shape, seed)
    if not 2 <= samples <= MAX_POINTS:
        raise InputError(_WHERE, "--samples", f"2 to {MAX_POINTS} samples", got=str(samples))
    if not 0 <= seed < 2 ** 32:
        raise InputError(_WHERE, "--seed", "a whole number from 0 to 2**32 - 1", got=str(seed))
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(keys), seed=np.random.default_rng(seed)).random(samples)
    factors = np.empty((samples, len(keys)))
    over: list[dict] = [{} for _ in range(samples)]
    texts: list[dict] = [{} for _ in range(samples)]
    for j, k in enumerate(keys):
        for i in range(samples):
            if k.is_range:
                lo, hi = k.numbers
                v = (math.floor(lo + u[i, j] * (hi - lo + 1)) if k.integer else lo + u[i, j] * (hi - lo))
                v = min(v, hi)
                over[i][k.key], texts[i][k.key] = _text(k, v)
                factors[i, j] = v
            else:
                c = min(int(u[i, j] * len(k.items)), len(k.items) - 1)
                over[i][k.key], texts[i][k.key], factors[i, j] = k.items[c], k.texts[c], k.numbers[c]
    if len({tuple(r) for r in factors}) != samples:
        raise InputError(_WHERE, "--samples", "no more samples than the listed values can make distinct "
                         "(use ranges LO:HI)", got=str(samples))
    return SweepDesign(tuple(keys), "latin-hypercube", factors, tuple(over), tuple(texts), None, seed)
