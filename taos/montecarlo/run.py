"""One Monte Carlo run: disperse, fly the segment, measure the limit cycle.

The LCO of a run is measured as ``taos lco`` measures it (:func:`taos.flight.lco.measure_oscillation`)
over the campaign's analysis window at the end of the segment: the FCS command fundamental,
its frequency, and whether it is sustained (growth over the window > 0.8) above just under one
avionics LSB (0.004 deg). Peaks of engine angle, engine rate and attitude error are taken over
the whole segment.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from taos.errors import InputError, SimulationUnstable
from taos.flight.ascent_sim import simulate_ascent
from taos.flight.lco import measure_oscillation
from taos.montecarlo.campaign import Campaign, apply_factors, base_models, run_factors

RECORD_INTERVAL_S = 0.02


@dataclass(frozen=True)
class RunResult:
    """One run (index -1: the nominal). Angles in degrees, as the JSON shows them; ``trace_rad``
    the FCS command every ``trace_interval`` of the campaign [rad]."""

    index: int
    seed: int
    ok: bool
    factors: dict
    error: str = ""
    lco: bool = False
    amplitude_deg: float = float("nan")
    engine_amplitude_deg: float = float("nan")
    frequency_hz: float = float("nan")
    growth: float = float("nan")
    peak_engine_deg: float = float("nan")
    peak_engine_rate_deg_s: float = float("nan")
    peak_attitude_deg: float = float("nan")
    skipped: tuple = ()
    trace_rad: tuple = field(default=(), repr=False)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["skipped"] = list(self.skipped)
        d["trace_rad"] = list(self.trace_rad)
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}

    @classmethod
    def from_dict(cls, d: dict) -> "RunResult":
        d = dict(d)
        for k in ("amplitude_deg", "engine_amplitude_deg", "frequency_hz", "growth", "peak_engine_deg",
                  "peak_engine_rate_deg_s", "peak_attitude_deg"):
            if d.get(k) is None:
                d[k] = float("nan")
        d["skipped"] = tuple(d.get("skipped", ()))
        d["trace_rad"] = tuple(d.get("trace_rad", ()))
        return cls(**d)


def run_one(c: Campaign, case: str, index: int, friction: str | None = None, base=None) -> RunResult:
    """Run ``index`` of case ``case`` (index -1: nominal). ``base`` = (ascent, model) to reuse.
    A run that fails (unstable, or a dispersed value the model refuses) is returned with
    ``ok=False`` and the reason; it never raises for that."""
    ascent, model = base if base is not None else base_models(c, friction)
    seed, factors = run_factors(c, index)
    try:
        a2, m2, skipped = apply_factors(ascent, model, c.cases[case], factors)
        h = simulate_ascent(a2, m2, axes=(c.axis,), start_s=c.start_s, end_s=c.start_s + c.duration_s,
                            dt_s=c.dt_s, record_interval_s=max(RECORD_INTERVAL_S, c.dt_s),
                            seed=c.seed if index < 0 else seed)
    except (SimulationUnstable, InputError, ValueError, ArithmeticError) as e:
        return RunResult(index=index, seed=seed, ok=False, factors=factors, error=str(e).splitlines()[0][:300])
    t_end = float(h.t_s[-1])
    m = measure_oscillation(h.flight_history(c.axis, t_end - c.analysis_window_s, t_end),
                            window_s=c.analysis_window_s)
    step = max(1, int(round(c.trace_interval_s / (h.t_s[1] - h.t_s[0]))))
    deg = math.degrees
    return RunResult(index=index, seed=seed, ok=True, factors=factors, lco=m.lco, amplitude_deg=deg(m.amplitude_rad),
                     engine_amplitude_deg=deg(m.engine_amplitude_rad), frequency_hz=m.freq_hz, growth=m.growth,
                     peak_engine_deg=deg(float(np.max(np.abs(h.signal("engine_rad", c.axis))))),
                     peak_engine_rate_deg_s=deg(float(np.max(np.abs(h.signal("engine_rate_rad_s", c.axis))))),
                     peak_attitude_deg=deg(float(np.max(np.abs(h.signal("attitude_rad", c.axis))))),
                     skipped=tuple(skipped),
                     trace_rad=tuple(float(v) for v in h.signal("command_rad", c.axis)[::step]))
