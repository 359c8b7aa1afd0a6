"""Monte Carlo campaign files: what is dispersed, how, and the named cases.

A campaign (``models/montecarlo/*.toml``) flies a segment of an ascent
(:mod:`taos.flight.ascent`) many times with dispersed parameters and measures the limit cycle
of each run as ``taos lco`` does. Format::

    name = "..."
    ascent = "../flight/ascent.toml"        # the flight (relative to this file)
    tvc_model = "../rs25_flight.toml"       # optional: default the ascent's tvc_model
    friction = "dahl"                       # optional: a friction law (default the model's)
    seed = 20221116                         # campaign seed: run i draws from SeedSequence([seed, i])
    start = "130 s"                         # segment flown (flight time)
    duration = "200 s"
    dt = "1 ms"                             # the integrator's step
    integrator = "rk4"                      # optional: "rk4" (default) or "etdrk4" (the actuator and
                                            # engine propagated exactly: steps up to 10 ms)
    axis = "yaw"
    analysis_window = "100 s"               # LCO measured over the last window of the segment
    trace_interval = "0.5 s"                # spacing of the stored FCS command trace
    update_interval = "5 s"                 # optional: override the ascent's zero-order-hold interval
    ptis = false                            # optional: fly the ascent's PTIs in the segment (default true)
    avionics = "bounding"                   # "bounding" (flat -1 dB, as taos lco) or "model" (quantiser)
    friction_follows_thrust = false         # optional: the friction level follows the trajectory's thrust,
                                            # T_c = mu N(t) r_b (taos.flight.friction_env; default false)
    default_case = "soft"

    [cases.soft]                            # named cases: TVC parameter overrides, with units
    load_stiffness = "115000 lbf/in"

    [dispersions]                           # multiplicative factors on the case's nominal value
    coulomb_torque = { distribution = "normal", mean = 1.0, std = 0.1, low = 0.5, high = 1.5 }
    wind = { distribution = "uniform", low = 0.5, high = 1.5 }

Distributions of a factor: ``normal`` (mean, std; optional truncation low/high by clipping) and
``uniform`` (low, high). Parameters: the TVC model's fittable values
(:data:`taos.identify.surrogate.PARAMETERS`: load_stiffness, coulomb_torque, bristle_stiffness,
loop_gain, pressure_feedback_gain, avionics_gain, ...) and the flight's (:data:`FLIGHT_PARAMETERS`).
A run's TVC model is one model variant through the loader (:mod:`taos.variants`), each key with the
model file's meaning: ``coulomb_torque`` is the friction level (the law's other load-proportional
parameters follow it), a dispersed torque-like parameter among them (``bristle_stiffness``) is set
as drawn.
A run is a pure function of (campaign, case, run index): the same seeds give the same results on
any executor.
"""

from __future__ import annotations

import dataclasses
import difflib
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from taos.errors import InputError
from taos.flight.ascent import Ascent, load_ascent
from taos.identify.surrogate import PARAMETERS
from taos.model import TvcModel, load_model, read_toml
from taos.shipped import resolve, resolve_reference
from taos.units import to_si

#: flight-side dispersible parameters -> what the factor multiplies
FLIGHT_PARAMETERS = {
    "vehicle_mass": "trajectory mass",
    "vehicle_inertia": "trajectory inertia (pitch = yaw)",
    "core_thrust": "core engine thrust along the trajectory",
    "fcs_attitude_gain": "FCS attitude gain K_p",
    "fcs_rate_gain": "FCS rate gain K_d",
    "fcs_integral_gain": "FCS integral gain K_i",
    "fcs_delay": "FCS sensor + computer delay",
    "wind": "the whole wind (steady, gust, turbulence)",
    "separation_kick": "the attitude-rate kick at booster separation",
}
DISTRIBUTIONS = ("normal", "uniform")
TOP_KEYS = {"name", "description", "ascent", "tvc_model", "friction", "seed", "start", "duration", "dt", "axis",
            "analysis_window", "trace_interval", "default_case", "cases", "dispersions", "update_interval", "ptis", "avionics",
            "friction_follows_thrust", "integrator"}
#: the campaign's integrators (:func:`taos.flight.ascent_sim.simulate_ascents`) -> their largest step [s]:
#: RK4's 2 ms is the oil column's stability bound (benchmarks/RESULTS.md, mcfast); ETDRK4's 10 ms the
#: largest step that divides the 20 ms records (benchmarks/RESULTS.md, mcexp: its accuracy)
MAX_DT_S = {"rk4": 2e-3, "etdrk4": 1e-2}
#: the spacing of a run's records [s] (taos.montecarlo.run.RECORD_INTERVAL_S): an ETDRK4 step divides it
_RECORDS_S = 0.02
MAX_SEGMENT_STEPS = 2_000_000


@dataclass(frozen=True)
class Dispersion:
    """A factor's distribution: ``normal`` (mean, std, clipped to [low, high]) or ``uniform``
    (low, high)."""

    name: str
    distribution: str
    mean: float = 1.0
    std: float = 0.0
    low: float = -math.inf
    high: float = math.inf

    def sample(self, rng: np.random.Generator) -> float:
        if self.distribution == "uniform":
            return float(rng.uniform(self.low, self.high))
        return float(np.clip(rng.normal(self.mean, self.std), self.low, self.high))


@dataclass(frozen=True)
class Campaign:
    """A parsed campaign file (SI). ``cases`` maps a case name to its TVC overrides
    (parameter name -> SI value)."""

    name: str
    source: str
    sha256: str
    ascent_file: str
    tvc_model_file: str
    friction: str | None
    seed: int
    start_s: float
    duration_s: float
    dt_s: float
    axis: str
    analysis_window_s: float
    trace_interval_s: float
    default_case: str
    cases: Mapping[str, Mapping[str, float]]
    dispersions: tuple[Dispersion, ...]
    update_interval_s: float | None = None
    ptis: bool = True
    avionics: str = "bounding"
    friction_follows_thrust: bool = False
    integrator: str = "rk4"


def _nearest(key: str, allowed) -> str:
    near = difflib.get_close_matches(key, list(allowed), n=1)
    return f" (did you mean '{near[0]}'?)" if near else ""


def _dispersion(name: str, spec, src: str) -> Dispersion:
    fld = f"dispersions.{name}"
    if name not in PARAMETERS and name not in FLIGHT_PARAMETERS:
        allowed = sorted(PARAMETERS) + sorted(FLIGHT_PARAMETERS)
        raise InputError(src, fld, "a dispersible parameter: " + ", ".join(allowed) + _nearest(name, allowed),
                         got="an unknown parameter")
    if not isinstance(spec, Mapping):
        raise InputError(src, fld, "a table like { distribution = \"normal\", mean = 1.0, std = 0.1 }", got=repr(spec))
    dist = spec.get("distribution")
    if dist not in DISTRIBUTIONS:
        raise InputError(src, f"{fld}.distribution", "'normal' or 'uniform'", got=repr(dist))
    allowed = {"distribution", "mean", "std", "low", "high"} if dist == "normal" else {"distribution", "low", "high"}
    for k in spec:
        if k not in allowed:
            raise InputError(src, f"{fld}.{k}", "one of " + ", ".join(sorted(allowed)) + _nearest(k, allowed),
                             got="an unknown key")
    num = {}
    for k in allowed - {"distribution"}:
        if k in spec:
            v = spec[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(src, f"{fld}.{k}", "a finite number (a factor on the nominal value)", got=repr(v))
            num[k] = float(v)
    if dist == "uniform":
        if "low" not in num or "high" not in num:
            raise InputError(src, fld, "both low and high for a uniform distribution", got="missing")
    else:
        if "std" not in num:
            raise InputError(src, f"{fld}.std", "a standard deviation (factor) >= 0", got="nothing (key missing)")
        if num["std"] < 0:
            raise InputError(src, f"{fld}.std", "a standard deviation >= 0", got=repr(spec["std"]))
        num.setdefault("mean", 1.0)
    lo, hi = num.get("low", -math.inf), num.get("high", math.inf)
    if not lo < hi:
        raise InputError(src, f"{fld}.high", f"a bound above low ({lo:g})", got=repr(spec.get("high")))
    if lo < 0 or (dist == "normal" and num["mean"] - 6 * num["std"] < 0 and not lo >= 0):
        raise InputError(src, f"{fld}.low", "a lower bound >= 0 (factors must stay non-negative)",
                         got=repr(spec.get("low", "none")))
    return Dispersion(name=name, distribution=dist, mean=num.get("mean", 1.0), std=num.get("std", 0.0), low=lo, high=hi)


def _case(name: str, tab, src: str) -> dict:
    if not isinstance(tab, Mapping):
        raise InputError(src, f"cases.{name}", "a table of TVC parameter overrides", got=repr(tab))
    out = {}
    for k, v in tab.items():
        if k not in PARAMETERS or k == "avionics_gain":
            allowed = sorted(set(PARAMETERS) - {"avionics_gain"})
            raise InputError(src, f"cases.{name}.{k}", "a TVC parameter: " + ", ".join(allowed) + _nearest(k, allowed),
                             got="an unknown parameter")
        p = PARAMETERS[k]
        out[k] = to_si(v, p.kind, source=src, field=f"cases.{name}.{k}", positive=True)
    return out


def load_campaign(path: str | Path) -> Campaign:
    """Load and check a campaign file (format in the module docstring). Raises
    :class:`~taos.errors.InputError` (one line) on bad input; refers files relative to it."""
    p = resolve(path, "campaign")
    src = str(p)
    raw, doc = read_toml(p, "a readable campaign file")
    for k in doc:
        if k not in TOP_KEYS:
            raise InputError(src, k, "one of " + ", ".join(sorted(TOP_KEYS)) + _nearest(k, TOP_KEYS), got="an unknown key")
    asc = doc.get("ascent")
    if not isinstance(asc, str) or not asc:
        raise InputError(src, "ascent", "the ascent file flown (a path)", got=repr(asc))
    tvc = doc.get("tvc_model", "")
    if not isinstance(tvc, str):
        raise InputError(src, "tvc_model", "a path string", got=repr(tvc))
    fr = doc.get("friction")
    if fr is not None and not isinstance(fr, str):
        raise InputError(src, "friction", "a friction law name", got=repr(fr))
    seed = doc.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 63:
        raise InputError(src, "seed", "a whole number from 0 to 2**63 - 1", got=repr(seed))
    t = lambda k, d, **c: to_si(doc.get(k, d), "time", source=src, field=k, **c)  # noqa: E731
    start, dur, dt = t("start", "0 s", nonnegative=True), t("duration", "200 s", positive=True), t("dt", "1 ms", positive=True)
    win, trace = t("analysis_window", "100 s", positive=True), t("trace_interval", "0.5 s", positive=True)
    integrator = doc.get("integrator", "rk4")
    if integrator not in MAX_DT_S:
        raise InputError(src, "integrator", "'rk4' or 'etdrk4'", got=repr(integrator))
    if integrator == "rk4" and not 1e-5 <= dt <= 2e-3:
        raise InputError(src, "dt", "an RK4 step from 0.01 ms to 2 ms (the oil column needs it)", got=repr(doc.get("dt")))
    if integrator == "etdrk4" and not (1e-5 <= dt <= MAX_DT_S["etdrk4"]
                                       and abs(_RECORDS_S / dt - round(_RECORDS_S / dt)) < 1e-9):
        raise InputError(src, "dt", "an ETDRK4 step from 0.01 ms to 10 ms that divides 20 ms (the records)",
                         got=repr(doc.get("dt")))
    if dur / dt > MAX_SEGMENT_STEPS:
        raise InputError(src, "duration", f"at most {MAX_SEGMENT_STEPS} steps of dt per run", got=f"{dur / dt:.3g}")
    if not 10.0 <= win <= dur:
        raise InputError(src, "analysis_window", f"a window from 10 s to the duration ({dur:g} s)",
                         got=repr(doc.get("analysis_window")))
    if not dt <= trace <= dur / 10:
        raise InputError(src, "trace_interval", "an interval from dt to a tenth of the duration",
                         got=repr(doc.get("trace_interval")))
    axis = doc.get("axis", "yaw")
    if axis not in ("pitch", "yaw"):
        raise InputError(src, "axis", "'pitch' or 'yaw'", got=repr(axis))
    cases_t = doc.get("cases", {"nominal": {}})
    if not isinstance(cases_t, Mapping) or not cases_t:
        raise InputError(src, "cases", "one or more [cases.NAME] tables", got=repr(cases_t)[:60])
    cases = {str(k): _case(str(k), v, src) for k, v in cases_t.items()}
    default = doc.get("default_case", next(iter(cases)))
    if default not in cases:
        raise InputError(src, "default_case", "one of the cases: " + ", ".join(cases), got=repr(default))
    disp_t = doc.get("dispersions", {})
    if not isinstance(disp_t, Mapping):
        raise InputError(src, "dispersions", "a [dispersions] table", got=repr(disp_t)[:60])
    disp = tuple(_dispersion(str(k), v, src) for k, v in sorted(disp_t.items()))
    upd = None
    if "update_interval" in doc:
        upd = to_si(doc["update_interval"], "time", source=src, field="update_interval", positive=True)
        if not 0.01 <= upd <= 10.0:
            raise InputError(src, "update_interval", "an interval from 0.01 s to 10 s", got=repr(doc["update_interval"]))
    avionics = doc.get("avionics", "bounding")
    if avionics not in ("bounding", "model"):
        raise InputError(src, "avionics", "'bounding' (flat -1 dB, paper sec. 2.3) or 'model'", got=repr(avionics))
    ptis = doc.get("ptis", True)
    if not isinstance(ptis, bool):
        raise InputError(src, "ptis", "true or false", got=repr(ptis))
    follow = doc.get("friction_follows_thrust", False)
    if not isinstance(follow, bool):
        raise InputError(src, "friction_follows_thrust", "true or false", got=repr(follow))
    c = Campaign(name=str(doc.get("name", p.stem)), source=src, sha256=hashlib.sha256(raw).hexdigest(),
                 ascent_file=str(resolve_reference(asc, p, field="ascent", kind="campaign", what="an ascent file")),
                 tvc_model_file=(str(resolve_reference(tvc, p, field="tvc_model", kind="campaign",
                                                       what="a TVC model file")) if tvc else ""),
                 friction=fr, seed=seed, start_s=start, duration_s=dur, dt_s=dt, axis=axis,
                 analysis_window_s=win, trace_interval_s=trace, default_case=str(default), cases=cases,
                 dispersions=disp, update_interval_s=upd, ptis=ptis,
                 avionics=avionics, friction_follows_thrust=follow, integrator=integrator)
    from taos.bounds import check_campaign_bounds
    check_campaign_bounds(c, {k: f"{q.section}.{q.toml_key}" for k, q in PARAMETERS.items()})   # before any work
    return c


def check_case(c: Campaign, case: str | None) -> str:
    case = case or c.default_case
    if case not in c.cases:
        raise InputError("command line", "--case", "one of the campaign's cases: " + ", ".join(c.cases), got=repr(case))
    return case


def base_models(c: Campaign, friction: str | None = None) -> tuple[Ascent, TvcModel]:
    """The campaign's ascent and TVC model (friction law: ``friction``, else the campaign's)."""
    ascent = load_ascent(c.ascent_file)
    tvc = c.tvc_model_file or ascent.tvc_model
    if not tvc:
        raise InputError(c.source, "tvc_model", "a TVC model file here or in the ascent file", got="none")
    model = load_model(tvc, friction=friction or c.friction)
    if c.avionics == "bounding":
        from taos.flight.lco import with_bounding_avionics
        model = with_bounding_avionics(model)
    if c.update_interval_s is not None:
        ascent = dataclasses.replace(ascent, update_interval_s=c.update_interval_s)
    if not c.ptis:
        ascent = dataclasses.replace(ascent, ptis=())
    end = c.start_s + c.duration_s
    if end > ascent.end_time_s + 1e-9:
        raise InputError(c.source, "duration", f"a segment ending by the ascent's end ({ascent.end_time_s:g} s)",
                         got=f"start + duration = {end:g} s")
    return ascent, model


def run_factors(c: Campaign, index: int) -> tuple[int, dict]:
    """(run seed, factor per dispersed parameter) of run ``index``; index < 0 is the nominal run
    (all factors 1). Draws in the campaign's (sorted) parameter order from
    SeedSequence([campaign seed, index])."""
    if index < 0:
        return -1, {d.name: 1.0 for d in c.dispersions}
    ss = np.random.SeedSequence([c.seed, index])
    rng = np.random.default_rng(ss)
    factors = {d.name: d.sample(rng) for d in c.dispersions}
    run_seed = int(ss.generate_state(1, np.uint64)[0] >> np.uint64(1))
    return run_seed, factors


def apply_factors(ascent: Ascent, model: TvcModel, overrides: Mapping[str, float], factors: Mapping[str, float]
                  ) -> tuple[Ascent, TvcModel, list[str]]:
    """Ascent and model with the case's ``overrides`` (SI) and the run's ``factors`` applied;
    also the dispersed names that do not apply (e.g. bristle stiffness of a Coulomb law)."""
    from taos.identify.surrogate import apply_values

    skipped, names, values = [], list(overrides), list(overrides.values())
    for k, f in factors.items():
        if k in PARAMETERS:
            p = PARAMETERS[k]
            try:
                values.append(f if k == "avionics_gain" else p.get(model) * f)
                names.append(k)
            except (TypeError, AttributeError):  # the law has no such field
                skipped.append(k)
    # one variant through the loader (taos.variants): coulomb_torque is the friction level (the law's
    # other torque-like parameters follow it; a dispersed one among them is set as drawn)
    if names:
        model = apply_values(model, names, [float(v) for v in values])
    tr, fl = ascent.trajectory, ascent.flight
    rep = dataclasses.replace
    if "vehicle_mass" in factors:
        tr = rep(tr, mass_kg=tr.mass_kg * factors["vehicle_mass"])
    if "vehicle_inertia" in factors:
        s = factors["vehicle_inertia"]
        tr = rep(tr, inertia_kgm2=tr.inertia_kgm2 * s)
        fl = rep(fl, vehicle=rep(fl.vehicle, pitch_inertia_kgm2=fl.vehicle.pitch_inertia_kgm2 * s,
                                 yaw_inertia_kgm2=fl.vehicle.yaw_inertia_kgm2 * s))
    if "core_thrust" in factors:
        tr = rep(tr, core_thrust_per_engine_N=tr.core_thrust_per_engine_N * factors["core_thrust"])
    fcs = fl.fcs
    for k, fld in (("fcs_attitude_gain", "attitude_gain"), ("fcs_rate_gain", "rate_gain_s"),
                   ("fcs_integral_gain", "integral_gain_per_s"), ("fcs_delay", "delay_s")):
        if k in factors:
            fcs = rep(fcs, **{fld: getattr(fcs, fld) * factors[k]})
    fl = rep(fl, fcs=fcs)
    wind = ascent.wind
    if "wind" in factors:
        wind = rep(wind, scale=wind.scale * factors["wind"])
    b = ascent.boosters
    if "separation_kick" in factors:
        b = rep(b, separation_rate_kick_rad_s=b.separation_rate_kick_rad_s * factors["separation_kick"])
    return rep(ascent, trajectory=tr, flight=fl, wind=wind, boosters=b), model, skipped

