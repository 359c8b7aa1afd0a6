"""Why a model passes or fails its spec mask: the mask on every basis, and each shortfall's cause.

The paper (sec. 1, 2) says Green Run missed its step and frequency-response specifications
through three phenomena outside the heritage linear servo: the load stiffness (structure), gimbal
friction and the avionics gain nonlinearity. This module checks a mask (:mod:`taos.report.spec`)
on four **bases** and names the **cause** of every failing point.

Bases (``basis`` of each :class:`SpecCheck`):

* ``linear``: the exact linear response (:func:`taos.planar.freqresp.linear_freqresp`; no friction,
  unity avionics) at the mask's frequencies;
* ``dwell``: the nonlinear sine dwell (:func:`taos.planar.freqresp.sine_dwell_points`, friction and
  avionics included, all points in one batched call) at the mask's frequencies, at the command
  amplitude the profile uses there: the amplitude of the profile's lowest-frequency dwell segment
  at or above the point's frequency on that axis (the test's band: 0.4 deg for commands up to
  7 Hz), or of its highest-frequency segment above them all;
* ``measured``: a measured record's estimated responses (:mod:`taos.identify.estimation`) at its
  points whose frequency is a mask frequency (within :data:`FREQ_MATCH_RTOL`); no interpolation;
* ``step``: the step figures (:func:`taos.report.merit.step_response_figures` /
  :func:`taos.report.merit.step_merit`, nonlinear simplex model) against the mask's ``[step]``
  requirements.

Phases are continuous from low frequency on the branch of the (evaluated) model's linear phase
(:func:`taos.planar.freqresp.linear_phase_reference`), as everywhere in the project.

Every check is evaluated on an **engine** (:mod:`taos.report.engines`), named in its ``engine``:
``"simplex"`` (the planar model, one axis at a time) or ``"taos"`` (the 3-D model: its own
linear response; its dwells run as the profile runs them, the other axis moving with the dwell
the profile commands meanwhile, so the cross-axis dither is in; its steps with the other axis at
rest; phases on the 3-D linear branch). A step requirement on the threshold or hysteresis is
simulated on the planar model and says so (``engine`` ``"simplex"``).

Causes, found by re-evaluating each FAILING point (only those: the passing ones are never
re-simulated; the dwells of one basis and axis go in one batched call per variant) on the SAME
engine with one factor removed (:func:`taos.report.engines.remove_causes`; 3-D: the 3-D model
rebuilt from the variant, :func:`taos.taos3d.with_values`):

* ``friction``: the gimbal friction law set to ``none``;
* ``load_stiffness``: the laboratory load, K_L -> :data:`LAB_LOAD_STIFFNESS_N_PER_M` (kept when
  the model's own K_L is stiffer), the "rigid load" an actuator is specified and accepted against;
* ``avionics``: a unity command path (no quantisation, crossover gain 1);
* ``pressure_limit``: the supply-pressure limit lifted (``actuator.pressure_limited = false``:
  no square-root valve law, no relief): "valve pressure saturation";
* and, when no single removal passes, the **servo alone** (friction, load path and avionics
  removed; the servo's own valve and supply kept).

The cause (:func:`cause_of`) is the tuple of single factors whose removal alone makes the point
pass (several when each alone suffices); ``("combined",)`` when only the servo alone passes;
``("servo",)`` when even the servo alone fails. A failing ``measured`` point is attributed on the
engine at the same amplitude and frequency: if the model's dwell there passes, the model does not
reproduce the shortfall and the cause is ``("unexplained",)``; otherwise as a ``dwell`` point.

:class:`Verdict` holds the checks; :meth:`Verdict.text` says in words why the model fails (or
passes) its mask, as the report's first line; :meth:`Verdict.to_dict` is what ``summary.json``
adds (docs/reference/outputs.md).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

from .engines import (  # noqa: F401
    CAUSES,
    LAB_LOAD_STIFFNESS_N_PER_M,
    SERVO_ALONE,
    PlanarEngine,
    engine_for,
    laboratory_model,
    remove_causes,
)

if TYPE_CHECKING:
    from taos.identify.estimation import MeasuredResponse
    from taos.model import TvcModel

    from .spec import SpecMask

AXES = ("pitch", "yaw")
BASES = ("linear", "dwell", "measured", "step")
#: a measured point is on a mask point when their frequencies agree within this relative tolerance
FREQ_MATCH_RTOL = 0.02
#: words of each cause in the verdict text
CAUSE_WORDS = {"friction": "gimbal friction", "load_stiffness": "the load stiffness (structure)",
               "avionics": "the avionics gain", "pressure_limit": "valve pressure saturation (the supply-pressure limit)",
               "combined": "friction, load stiffness and avionics together",
               "servo": "the servo itself", "unexplained": "something the model does not reproduce"}
#: words of each engine in the verdict text
ENGINE_WORDS = {"simplex": "planar simplex model", "taos": "3-D taos model"}
_UNITS = {"gain_db": "dB", "phase_deg": "deg", "rise_time_s": "s", "overshoot_pct": "%", "threshold_deg": "deg",
          "hysteresis_deg": "deg"}
_NAMES = {"gain_db": "gain", "phase_deg": "phase", "rise_time_s": "rise time", "overshoot_pct": "overshoot",
          "threshold_deg": "threshold", "hysteresis_deg": "hysteresis"}


def cause_of(single_passes: Mapping[str, bool], servo_passes: bool | None) -> tuple[str, ...]:
    """The cause of a failing point from its re-evaluations: the factors whose removal alone
    makes it pass (in :data:`CAUSES` order); else ``("combined",)`` if the servo alone passes,
    ``("servo",)`` if not."""
    singles = tuple(c for c in CAUSES if single_passes.get(c))
    if singles:
        return singles
    return ("combined",) if servo_passes else ("servo",)


# -- checks ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Bound:
    """One bounded quantity of a check: ``value`` (None when undefined: fails) in [lo, hi]."""

    quantity: str
    value: float | None
    lo: float
    hi: float

    @property
    def passed(self) -> bool:
        return self.value is not None and self.lo <= self.value <= self.hi

    def excess(self) -> float:
        """How far outside the bounds (0 inside; inf when undefined), in the quantity's unit."""
        if self.value is None:
            return math.inf
        return max(self.lo - self.value, self.value - self.hi, 0.0)

    def words(self) -> str:
        u = _UNITS.get(self.quantity, "")
        if self.value is None:
            return f"{_NAMES.get(self.quantity, self.quantity)} undefined"
        side = f"below the lower bound {self.lo:g}" if self.value < self.lo else f"above the upper bound {self.hi:g}"
        fmt = "+.1f" if u in ("dB", "deg") else ".3g"
        return f"{_NAMES.get(self.quantity, self.quantity)} {self.value:{fmt}} {u}, {self.excess():.3g} {u} {side}"


@dataclass(frozen=True)
class SpecCheck:
    """One mask point on one basis and axis (module docstring): its bounds, and for a failing
    point the ``cause`` and whether each removal (``"friction"``, ..., ``"servo"``) passed (a
    measured point also ``"model_dwell"``: the unmodified model's dwell at that point);
    ``engine`` the engine that produced its values and causes (``"simplex"`` or ``"taos"``);
    ``dither`` the other axis' (amplitude [rad], frequency [Hz]) during a 3-D dwell (None: at
    rest, or a planar point)."""

    basis: str
    axis: str
    response: str                 # "engine", "piston" or "step"
    freq_hz: float | None
    amplitude_rad: float | None
    bounds: tuple[Bound, ...]
    cause: tuple[str, ...] = ()
    removed: Mapping[str, bool] = field(default_factory=dict)
    engine: str = "simplex"
    dither: tuple[float, float] | None = None

    @property
    def passed(self) -> bool:
        return all(b.passed for b in self.bounds)

    def worst(self) -> Bound:
        """The failing bound furthest outside, relative to its bounds' width."""
        return max(self.bounds, key=lambda b: b.excess() / max(b.hi - b.lo, 1e-12))

    def where(self) -> str:
        """e.g. "pitch engine at 2 Hz (dwell, 0.4 deg)" or "pitch step (0.5 deg)"."""
        amp = "" if self.amplitude_rad is None else f", {math.degrees(self.amplitude_rad):.2g} deg"
        if self.response == "step":
            return f"{self.axis} step ({math.degrees(self.amplitude_rad):.2g} deg)"
        return f"{self.axis} {self.response} at {self.freq_hz:g} Hz ({self.basis}{amp})"

    def to_dict(self) -> dict:
        d = {"basis": self.basis, "axis": self.axis, "response": self.response, "freq_hz": self.freq_hz,
             "amplitude_deg": None if self.amplitude_rad is None else math.degrees(self.amplitude_rad),
             "pass": self.passed, "engine": self.engine}
        if self.dither is not None:
            d["cross_axis_amplitude_deg"] = math.degrees(self.dither[0])
            d["cross_axis_freq_hz"] = self.dither[1]
        for b in self.bounds:
            d[b.quantity] = b.value
            d[f"{b.quantity}_bounds"] = [b.lo, b.hi]
            d[f"{b.quantity}_pass"] = b.passed
        d["cause"] = list(self.cause) if not self.passed else None
        d["removed_pass"] = dict(self.removed) if not self.passed else None
        return d


def _finite(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _freq_bounds(point, h: complex, ref_deg: float) -> tuple[Bound, ...]:
    """Gain and phase bounds of a mask point for response value ``h`` (phase on the branch
    nearest ``ref_deg``)."""
    from taos.linear import phase_deg_continuous

    out = []
    if point.gain_db is not None:
        g = 20 * math.log10(abs(h)) if abs(h) > 0 else -math.inf
        out.append(Bound("gain_db", _finite(g), *point.gain_db))
    if point.phase_deg is not None:
        ph = float(phase_deg_continuous([point.freq_hz], [h], [ref_deg])[0]) if abs(h) > 0 else math.nan
        out.append(Bound("phase_deg", _finite(ph), *point.phase_deg))
    return tuple(out)


def dwell_segment(segments: Sequence[tuple], freq_hz: float) -> tuple | None:
    """The profile's dwell segment a mask point at ``freq_hz`` is run at: the lowest-frequency
    one at or above it, else the highest. ``segments``: one axis' dwell segments as (frequency
    [Hz], amplitude [rad]) or, with the other axis' dwell meanwhile, (frequency, amplitude, other
    frequency [Hz], other amplitude [rad]) (:func:`taos.report.engines.concurrent_dwells`);
    None when there are none."""
    if not segments:
        return None
    segs = sorted(segments)
    above = [s for s in segs if s[0] >= freq_hz * (1 - 1e-9)]
    return above[0] if above else segs[-1]


def dwell_amplitude_rad(segments: Sequence[tuple], freq_hz: float) -> float | None:
    """The profile's command amplitude [rad] at ``freq_hz`` (:func:`dwell_segment`'s); None
    when there are no segments."""
    s = dwell_segment(segments, freq_hz)
    return None if s is None else s[1]


def _dither(segments, freq_hz) -> tuple[float, float] | None:
    """The other axis' (amplitude [rad], frequency [Hz]) meanwhile, when ``segments`` carry it."""
    s = dwell_segment(segments, freq_hz)
    return (s[3], s[2]) if s is not None and len(s) >= 4 and s[3] > 0 else None


def _freq_checks(engine, mask, axis, basis, amps, dithers=None) -> list[SpecCheck]:
    pts = mask.points
    r = engine.responses(axis, [p.freq_hz for p in pts], amps, dithers)
    return [SpecCheck(basis, axis, p.response, p.freq_hz, None if amps is None else float(amps[k]),
                      _freq_bounds(p, complex(r[p.response][0][k]), float(r[p.response][1][k])),
                      engine=engine.name, dither=None if dithers is None else dithers[k])
            for k, p in enumerate(pts)]


def _measured_checks(engine, mask, m: MeasuredResponse, segments=None) -> list[SpecCheck]:
    """Mask points on a measured record's points at the mask's frequencies (module docstring);
    phases on ``engine``'s linear branch, and its dwell (with the profile's dither) attributes them."""
    R = engine.model.actuator.moment_arm_m
    out = []
    for p in mask.points:
        h_all = m.piston_m_per_rad / R if p.response == "piston" else m.engine
        if h_all is None:
            continue
        for k in np.flatnonzero(np.isclose(m.freq_hz, p.freq_hz, rtol=FREQ_MATCH_RTOL)):
            a = float(m.amplitude_rad[k])
            if not math.isfinite(a):
                continue
            rp, re = engine.phase_reference(m.axis, [float(m.freq_hz[k])])
            ref = float((rp if p.response == "piston" else re)[0])
            dither = _dither(segments, float(m.freq_hz[k])) if segments else None
            out.append(SpecCheck("measured", m.axis, p.response, float(m.freq_hz[k]), a,
                                 _freq_bounds(p, complex(h_all[k]), ref), engine=engine.name, dither=dither))
    return out


def _step_check(axis, reqs, values, engine: str = "simplex") -> SpecCheck:
    return SpecCheck("step", axis, "step", None, reqs[0].amplitude_rad,
                     tuple(Bound(r.figure, None if values.get(r.figure) is None else _finite(values[r.figure]),
                                 *r.bounds) for r in reqs), engine=engine)


def _reevaluate(engine, checks: list[SpecCheck], mask, threads=None) -> list[bool]:
    """Whether each check (one basis and axis) passes on ``engine``."""
    c0 = checks[0]
    if c0.basis == "step":
        return [_step_check(c0.axis, mask.steps, engine.step_values(c0.axis, mask.steps, threads)).passed]
    amps = None if c0.basis == "linear" else [c.amplitude_rad for c in checks]
    dithers = None if c0.basis == "linear" else [c.dither for c in checks]
    r = engine.responses(c0.axis, [c.freq_hz for c in checks], amps, dithers)
    out = []
    for k, c in enumerate(checks):
        h, ref = r[c.response][0][k], r[c.response][1][k]
        out.append(all(Bound(b.quantity, v.value, b.lo, b.hi).passed
                       for b, v in zip(c.bounds, _bounds_like(c, complex(h), float(ref)))))
    return out


def _bounds_like(c: SpecCheck, h: complex, ref: float) -> tuple[Bound, ...]:
    from .spec import SpecPoint

    q = {b.quantity: (b.lo, b.hi) for b in c.bounds}
    return _freq_bounds(SpecPoint(c.response, c.freq_hz, q.get("gain_db"), q.get("phase_deg")), h, ref)


def attribute(engine, checks: Sequence[SpecCheck], mask: SpecMask, dt_s: float | None = None,
              threads: int | None = None) -> list[SpecCheck]:
    """``checks`` with the cause of each failing one (module docstring); passing ones unchanged.
    ``engine``: a verdict engine (:mod:`taos.report.engines`), or a planar model (with ``dt_s``
    [s]). Each basis and axis is re-evaluated once per removal, on the same engine and its
    failing points only. A failing step's single removals are independent runs, on ``threads``
    threads (:func:`taos.planar._parallel.run_tasks`, the serial run's numbers); a dwell basis'
    removals are one parallel batch each, one after the other."""
    from taos.planar._parallel import run_tasks

    if not hasattr(engine, "responses"):
        engine = PlanarEngine(engine, 2e-4 if dt_s is None else dt_s)
    out = list(checks)
    groups: dict[tuple[str, str], list[int]] = {}
    for i, c in enumerate(checks):
        if not c.passed:
            groups.setdefault((c.basis, c.axis), []).append(i)
    for (basis, axis), idx in groups.items():
        group = [checks[i] for i in idx]
        removed = [dict() for _ in idx]
        todo = list(range(len(idx)))
        if basis == "measured":    # does the model itself fail there?
            own = _reevaluate(engine, [dataclasses.replace(c, basis="dwell") for c in group], mask)
            for j, ok in enumerate(own):
                removed[j]["model_dwell"] = ok
            todo = [j for j in todo if not own[j]]
        variants = CAUSES + ("servo",)
        if basis == "step" and todo:   # the single removals' step runs at once
            sub = [group[j] for j in todo]
            got = run_tasks([lambda c=c, sub=sub: _reevaluate(engine.without((c,)), sub, mask, threads) for c in CAUSES],
                            threads)
            for c, oks in zip(CAUSES, got):
                for j, ok in zip(todo, oks):
                    removed[j][c] = ok
            variants = ("servo",)
        for variant in variants:
            if variant == "servo":   # only where no single removal passed
                todo = [j for j in todo if not any(removed[j].get(c) for c in CAUSES)]
            if not todo:
                break
            ev = engine.without(SERVO_ALONE if variant == "servo" else (variant,))
            sub = [dataclasses.replace(group[j], basis="dwell") if basis == "measured" else group[j] for j in todo]
            for j, ok in zip(todo, _reevaluate(ev, sub, mask, threads)):
                removed[j][variant] = ok
        for j, i in enumerate(idx):
            rem = removed[j]
            if rem.get("model_dwell"):
                cause = ("unexplained",)
            else:
                cause = cause_of({c: rem.get(c, False) for c in CAUSES}, rem.get("servo"))
            out[i] = dataclasses.replace(checks[i], cause=cause, removed=rem)
    return out


# -- the verdict -------------------------------------------------------------------------------

@dataclass(frozen=True)
class Verdict:
    """A model's mask on every basis, with the causes of its shortfalls (module docstring)."""

    model_name: str
    mask_name: str
    mask_source: str
    checks: tuple[SpecCheck, ...]
    #: the engine the dwells, linear responses and causes were evaluated on ("simplex" or "taos")
    engine: str = "simplex"

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def passed_by_basis(self) -> dict:
        """{basis: all its checks pass} for the bases checked."""
        out = {}
        for c in self.checks:
            out[c.basis] = out.get(c.basis, True) and c.passed
        return out

    def failures(self) -> list[SpecCheck]:
        return [c for c in self.checks if not c.passed]

    def text(self) -> str:
        """In words: why the model fails (or passes) its mask, e.g. "RS-25 hot fire: fails the
        mask at 1 and 2 Hz (dwell; worst ...) because of gimbal friction; the linear response
        passes." """
        by = self.passed_by_basis()
        bases = ", ".join(b for b in BASES if b in by)
        name = self.model_name if self.engine == "simplex" else f"{self.model_name} ({ENGINE_WORDS[self.engine]})"
        if self.passed:
            return f"{name}: passes the mask ({self.mask_name}) on every basis checked ({bases})."
        groups: dict[tuple[str, ...], list[SpecCheck]] = {}
        for c in self.failures():
            groups.setdefault(c.cause, []).append(c)
        parts = []
        for cause, cs in sorted(groups.items(), key=lambda kv: -len(kv[1])):
            freqs = sorted({c.freq_hz for c in cs if c.freq_hz is not None})
            where = []
            if freqs:
                where.append(_and([f"{f:g}" for f in freqs]) + " Hz")
            if any(c.response == "step" for c in cs):
                where.append("the step")
            cb = [b for b in BASES if any(c.basis == b for c in cs)]
            amps = sorted({round(math.degrees(c.amplitude_rad), 6) for c in cs
                           if c.amplitude_rad is not None and c.basis in ("dwell", "measured")})
            if amps:
                cb.append(_and([f"{a:g}" for a in amps]) + " deg")
            worst = max(cs, key=lambda c: (c.worst().excess() / max(c.worst().hi - c.worst().lo, 1e-12)))
            if cause in (("combined",), ("servo",), ("unexplained",)):
                why = CAUSE_WORDS[cause[0]]
            else:
                why = _and([CAUSE_WORDS[c] for c in cause]) + (", either of which removed alone passes"
                                                               if len(cause) > 1 else "")
            parts.append(f"at {_and(where)} ({', '.join(cb)}; worst: {worst.where()} {worst.worst().words()}) "
                         f"because of {why}")
        s = f"{name}: fails the mask ({self.mask_name}) " + "; and ".join(parts)
        if by.get("linear"):
            s += "; the linear servo passes"
        return s + "."

    def to_dict(self) -> dict:
        """The ``summary.json`` keys this adds (docs/reference/outputs.md)."""
        return {"spec_verdict_text": self.text(), "spec_verdict_pass": self.passed,
                "spec_pass_by_basis": self.passed_by_basis(),
                "spec_engine": self.engine,
                "spec_points": [c.to_dict() for c in self.checks],
                "spec_attribution": {
                    "causes": list(CAUSES) + ["combined", "servo", "unexplained"],
                    "laboratory_load_stiffness_N_per_m": LAB_LOAD_STIFFNESS_N_PER_M,
                    "engine": self.engine,
                    "method": "each failing point re-evaluated on the same engine with one factor removed (friction "
                              "law none; load stiffness K_L -> max(K_L, laboratory); unity avionics; supply-pressure "
                              "limit lifted) and, if none passes, friction, load path and avionics together (the "
                              "servo alone, its valve kept); the cause is the factors whose removal alone passes, "
                              "'combined' when only the servo alone passes, 'servo' when it fails too; a measured "
                              "point the model's own dwell passes is 'unexplained'"}}


def _and(items: Sequence[str]) -> str:
    items = list(items)
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def spec_verdict(model: TvcModel, mask: SpecMask, *, segments: Mapping[str, Sequence[tuple]] | None = None,
                 measured: Mapping[str, MeasuredResponse] | None = None, step_figures: Mapping[str, dict] | None = None,
                 dt_s: float | None = None, axes: Sequence[str] = AXES, attribute_causes: bool = True,
                 threads: int | None = None, engine: str = "simplex", taos_model=None) -> Verdict:
    """``model`` against ``mask`` on every basis (module docstring), with causes, on ``engine``
    (``"simplex"`` or ``"taos"``; 3-D: ``taos_model``, else built from ``model``).

    ``segments``: per axis the profile's dwell segments as (frequency [Hz], amplitude [rad]), or
    with the other axis' dwell meanwhile (:func:`taos.report.engines.concurrent_dwells`: the 3-D
    dwells run it; the planar ones ignore it) (none: no dwell basis); ``measured``: per axis a
    measured record's responses (none: no measured basis); ``step_figures``: per axis the planar
    step figures already simulated (``StepMerit.to_dict()``, reused on the simplex engine when
    their amplitude is the mask's); ``dt_s``: the integration step [s] of dwells and steps
    (default the engine's own); ``threads``: for the independent step runs (:func:`attribute`;
    the same numbers on any count)."""
    ev = engine_for(model, engine, dt_s, taos_model)
    checks: list[SpecCheck] = []
    for ax in axes:
        checks += _freq_checks(ev, mask, ax, "linear", None)
    for ax in axes:
        segs = (segments or {}).get(ax)
        if segs:
            amps = [dwell_amplitude_rad(segs, p.freq_hz) for p in mask.points]
            dith = [_dither(segs, p.freq_hz) for p in mask.points] if ev.name == "taos" else None
            checks += _freq_checks(ev, mask, ax, "dwell", amps, dith)
    for ax in axes:
        if measured and ax in measured:
            checks += _measured_checks(ev, mask, measured[ax], (segments or {}).get(ax) if ev.name == "taos" else None)
    if mask.steps:
        for ax in axes:
            have = (step_figures or {}).get(ax) if ev.name == "simplex" else None
            amp_deg = math.degrees(mask.steps[0].amplitude_rad)
            if have is None or not math.isclose(have.get("step_amplitude_deg", math.nan), amp_deg, rel_tol=1e-9):
                have = ev.step_values(ax, mask.steps, threads)
            checks.append(_step_check(ax, mask.steps, have, ev.step_engine(mask.steps)))
    if attribute_causes:
        checks = attribute(ev, checks, mask, threads=threads)
    return Verdict(model.name, mask.name, mask.source, tuple(checks), ev.name)
