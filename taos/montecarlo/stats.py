"""Campaign statistics: how often the TVC limit-cycles, how large, and what drives it.

* LCO fraction k/n with the Wilson score interval (E. B. Wilson, "Probable inference, the law of
  succession, and statistical inference", JASA 22 (1927) 209-212), 95 % by default;
* percentiles (5, 50, 95) of the command oscillation amplitude and frequency (LCO runs), and of
  the peak engine angle, engine rate and attitude error (all runs);
* envelopes: the 5/50/95 % bands of the FCS command trace over time;
* sensitivity: Spearman rank correlation of each dispersed factor with the command oscillation
  amplitude, strongest first (scipy.stats.spearmanr).

Statistics depend only on the runs (sorted by index), never on the executor or timing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.montecarlo.run import RunResult

PERCENTILES = (5, 50, 95)


def wilson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion k/n: centre (k + z^2/2)/(n + z^2),
    half-width z sqrt(k(n-k)/n + z^2/4)/(n + z^2)."""
    if n == 0:
        return 0.0, 1.0
    from scipy.stats import norm
    z = float(norm.ppf(0.5 + confidence / 2))
    c = (k + z * z / 2) / (n + z * z)
    h = z * math.sqrt(k * (n - k) / n + z * z / 4) / (n + z * z)
    return max(0.0, c - h), min(1.0, c + h)


def _pct(values) -> dict | None:
    v = np.asarray([x for x in values if math.isfinite(x)], float)
    if v.size == 0:
        return None
    return {f"p{p}": float(np.percentile(v, p)) for p in PERCENTILES}


@dataclass(frozen=True, eq=False)
class CampaignResult:
    """A finished campaign: the runs (by index), the nominal run, traces and the summary."""

    campaign_name: str
    case: str
    runs: tuple[RunResult, ...]
    nominal: RunResult
    trace_t_s: np.ndarray
    traces_rad: np.ndarray
    nominal_trace_rad: np.ndarray
    summary: dict

    @property
    def n_runs(self) -> int:
        return len(self.runs)


def summarise(campaign_name: str, case: str, runs, nominal: RunResult, start_s: float, trace_interval_s: float,
              confidence: float = 0.95) -> CampaignResult:
    """Statistics of ``runs`` (module docstring) as a :class:`CampaignResult`."""
    runs = tuple(sorted(runs, key=lambda r: r.index))
    ok = [r for r in runs if r.ok]
    k = sum(1 for r in ok if r.lco)
    lo, hi = wilson_interval(k, len(ok), confidence)
    traces = np.array([r.trace_rad for r in ok], float) if ok else np.zeros((0, len(nominal.trace_rad)))
    t = start_s + trace_interval_s * np.arange(len(nominal.trace_rad))
    env = {}
    if len(ok):
        for p in PERCENTILES:
            env[f"p{p}_deg"] = np.degrees(np.percentile(traces, p, axis=0)).tolist()
    sens = []
    amp = np.array([r.amplitude_deg for r in ok])
    if len(ok) > 2:
        from scipy.stats import spearmanr
        for name in sorted(ok[0].factors):
            x = np.array([r.factors[name] for r in ok])
            if np.ptp(x) == 0 or np.ptp(amp) == 0:
                continue
            rho, pval = spearmanr(x, amp)
            sens.append({"parameter": name, "spearman_rho": float(rho), "p_value": float(pval)})
        sens.sort(key=lambda s: -abs(s["spearman_rho"]))
    lco_runs = [r for r in ok if r.lco]
    summary = {
        "campaign": campaign_name, "case": case, "runs": len(runs), "runs_ok": len(ok),
        "runs_failed": len(runs) - len(ok),
        "lco_fraction": {"value": k / len(ok) if ok else 0.0, "lco_runs": k, "ci_low": lo, "ci_high": hi,
                         "confidence": confidence, "method": "Wilson score"},
        "nominal": nominal.to_dict() | {"trace_rad": None},
        "amplitude_deg_lco_runs": _pct([r.amplitude_deg for r in lco_runs]),
        "frequency_hz_lco_runs": _pct([r.frequency_hz for r in lco_runs]),
        "amplitude_deg_all_runs": _pct([r.amplitude_deg for r in ok]),
        "peak_engine_deg": _pct([r.peak_engine_deg for r in ok]),
        "peak_engine_rate_deg_s": _pct([r.peak_engine_rate_deg_s for r in ok]),
        "peak_attitude_deg": _pct([r.peak_attitude_deg for r in ok]),
        "sensitivity_of_amplitude": sens,
        "failures": [{"index": r.index, "seed": r.seed, "factors": r.factors, "error": r.error}
                     for r in runs if not r.ok],
        "envelope_t_s": t.tolist(), "envelope": env,
    }
    return CampaignResult(campaign_name=campaign_name, case=case, runs=runs, nominal=nominal, trace_t_s=t,
                          traces_rad=traces, nominal_trace_rad=np.asarray(nominal.trace_rad, float), summary=summary)
