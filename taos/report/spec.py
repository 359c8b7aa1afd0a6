"""Spec masks: gain and phase bounds per frequency, and the pass/fail of a response.

A mask file (TOML, shipped ones in ``models/specs/``)::

    name = "..."
    [[point]]
    response = "engine"          # or "piston" (x_p / (R theta_c))
    frequency = "2 Hz"
    gain_db = [-2.0, 2.0]        # optional [min, max], dB of the dimensionless gain
    phase_deg = [-45.0, 5.0]     # optional [min, max], phase continuous from low frequency
    source = "..."               # required: where these bounds come from (a document, or
                                 # "[notional] ..." with the reasoning that chose them)

    [step]                       # optional: step requirements on the simulated step figures
    amplitude = "0.5 deg"        # the command step (default 0.5 deg)
    rise_time_s = [0.0, 0.1]     # [min, max] of any of STEP_FIGURES (taos.report.merit.StepMerit)
    overshoot_pct = [0.0, 25.0]
    source = "..."               # required, as a point's

Every bound carries its ``source`` (a mask is a requirement; a number without a provenance is
not one): the loader refuses a point or a ``[step]`` table without a non-empty ``source``
(:class:`~taos.errors.InputError` naming ``point[i].source`` / ``step.source``). Masks built in
code (:class:`SpecPoint`) may leave it empty.

:func:`check_spec` evaluates the exact linear response of a model at each point
(:func:`taos.planar.freqresp.linear_freqresp`, the project's conventions) and returns a
:class:`SpecResult` with one row per point and the overall verdict.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..units import to_si

RESPONSES = ("engine", "piston")
#: the step figures a ``[step]`` table may bound (keys of :class:`taos.report.merit.StepMerit`)
STEP_FIGURES = ("rise_time_s", "overshoot_pct", "threshold_deg", "hysteresis_deg")
DEFAULT_STEP_AMPLITUDE_RAD = math.radians(0.5)


@dataclass(frozen=True)
class SpecPoint:
    """One mask point: bounds [min, max] on the gain [dB] and phase [deg] of ``response`` at
    ``freq_hz`` [Hz], and where they come from (``source``; required in a file)."""

    response: str
    freq_hz: float
    gain_db: tuple[float, float] | None
    phase_deg: tuple[float, float] | None
    source: str = ""


@dataclass(frozen=True)
class StepRequirement:
    """Bounds [min, max] on one step figure (``figure`` in :data:`STEP_FIGURES`, in its unit)
    of a command step of ``amplitude_rad`` [rad]."""

    figure: str
    bounds: tuple[float, float]
    amplitude_rad: float
    source: str = ""


@dataclass(frozen=True)
class SpecMask:
    name: str
    source: str
    points: tuple[SpecPoint, ...]
    steps: tuple[StepRequirement, ...] = ()


def _pair(v, src, field):
    if v is None:
        return None
    if (not isinstance(v, list) or len(v) != 2 or not all(isinstance(x, (int, float)) for x in v)
            or not all(math.isfinite(x) for x in v) or not v[0] < v[1]):
        raise InputError(src, field, "[min, max] numbers with min < max", got=repr(v))
    return (float(v[0]), float(v[1]))


def load_spec(path) -> SpecMask:
    """Read and validate a spec-mask file (module docstring)."""
    from ..shipped import resolve
    p = Path(resolve(path, "spec"))
    src = str(path)
    try:
        tab = tomllib.loads(p.read_text())
    except OSError as e:
        raise InputError(src, "(file)", "a readable spec-mask TOML file", got=e.strerror) from None
    except tomllib.TOMLDecodeError as e:
        raise InputError(src, "(file)", "valid TOML", got=str(e).splitlines()[0]) from None
    unknown = set(tab) - {"name", "point", "step"}
    if unknown:
        raise InputError(src, sorted(unknown)[0], "only 'name', [[point]] and [step] tables", got="an unknown key")
    pts = []
    for i, pt in enumerate(tab.get("point", [])):
        f = f"point[{i}]"
        bad = set(pt) - {"response", "frequency", "gain_db", "phase_deg", "source"}
        if bad:
            raise InputError(src, f"{f}.{sorted(bad)[0]}", "response, frequency, gain_db, phase_deg, source",
                             got="unknown key")
        resp = pt.get("response", "engine")
        if resp not in RESPONSES:
            raise InputError(src, f"{f}.response", "'engine' or 'piston'", got=repr(resp))
        if "frequency" not in pt:
            raise InputError(src, f"{f}.frequency", "a frequency like '2 Hz'", got="none")
        fz = to_si(pt["frequency"], "frequency", source=src, field=f"{f}.frequency", positive=True)
        g, ph = _pair(pt.get("gain_db"), src, f"{f}.gain_db"), _pair(pt.get("phase_deg"), src, f"{f}.phase_deg")
        if g is None and ph is None:
            raise InputError(src, f, "gain_db and/or phase_deg bounds", got="neither")
        pts.append(SpecPoint(resp, fz, g, ph, _source(pt, src, f)))
    if not pts:
        raise InputError(src, "point", "at least one [[point]]", got="none")
    return SpecMask(str(tab.get("name", p.stem)), src, tuple(pts), _steps(tab.get("step"), src))


def _steps(tab, src) -> tuple[StepRequirement, ...]:
    """The ``[step]`` table's requirements (module docstring); () when there is none."""
    if tab is None:
        return ()
    if not isinstance(tab, dict):
        raise InputError(src, "step", "a [step] table", got=type(tab).__name__)
    bad = set(tab) - {"amplitude", "source", *STEP_FIGURES}
    if bad:
        raise InputError(src, f"step.{sorted(bad)[0]}", "amplitude, source or one of " + ", ".join(STEP_FIGURES),
                         got="unknown key")
    amp = (to_si(tab["amplitude"], "angle", source=src, field="step.amplitude", positive=True)
           if "amplitude" in tab else DEFAULT_STEP_AMPLITUDE_RAD)
    out = tuple(StepRequirement(k, _pair(tab[k], src, f"step.{k}"), amp) for k in STEP_FIGURES if k in tab)
    if not out:
        raise InputError(src, "step", "bounds on at least one of " + ", ".join(STEP_FIGURES), got="none")
    where = _source(tab, src, "step")
    return tuple(StepRequirement(r.figure, r.bounds, r.amplitude_rad, where) for r in out)


def _source(tab: dict, src: str, where: str) -> str:
    """The required ``source`` of a point or ``[step]`` table (module docstring)."""
    v = tab.get("source")
    if not isinstance(v, str) or not v.strip():
        raise InputError(src, f"{where}.source", "where the bounds come from: a document, or '[notional] ...' with "
                         "the reasoning that chose them", got="nothing" if v is None else repr(v)[:40])
    return v.strip()


@dataclass(frozen=True)
class SpecRow:
    point: SpecPoint
    gain_db: float
    phase_deg: float
    gain_pass: bool | None
    phase_pass: bool | None

    @property
    def passed(self) -> bool:
        return self.gain_pass is not False and self.phase_pass is not False


@dataclass(frozen=True)
class SpecResult:
    """Pass/fail of one axis' linear response against a mask."""

    mask: SpecMask
    axis: str
    rows: tuple[SpecRow, ...]

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.rows)

    def failures(self) -> list[str]:
        out = []
        for r in self.rows:
            p = r.point
            if r.gain_pass is False:
                out.append(f"{p.response} gain {r.gain_db:.2f} dB at {p.freq_hz:g} Hz outside [{p.gain_db[0]:g}, "
                           f"{p.gain_db[1]:g}]")
            if r.phase_pass is False:
                out.append(f"{p.response} phase {r.phase_deg:.1f} deg at {p.freq_hz:g} Hz outside "
                           f"[{p.phase_deg[0]:g}, {p.phase_deg[1]:g}]")
        return out

    def to_dict(self) -> dict:
        return {"spec": self.mask.name, "spec_file": self.mask.source, "axis": self.axis, "pass": self.passed,
                "failures": self.failures(),
                "points": [{"response": r.point.response, "freq_hz": r.point.freq_hz,
                            "gain_db": r.gain_db, "gain_db_bounds": list(r.point.gain_db) if r.point.gain_db else None,
                            "gain_pass": r.gain_pass, "phase_deg": r.phase_deg,
                            "phase_deg_bounds": list(r.point.phase_deg) if r.point.phase_deg else None,
                            "phase_pass": r.phase_pass, "pass": r.passed} for r in self.rows]}


def check_spec(model, mask: SpecMask, axis: str = "pitch") -> SpecResult:
    """The linear response of ``model``'s ``axis`` against ``mask``."""
    from ..planar.freqresp import linear_freqresp
    from ..linear import gain_db

    f = np.array([p.freq_hz for p in mask.points])
    fr = linear_freqresp(model, f, axis)
    g = {"engine": gain_db(fr.engine), "piston": gain_db(fr.piston)}
    ph = {"engine": fr.engine_phase_deg(), "piston": fr.piston_phase_deg()}
    rows = []
    for k, p in enumerate(mask.points):
        gv, pv = float(g[p.response][k]), float(ph[p.response][k])
        rows.append(SpecRow(p, gv, pv, None if p.gain_db is None else bool(p.gain_db[0] <= gv <= p.gain_db[1]),
                            None if p.phase_deg is None else bool(p.phase_deg[0] <= pv <= p.phase_deg[1])))
    return SpecResult(mask, axis, tuple(rows))
