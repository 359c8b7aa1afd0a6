"""Campaign statistics: how often the TVC limit-cycles, how large, and what drives it.

Every run is counted: ``runs = ok + failed + diverged`` (a run that failed or left the physical
envelope is reported apart, with its reason in the store, never dropped).

* LCO fraction k/n over the completed runs with the Wilson score interval (E. B. Wilson,
  "Probable inference, the law of succession, and statistical inference", JASA 22 (1927)
  209-212), 95 % by default, and the range k/N .. (k + failed + diverged)/N over all N runs
  (what the fraction would be whichever way the runs without a verdict went);
* percentiles (5, 50, 95) with distribution-free intervals from order statistics: the interval
  [x_(l), x_(u)] covers the q-quantile with probability P(l <= B <= u - 1), B ~ Bin(n, q)
  (W. J. Conover, Practical Nonparametric Statistics, 3rd ed., 1999, sec. 3.2); ``None`` when
  n is too small for the confidence asked;
* envelopes: the 5/50/95 % bands of the FCS command trace over time;
* the amplitude's Spearman rank correlation with each factor (quick view) with Holm's step-down
  correction for testing every factor (S. Holm, Scand. J. Statist. 6 (1979) 65-70); the p-value
  is exact (all n! orderings) up to ``EXACT_SPEARMAN_MAX`` runs and Student's t approximation
  above (J. H. Zar, JASA 67 (1972) 578-580: good from about 10 pairs); with 4 runs the smallest
  two-sided exact p is 2/24 = 0.083, so nothing is "significant" there;
* the LCO yes/no outcome: logistic regression on the standardised factors
  (:func:`taos.montecarlo.sensitivity.logistic_regression`).

Statistics depend only on the stored runs, in run order, never on the executor or timing.

**Warnings** (``summary["warnings"]``, printed by ``taos montecarlo``): a statistic that cannot
be trusted as printed says so: the LCO fraction from fewer than ``MIN_RUNS_FRACTION`` completed
runs (its 95 % interval can then be wider than +-10 points: 1.96 sqrt(0.25/n) = 0.1 at n = 96),
a percentile without a distribution-free interval (fewer than 59 runs for p5/p95 at 95 %),
Spearman's rho from fewer than ``MIN_RUNS_SPEARMAN`` runs, and runs that diverged or failed
(the fraction over the completed runs alone then hides them: the range over all runs is the
honest figure). The ``headline`` counts every run: limit cycle, none, diverged, failed, not run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.montecarlo.sensitivity import holm, logistic_regression
from taos.montecarlo.store import STATUS

__all__ = ["wilson_interval", "quantile_interval", "percentiles", "holm", "spearman", "envelope", "CampaignResult",
           "summarise"]

PERCENTILES = (5, 50, 95)
#: fewer completed runs than this: the LCO fraction is warned about (module docstring)
MIN_RUNS_FRACTION = 100
#: fewer runs than this: Spearman's rho is warned about
MIN_RUNS_SPEARMAN = 10
#: exact permutation p-values of Spearman's rho up to this many runs (9! = 362,880 orderings)
EXACT_SPEARMAN_MAX = 9
#: runs listed in the summary's ``failures`` (all of them are in the store)
MAX_LISTED = 1000


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


def quantile_interval(n: int, q: float, confidence: float = 0.95) -> tuple[int, int] | None:
    """1-based ranks (l, u) of the order statistics bracketing the q-quantile of n samples with
    probability >= ``confidence`` (module docstring), or None when n is too small."""
    from scipy.stats import binom
    a = (1 - confidence) / 2
    lo, hi = int(binom.ppf(a, n, q)), int(binom.ppf(1 - a, n, q)) + 1
    if lo < 1 or hi > n:
        return None
    return lo, hi


def percentiles(values, confidence: float = 0.95) -> dict | None:
    """``{"n", "p5", "p5_ci", ...}`` of the finite ``values`` (None when there are none)."""
    v = np.sort(np.asarray(values, float)[np.isfinite(values)])
    if v.size == 0:
        return None
    out: dict = {"n": int(v.size)}
    for p in PERCENTILES:
        out[f"p{p}"] = float(np.percentile(v, p))
        r = quantile_interval(v.size, p / 100, confidence)
        out[f"p{p}_ci"] = None if r is None else [float(v[r[0] - 1]), float(v[r[1] - 1])]
    return out


def spearman_exact_p(x: np.ndarray, y: np.ndarray) -> float:
    """Two-sided exact p-value of Spearman's rho of (x, y): the fraction of the n! orderings of
    y's ranks whose |rho| reaches the observed one (ties: mid-ranks, permuted as they are)."""
    import itertools

    from scipy.stats import rankdata
    rx, ry = rankdata(x), rankdata(y)
    rx, ry = rx - rx.mean(), ry - ry.mean()
    perms = np.array(list(itertools.permutations(range(len(ry)))), np.int32)
    den = math.sqrt(float(rx @ rx) * float(ry @ ry))
    obs = abs(float(rx @ ry)) / den
    return float(np.mean(np.abs(ry[perms] @ rx) / den >= obs - 1e-12))


def spearman(names, factors: np.ndarray, y: np.ndarray, alpha: float = 0.05) -> list[dict]:
    """Spearman's rho of each factor column with ``y``, strongest first, Holm-adjusted; the
    p-value exact up to :data:`EXACT_SPEARMAN_MAX` runs (``p_method``)."""
    from scipy.stats import spearmanr
    rows = []
    if len(y) < 4 or np.ptp(y) == 0:
        return rows
    exact = len(y) <= EXACT_SPEARMAN_MAX
    for j, name in enumerate(names):
        x = factors[:, j]
        if np.ptp(x) == 0:
            continue
        rho, pval = spearmanr(x, y)
        if exact:
            pval = spearman_exact_p(x, y)
        rows.append({"parameter": name, "spearman_rho": float(rho), "p_value": float(pval),
                     "p_method": "exact permutation" if exact else "Student t approximation"})
    for r, a in zip(rows, holm([r["p_value"] for r in rows])):
        r["p_holm"] = float(a)
        r["significant"] = bool(a < alpha)
    rows.sort(key=lambda s: -abs(s["spearman_rho"]))
    return rows


def envelope(traces, ok: np.ndarray, block_bytes: int = 64 << 20) -> dict:
    """5/50/95 % bands [deg] over the ok runs of ``traces`` (an array or a lazy (run, time)
    xarray variable), computed a block of time columns at a time."""
    m = traces.shape[1]
    n_ok = int(ok.sum())
    env = {f"p{p}_deg": np.full(m, np.nan) for p in PERCENTILES}
    if n_ok == 0 or m == 0:
        return {k: v.tolist() for k, v in env.items()}
    step = max(1, block_bytes // (8 * max(len(ok), 1)))
    for j in range(0, m, step):
        blk = np.asarray(traces[:, j:j + step])[ok]
        for p in PERCENTILES:
            env[f"p{p}_deg"][j:j + step] = np.degrees(np.percentile(blk, p, axis=0))
    return {k: v.tolist() for k, v in env.items()}


def headline(n: int, k: int, n_ok: int, n_div: int, n_fail: int, n_pend: int, ci, all_range,
             confidence: float) -> str:
    """One line counting every run: limit cycle, none, diverged, failed, not run; the LCO fraction
    over the completed runs with its interval and, when some runs have no verdict, its range over
    all runs."""
    parts = [f"{k} limit cycle", f"{n_ok - k} none"] + [f"{c} {w}" for c, w in ((n_div, "diverged (hard stops)"),
                                                                                (n_fail, "failed"),
                                                                                (n_pend, "not run")) if c]
    text = f"{n} runs: " + ", ".join(parts)
    if n_ok:
        text += (f"; LCO in {100 * k / n_ok:.1f} % of the {n_ok} completed runs ({100 * confidence:g} % CI "
                 f"{100 * ci[0]:.1f}-{100 * ci[1]:.1f} %)")
    if n_ok < n and n:
        text += f"; over all {n} runs between {100 * all_range[0]:.1f} and {100 * all_range[1]:.1f} %"
    return text


def warnings_of(s: dict) -> list[str]:
    """What in summary ``s`` cannot be trusted as printed (module docstring)."""
    out = []
    bad = s["runs_diverged"] + s["runs_failed"]
    if bad:
        out.append(f"{bad} of {s['runs']} runs diverged or failed and have no verdict: the LCO fraction over the "
                   f"completed runs leaves them out; over all runs it lies between "
                   f"{100 * s['lco_fraction']['all_runs_low']:.1f} and {100 * s['lco_fraction']['all_runs_high']:.1f} %")
    if s["runs_not_run"]:
        out.append(f"{s['runs_not_run']} of {s['runs']} runs not run yet (resume the campaign)")
    if s["runs_ok"] < MIN_RUNS_FRACTION:
        f = s["lco_fraction"]
        out.append(f"LCO fraction from {s['runs_ok']} completed runs (fewer than {MIN_RUNS_FRACTION}): "
                   f"{100 * f['confidence']:g} % interval {100 * f['ci_low']:.1f}-{100 * f['ci_high']:.1f} %")
    for key in ("amplitude_deg_lco_runs", "amplitude_deg_all_runs", "peak_engine_deg"):
        p = s.get(key)
        if p and (p["p5_ci"] is None or p["p95_ci"] is None):
            out.append(f"{key}: p5/p95 from {p['n']} runs have no distribution-free "
                       f"{100 * s['lco_fraction']['confidence']:g} % interval (too few runs)")
    n_sp = s["runs_ok"]
    if s["sensitivity_of_amplitude"] and n_sp < MIN_RUNS_SPEARMAN:
        out.append(f"Spearman's rho from {n_sp} runs (fewer than {MIN_RUNS_SPEARMAN}): a screen, not evidence")
    return out


@dataclass(frozen=True, eq=False)
class CampaignResult:
    """A finished campaign: per-run arrays in run order (``status`` codes of
    :data:`taos.montecarlo.store.STATUS`), the envelopes and the summary (JSON-ready)."""

    campaign_name: str
    case: str
    status: np.ndarray
    lco: np.ndarray
    amplitude_deg: np.ndarray
    trace_t_s: np.ndarray
    traces_rad: object  # (run, time): an array or a lazy xarray variable
    nominal_trace_rad: np.ndarray
    summary: dict

    @property
    def n_runs(self) -> int:
        return len(self.status)

    @property
    def ok(self) -> np.ndarray:
        return self.status == STATUS["ok"]


def summarise(campaign_name: str, case: str, ds, nominal, confidence: float = 0.95) -> CampaignResult:
    """Statistics (module docstring) of the stored runs ``ds`` and the ``nominal`` run (both
    :class:`xarray.Dataset` in the store layout)."""
    st = np.asarray(ds["status"].values, np.int8)
    ok = st == STATUS["ok"]
    n_fail, n_div = int((st == STATUS["failed"]).sum()), int((st == STATUS["diverged"]).sum())
    lco = (np.asarray(ds["lco"].values, float) == 1) & ok   # (NaN: a run not run yet)
    k, n_ok, n = int(lco.sum()), int(ok.sum()), len(st)
    lo, hi = wilson_interval(k, n_ok, confidence)
    sc = {v: np.asarray(ds[v].values, float) for v in ("amplitude_deg", "frequency_hz", "peak_engine_deg",
                                                       "peak_engine_rate_deg_s", "peak_attitude_deg")}
    names = [str(x) for x in ds["parameter"].values]
    fac = np.asarray(ds["factor"].values, float)
    bad = np.flatnonzero((st == STATUS["failed"]) | (st == STATUS["diverged"]))[:MAX_LISTED]
    errors = np.asarray(ds["error"].isel(run=bad).values) if len(bad) else np.zeros(0, str)
    seeds = np.asarray(ds["seed"].isel(run=bad).values) if len(bad) else np.zeros(0, np.int64)
    nom = {v: (nominal[v].values[0].item() if v in nominal else None) for v in
           ("status", "lco", "amplitude_deg", "engine_amplitude_deg", "frequency_hz", "peak_engine_deg")}
    nom = {kk: (None if isinstance(v, float) and not math.isfinite(v) else v) for kk, v in nom.items()}
    amp = sc["amplitude_deg"]
    n_pend = int((st == STATUS["pending"]).sum())
    all_lo, all_hi = (k / n if n else None), ((k + n_fail + n_div + n_pend) / n if n else None)
    summary = {
        "campaign": campaign_name, "case": case,
        "headline": headline(n, k, n_ok, n_div, n_fail, n_pend, (lo, hi), (all_lo, all_hi), confidence),
        "runs": n, "runs_ok": n_ok, "runs_lco": k, "runs_no_lco": n_ok - k, "runs_failed": n_fail,
        "runs_diverged": n_div, "runs_not_run": n_pend,
        "lco_fraction": {"value": k / n_ok if n_ok else None, "lco_runs": k, "ci_low": lo, "ci_high": hi,
                         "confidence": confidence, "method": "Wilson score, over the completed runs",
                         "all_runs_low": all_lo, "all_runs_high": all_hi},
        "nominal": nom,
        "amplitude_deg_lco_runs": percentiles(amp[lco], confidence),
        "frequency_hz_lco_runs": percentiles(sc["frequency_hz"][lco], confidence),
        "amplitude_deg_all_runs": percentiles(amp[ok], confidence),
        "peak_engine_deg": percentiles(sc["peak_engine_deg"][ok], confidence),
        "peak_engine_rate_deg_s": percentiles(sc["peak_engine_rate_deg_s"][ok], confidence),
        "peak_attitude_deg": percentiles(sc["peak_attitude_deg"][ok], confidence),
        "sensitivity_of_amplitude": spearman(names, fac[ok], amp[ok]),
        "lco_logistic_regression": logistic_regression(names, fac[ok], lco[ok]),
        "failures": [{"index": int(i), "status": "failed" if st[i] == STATUS["failed"] else "diverged",
                      "seed": int(sd), "error": str(e)} for i, sd, e in zip(bad, seeds, errors)],
        "envelope_t_s": np.asarray(ds["time"].values).tolist(),
        "envelope": envelope(ds["trace"], ok),
    }
    summary["warnings"] = warnings_of(summary)
    return CampaignResult(campaign_name=campaign_name, case=case, status=st, lco=lco, amplitude_deg=amp,
                          trace_t_s=np.asarray(ds["time"].values), traces_rad=ds["trace"],
                          nominal_trace_rad=np.asarray(nominal["trace"].values[0]), summary=summary)
