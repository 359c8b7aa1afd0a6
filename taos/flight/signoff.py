"""Flight sign-off: the limit-cycle analysis checked against stated requirements, case by case,
with the margin to each limit (``taos lco ... --requirements FILE``).

A requirements file (TOML, e.g. ``models/specs/flight_signoff_notional.toml``) states limits:

* ``low_gain_margin_min_db`` [dB]: the low-frequency gain margin of L0 N(A, .) (how far the loop
  gain may fall before the conditionally stable loop loses stability) at every describing-
  function amplitude A >= ``margin_amplitude_min``;
* ``phase_margin_min`` (an angle): the smallest phase margin of L0 N(A, .) at those amplitudes;
* ``lco_engine_amplitude_max`` (an angle): the engine amplitude of a self-sustained limit cycle
  (the describing function's stable cycle, and the time-domain run's when one was made);
* ``lco_frequency_band`` ([low, high], frequencies): where a limit cycle, if any, may sit;
* ``margin_amplitude_min`` (an angle, default 0): the amplitudes below it are the limit cycle's
  own (friction's small-amplitude gain loss), bounded by the LCO limits instead of the margins.

Each limit is optional; ``notional = true`` labels the requirements (and every output) as
notional. Definitions (SI inside, engineering units at the edges):

* signed low-frequency gain margin at amplitude A: 20 log10 |L0 N(A, j w_pc)| at the -180 deg
  (mod 360) crossing w_pc of L0 N(A, .) nearest (in log frequency) to the low-frequency crossing
  w_0 of the rigid loop L0 (where |L0| > 1: the conditionally stable crossing,
  :func:`taos.flight.vehicle.margins`). Positive: the gain may fall by that much; negative: the loop
  already lacks that much gain at this amplitude. A loop L0 without such a crossing has no
  low-frequency gain margin to check (reported, passes);
* phase margin at A: the smallest over the gain crossovers of L0 N(A, .) (none: |L| never
  reaches 1, passes);
* margin to a limit: value - limit for a minimum, limit - value for a maximum, the distance to
  the nearer band edge (positive inside) for a band; a check passes when its margin is >= 0.

Cases: the nominal model and flight file, or every point of a ``--sweep`` grid (the dispersions,
:func:`taos.flight.lco_map.apply_value`), each analysed by :func:`taos.flight.lco.analyse_lco`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable

import numpy as np

from taos.errors import InputError
from taos.flight.lco_verdict import grows_beyond_map, low_frequency_crossing_hz, signed_low_gain_margin

if TYPE_CHECKING:
    from taos.flight.lco import LcoReport
    from taos.flight.lco_map import SweepAxis
    from taos.flight.vehicle import FlightModel
    from taos.model import TvcModel

#: the requirement keys and what each is: key -> (unit kind or "dB", expected text)
KEYS = {"low_gain_margin_min_db": "a gain margin in dB (a number, e.g. 6)",
        "phase_margin_min": "an angle with its unit, e.g. '30 deg'",
        "lco_engine_amplitude_max": "an angle with its unit, e.g. '0.1 deg'",
        "lco_frequency_band": "two frequencies [low, high], e.g. ['0.05 Hz', '1 Hz']",
        "margin_amplitude_min": "an angle with its unit, e.g. '0.1 deg'"}
#: at most this many cases (sweep grid points) per sign-off
MAX_CASES = 64


@dataclass(frozen=True)
class Requirements:
    """Stated limits (SI; None: not required). See the module docstring."""

    name: str
    source: str
    notional: bool
    low_gain_margin_min_db: float | None = None
    phase_margin_min_rad: float | None = None
    lco_engine_amplitude_max_rad: float | None = None
    lco_frequency_band_hz: tuple[float, float] | None = None
    margin_amplitude_min_rad: float = 0.0

    def to_dict(self) -> dict:
        deg = lambda x: None if x is None else math.degrees(x)  # noqa: E731
        return {"name": self.name, "file": self.source, "notional": self.notional,
                "low_gain_margin_min_db": self.low_gain_margin_min_db,
                "phase_margin_min_deg": deg(self.phase_margin_min_rad),
                "lco_engine_amplitude_max_deg": deg(self.lco_engine_amplitude_max_rad),
                "lco_frequency_band_hz": None if self.lco_frequency_band_hz is None else list(self.lco_frequency_band_hz),
                "margin_amplitude_min_deg": math.degrees(self.margin_amplitude_min_rad)}


def load_requirements(path: str | Path) -> Requirements:
    """Read a requirements file; :class:`InputError` (file, key, what was expected) on bad input."""
    from taos.model import read_toml
    from taos.errors import check_keys
    from taos.units import to_si

    src = str(path)
    _, doc = read_toml(path, "a readable requirements file")
    check_keys(doc, {"name", "description", "notional", "limits"}, src)
    lim = doc.get("limits")
    if not isinstance(lim, dict) or not lim:
        raise InputError(src, "limits", "a [limits] table with at least one of " + ", ".join(KEYS), got=repr(lim))
    check_keys(lim, set(KEYS), src, "limits")
    notional = doc.get("notional", False)
    if not isinstance(notional, bool):
        raise InputError(src, "notional", "true or false", got=repr(notional))

    def angle(key):
        return None if key not in lim else to_si(lim[key], "angle", source=src, field=f"limits.{key}", nonnegative=True)

    gm = lim.get("low_gain_margin_min_db")
    if gm is not None and (isinstance(gm, bool) or not isinstance(gm, (int, float)) or not math.isfinite(gm)):
        raise InputError(src, "limits.low_gain_margin_min_db", KEYS["low_gain_margin_min_db"], got=repr(gm))
    band = lim.get("lco_frequency_band")
    if band is not None:
        if not isinstance(band, list) or len(band) != 2:
            raise InputError(src, "limits.lco_frequency_band", KEYS["lco_frequency_band"], got=repr(band))
        band = tuple(to_si(b, "frequency", source=src, field="limits.lco_frequency_band", positive=True) for b in band)
        if not band[0] < band[1]:
            raise InputError(src, "limits.lco_frequency_band", "low < high", got=repr(lim["lco_frequency_band"]))
    return Requirements(name=str(doc.get("name", "requirements")), source=src, notional=notional,
                        low_gain_margin_min_db=None if gm is None else float(gm),
                        phase_margin_min_rad=angle("phase_margin_min"),
                        lco_engine_amplitude_max_rad=angle("lco_engine_amplitude_max"),
                        lco_frequency_band_hz=band, margin_amplitude_min_rad=angle("margin_amplitude_min") or 0.0)


@dataclass(frozen=True)
class Check:
    """One requirement on one case: value against limit, margin (>= 0 passes), where it binds."""

    requirement: str
    unit: str
    limit: object
    value: float | None
    margin: float | None
    passed: bool
    where: str

    def to_dict(self) -> dict:
        fin = lambda x: None if x is None or not math.isfinite(x) else float(x)  # noqa: E731
        lim = list(self.limit) if isinstance(self.limit, tuple) else self.limit
        return {"requirement": self.requirement, "unit": self.unit, "limit": lim, "value": fin(self.value),
                "margin": fin(self.margin), "pass": self.passed, "where": self.where}


@dataclass(frozen=True, eq=False)
class CaseResult:
    """The checks of one case (``parameters``: the swept values, SI; empty for the nominal case)."""

    label: str
    parameters: dict
    checks: tuple[Check, ...]
    lco_text: str
    report: object = field(repr=False, default=None)

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def to_dict(self) -> dict:
        return {"case": self.label, "parameters": self.parameters, "pass": self.passed, "lco_verdict": self.lco_text,
                "checks": [c.to_dict() for c in self.checks]}


@dataclass(frozen=True, eq=False)
class SignOff:
    """The sign-off over all cases."""

    requirements: Requirements
    cases: tuple[CaseResult, ...]
    provenance: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.cases)

    def text(self) -> str:
        """The verdict in one sentence."""
        label = "NOTIONAL requirements" if self.requirements.notional else "requirements"
        failed = [c for c in self.cases if not c.passed]
        head = f"flight sign-off against {label} '{self.requirements.name}': "
        if not failed:
            return head + f"PASS in all {len(self.cases)} case(s)"
        worst = []
        for c in failed:
            bad = [k for k in c.checks if not k.passed]
            worst.append(f"{c.label}: " + ", ".join(f"{k.requirement} ({_fmt(k.value)} {k.unit} against "
                                                    f"{_fmt_limit(k.limit)} {k.unit}, {k.where})" for k in bad))
        return head + f"FAIL in {len(failed)} of {len(self.cases)} case(s): " + "; ".join(worst)

    def table_text(self) -> str:
        w = max(len("case"), *(len(c.label) for c in self.cases))
        lines = [f"{'case':{w}s} {'requirement':26s} {'limit':>16s} {'value':>10s} {'margin':>10s}  result  where"]
        for c in self.cases:
            for k in c.checks:
                lines.append(f"{c.label:{w}s} {k.requirement:26s} {_fmt_limit(k.limit) + ' ' + k.unit:>16s} "
                             f"{_fmt(k.value):>10s} {_fmt(k.margin):>10s}  {'pass' if k.passed else 'FAIL':6s}  {k.where}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {"pass": self.passed, "text": self.text(), "notional": self.requirements.notional,
                "requirements": self.requirements.to_dict(), "cases": [c.to_dict() for c in self.cases],
                "margin_definition": "value - limit for a minimum, limit - value for a maximum, distance to the "
                                     "nearer band edge (positive inside) for a band; >= 0 passes",
                "provenance": self.provenance}


def _fmt(x) -> str:
    return "-" if x is None or x != x else f"{x:.4g}"   # (inf: "inf", unbounded)


def _fmt_limit(lim) -> str:
    return f"[{lim[0]:.4g}, {lim[1]:.4g}]" if isinstance(lim, tuple) else f"{lim:.4g}"


# -- the checks ----------------------------------------------------------------------------------

def check_case(req: Requirements, report: LcoReport, label: str = "nominal",
               parameters: dict | None = None) -> CaseResult:
    """The requirements' checks on one :class:`taos.flight.lco.LcoReport`."""
    pred = report.prediction
    amps = [a for a in pred.df.amplitude_rad if a >= req.margin_amplitude_min_rad * (1 - 1e-9)]
    checks = []
    span = (f"A >= {math.degrees(req.margin_amplitude_min_rad):.3g} deg" if req.margin_amplitude_min_rad > 0
            else "every amplitude")
    if req.low_gain_margin_min_db is not None:
        f0 = low_frequency_crossing_hz(pred)
        if f0 is None:
            checks.append(Check("low-frequency gain margin", "dB", req.low_gain_margin_min_db, math.inf, math.inf, True,
                                "the rigid loop has no low-frequency -180 deg crossing"))
        else:
            vals = [(signed_low_gain_margin(pred, a, f0), a) for a in amps]
            vals = [((g if g is not None else math.inf), fx, a) for (g, fx), a in vals]
            g, fx, a = min(vals, key=lambda v: v[0]) if vals else (math.inf, None, None)
            where = ("no amplitude at or above the margin amplitude" if a is None else
                     f"A = {math.degrees(a):.3g} deg" + ("" if fx is None else f", {fx:.3g} Hz") + f" ({span})")
            checks.append(Check("low-frequency gain margin", "dB", req.low_gain_margin_min_db, g,
                                g - req.low_gain_margin_min_db, g >= req.low_gain_margin_min_db, where))
    if req.phase_margin_min_rad is not None:
        lim = math.degrees(req.phase_margin_min_rad)
        rows = [(m.phase_margin_deg, m.gain_crossover_hz, a) for a, m in zip(pred.df.amplitude_rad,
                                                                             pred.margins_by_amplitude) if a in amps]
        rows = [((pm if pm is not None else math.inf), fc, a) for pm, fc, a in rows]
        pm, fc, a = min(rows, key=lambda v: v[0]) if rows else (math.inf, None, None)
        where = ("|L| never reaches 1" if not math.isfinite(pm) else
                 f"A = {math.degrees(a):.3g} deg, crossover {fc:.3g} Hz ({span})")
        checks.append(Check("phase margin", "deg", lim, pm, pm - lim, pm >= lim, where))
    cycles = _cycles(report)
    grows = grows_beyond_map(pred)
    if req.lco_engine_amplitude_max_rad is not None:
        lim = math.degrees(req.lco_engine_amplitude_max_rad)
        if grows:   # no cycle inside the map because the motion outgrows it
            checks.append(Check("LCO engine amplitude", "deg", lim, math.inf, -math.inf, False, grows))
        elif cycles:
            v, src, _ = max(cycles, key=lambda c: c[0])
            checks.append(Check("LCO engine amplitude", "deg", lim, v, lim - v, v <= lim, src))
        else:
            checks.append(Check("LCO engine amplitude", "deg", lim, 0.0, lim, True, "no limit cycle"))
    if req.lco_frequency_band_hz is not None:
        lo, hi = req.lco_frequency_band_hz
        if cycles:
            worst = min(((min(f - lo, hi - f), f, src) for _, src, f in cycles), key=lambda c: c[0])
            checks.append(Check("LCO frequency band", "Hz", (lo, hi), worst[1], worst[0], worst[0] >= 0, worst[2]))
        else:
            checks.append(Check("LCO frequency band", "Hz", (lo, hi), None, None, True, "no limit cycle"))
    return CaseResult(label, dict(parameters or {}), tuple(checks), report.verdict().text, report)


def _cycles(report: LcoReport) -> list[tuple[float, str, float]]:
    """(engine amplitude [deg], source, frequency [Hz]) of each self-sustained cycle: the
    describing function's stable cycle and the time-domain run's when it oscillates."""
    out = []
    c = report.prediction.stable_cycle
    if c is not None:
        out.append((math.degrees(c.engine_amplitude_rad), "describing function", c.freq_hz))
    td = report.time_domain
    if td is not None and td.lco:
        out.append((math.degrees(td.engine_amplitude_rad), "time domain", td.freq_hz))
    return out


def sign_off(req: Requirements, flight: FlightModel, model: TvcModel, *, sweep_axes: Iterable[SweepAxis] = (),
             progress: bool = False, **lco_kw: Any) -> SignOff:
    """The sign-off of ``model`` in ``flight`` against ``req``: the nominal case, or every point
    of the grid of ``sweep_axes`` (:class:`taos.flight.lco_map.SweepAxis`; prediction only).
    ``lco_kw``: :func:`taos.flight.lco.analyse_lco`'s settings. The number of cases is checked
    (at most :data:`MAX_CASES`) before any work."""
    from tqdm import tqdm

    from taos.flight.lco import analyse_lco
    from taos.flight.lco_map import SWEEPABLE, apply_value
    from taos.results import output_provenance

    axes = tuple(sweep_axes)
    shape = tuple(len(a.values) for a in axes)
    n = int(np.prod(shape)) if axes else 1
    if n > MAX_CASES:
        raise InputError("command line", "--sweep", f"at most {MAX_CASES} cases for a sign-off", got=f"{n} cases")
    cases = []
    grid = list(np.ndindex(shape)) if axes else [()]
    for idx in tqdm(grid, desc="sign-off", unit="case", disable=not progress):
        fl, m, params = flight, model, {}
        for a, i in zip(axes, idx):
            fl, m = apply_value(fl, m, a.name, a.values[i])
            params[SWEEPABLE[a.name][1]] = a.values[i]   # (SI, unit in the key: load_stiffness_N_per_m)
        kw = dict(lco_kw, time_domain=False) if axes else lco_kw
        rep = analyse_lco(fl, m, **kw)
        label = ", ".join(f"{a.name} = {a.values[i]:.4g} {a.unit}" for a, i in zip(axes, idx)) or "nominal"
        cases.append(check_case(req, rep, label, params))
    prov = output_provenance([model], [("flight", flight.source), ("requirements", req.source)])
    return SignOff(req, tuple(cases), prov)
