"""Global sensitivity of a campaign output, and what drives the LCO yes/no outcome.

* **Sobol' indices** (I. M. Sobol', Math. Comput. Simul. 55 (2001) 271-280): first-order
  ``S1_i = V[E(Y|X_i)]/V(Y)`` and total ``ST_i = E[V(Y|X_~i)]/V(Y)``, estimated on a Saltelli
  design (A. Saltelli et al., Comput. Phys. Commun. 181 (2010) 259-270) of ``N (k + 2)`` runs
  (scrambled Sobol' sequence; ``N`` a power of two), with bootstrap confidence intervals, by SALib
  (J. Herman, W. Usher, JOSS 2 (2017) 97; ``SALib.sample.sobol``, ``SALib.analyze.sobol``).
* **Morris elementary effects** (M. D. Morris, Technometrics 33 (1991) 161-174) with the
  ``mu*`` of F. Campolongo et al. (Environ. Model. Softw. 22 (2007) 1509-1518): a cheap screen,
  ``N (k + 1)`` runs (``SALib.sample.morris``, ``SALib.analyze.morris``).
* **Logistic regression** of a yes/no outcome on the standardised factors,
  ``P(yes) = 1/(1 + exp(-(b0 + sum b_j z_j)))``, fitted by iteratively reweighted least squares
  (maximum likelihood; D. W. Hosmer, S. Lemeshow, Applied Logistic Regression, 2nd ed., 2000,
  ch. 1-2), Wald standard errors from the Fisher information, odds ratio per standard deviation
  of each factor and Holm-adjusted p-values.

**When the indices cannot be trusted** (:func:`sobol_warnings`): the true indices satisfy
``0 <= S1_i <= ST_i`` and ``sum S1_i <= 1``; an estimate breaking one of them by more than
``SOBOL_SLACK`` (0.05 of the variance) or by more than its bootstrap interval (a negative index,
``S1_i > ST_i``, ``sum S1 > 1``; the sum's half-width taken as the root sum of squares of the S1
half-widths), or an interval half-width above ``SOBOL_MAX_CONF`` (0.1: the factors cannot be
ranked), says that N is too small for this output, and the warning says so. Choosing N: the estimators' error falls as 1/sqrt(N); start at N = 256 to 1024
and double N until every index's interval is narrower than the differences that matter and no
warning is left (Saltelli et al. 2010 use N of the order of 1000; SALib's intervals at N = 16 are
wider than the indices).

The factors' distributions are those of the campaign's dispersions: ``uniform`` as is, ``normal``
as a normal truncated at [low, high] (mean +- 6 std where unbounded, floored at 0). The design
rows are run through the same engine as a Monte Carlo campaign.
"""

from __future__ import annotations

import math
import warnings
from typing import Sequence

import numpy as np

METHODS = ("sobol", "morris")
#: a bound of the Sobol' indices broken by more than this is warned about even inside its interval
SOBOL_SLACK = 0.05
#: an index's interval half-width beyond this: warned (the indices are fractions of the variance)
SOBOL_MAX_CONF = 0.1
MORRIS_LEVELS = 4


def problem(dispersions: Sequence) -> dict:
    """The SALib problem of ``dispersions`` (:class:`taos.montecarlo.campaign.Dispersion`)."""
    names, bounds, dists = [], [], []
    for d in dispersions:
        names.append(d.name)
        if d.distribution == "uniform":
            dists.append("unif")
            bounds.append([d.low, d.high])
        else:
            lo = d.low if math.isfinite(d.low) else max(0.0, d.mean - 6 * d.std)
            hi = d.high if math.isfinite(d.high) else d.mean + 6 * d.std
            if d.std == 0:
                dists.append("unif")
                bounds.append([d.mean, d.mean + 1e-12])
            else:
                dists.append("truncnorm")
                bounds.append([lo, hi, d.mean, d.std])
    return {"num_vars": len(names), "names": names, "bounds": bounds, "dists": dists}


def design(method: str, prob: dict, n: int, seed: int) -> np.ndarray:
    """The design rows (runs, k) of ``method`` with ``n`` base samples (Sobol': a power of
    two, n (k + 2) rows) or trajectories (Morris: n (k + 1) rows)."""
    if method == "sobol":
        from SALib.sample import sobol
        return sobol.sample(prob, n, calc_second_order=False, seed=seed)
    from SALib.sample import morris
    return morris.sample(prob, n, num_levels=MORRIS_LEVELS, seed=seed)


def indices(method: str, prob: dict, x: np.ndarray, y: np.ndarray, seed: int, confidence: float = 0.95) -> list[dict]:
    """Per factor: Sobol' ``S1``, ``S1_conf``, ``ST``, ``ST_conf`` (half-widths of the
    ``confidence`` bootstrap interval) or Morris ``mu_star``, ``mu_star_conf``, ``sigma``;
    strongest (ST or mu*) first."""
    y = np.asarray(y, float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if method == "sobol":
            from SALib.analyze import sobol
            r = sobol.analyze(prob, y, calc_second_order=False, conf_level=confidence, seed=seed)
            rows = [{"parameter": nm, "S1": float(r["S1"][i]), "S1_conf": float(r["S1_conf"][i]),
                     "ST": float(r["ST"][i]), "ST_conf": float(r["ST_conf"][i])} for i, nm in enumerate(prob["names"])]
            rows.sort(key=lambda d: -d["ST"])
            return rows
        from SALib.analyze import morris
        r = morris.analyze(prob, np.asarray(x, float), y, conf_level=confidence, num_levels=MORRIS_LEVELS, seed=seed)
        rows = [{"parameter": nm, "mu_star": float(r["mu_star"][i]), "mu_star_conf": float(r["mu_star_conf"][i]),
                 "sigma": float(r["sigma"][i])} for i, nm in enumerate(prob["names"])]
        rows.sort(key=lambda d: -d["mu_star"])
        return rows


def sobol_warnings(rows: Sequence[dict], n_base: int) -> list[str]:
    """Checks of Sobol' estimates ``rows`` (:func:`indices`) against ``0 <= S1 <= ST``,
    ``sum S1 <= 1`` (module docstring): one line per bound broken by more than ``SOBOL_SLACK``
    or beyond its interval, and one when an interval is wider than ``SOBOL_MAX_CONF``; each
    ends with the advice to raise N (``n_base``)."""
    out = []
    tail = f" at N = {n_base}: N is too small for this output (double N until no warning is left)"

    def broken(excess: float, conf: float, what: str) -> None:
        if excess > SOBOL_SLACK or excess > conf:
            out.append(what + (f" beyond its interval (+-{conf:.2g})" if excess > conf else
                               f" (within its interval +-{conf:.2g})") + tail)
    if any(not all(math.isfinite(r[k]) for k in ("S1", "ST", "S1_conf", "ST_conf")) for r in rows):
        return ["non-finite Sobol' indices or intervals (an output without variance?)" + tail]
    s1 = sum(r["S1"] for r in rows)
    broken(s1 - 1, math.sqrt(sum(r["S1_conf"] ** 2 for r in rows)), f"first-order indices sum to {s1:.3g} > 1")
    for r in rows:
        broken(r["S1"] - r["ST"], math.hypot(r["S1_conf"], r["ST_conf"]),
               f"{r['parameter']}: S1 {r['S1']:.3g} > ST {r['ST']:.3g}")
        for k in ("S1", "ST"):
            broken(-r[k], r[f"{k}_conf"], f"{r['parameter']}: {k} {r[k]:.3g} < 0")
    wide = max(max(r["S1_conf"], r["ST_conf"]) for r in rows) if rows else 0.0
    if wide > SOBOL_MAX_CONF:
        out.append(f"interval half-widths up to {wide:.2g} (> {SOBOL_MAX_CONF:g}): the factors cannot be ranked"
                   + tail)
    return out


def holm(pvalues) -> np.ndarray:
    """Holm's step-down adjusted p-values (family-wise error)."""
    p = np.asarray(pvalues, float)
    order = np.argsort(p)
    adj = np.empty_like(p)
    run = 0.0
    for rank, i in enumerate(order):
        run = max(run, min(1.0, (len(p) - rank) * p[i]))
        adj[i] = run
    return adj


#: |coefficient per standard deviation| beyond which the fit is taken as separated (odds ratio
#: e^30 ~ 1e13 per standard deviation: no physical factor acts so sharply on a Monte Carlo outcome)
SEPARATION_COEF = 30.0


def logistic_regression(names: Sequence[str], x: np.ndarray, yes: np.ndarray, max_iter: int = 50,
                        alpha: float = 0.05) -> dict | None:
    """Logistic regression of ``yes`` (bool per run) on the columns of ``x`` (module docstring);
    None when it cannot be fitted (one outcome only, or fewer runs than 10 per factor)."""
    from scipy.stats import norm
    yes = np.asarray(yes, bool)
    x = np.asarray(x, float)
    keep = [j for j in range(x.shape[1]) if np.ptp(x[:, j]) > 0] if x.size else []
    n = len(yes)
    if not keep or yes.all() or not yes.any() or n < 10 * len(keep):
        return None
    mu, sd = x[:, keep].mean(axis=0), x[:, keep].std(axis=0)
    z = np.column_stack([np.ones(n), (x[:, keep] - mu) / sd])
    b = np.zeros(z.shape[1])
    converged = False
    for _ in range(max_iter):
        p = 1 / (1 + np.exp(-np.clip(z @ b, -700, 700)))
        w = np.maximum(p * (1 - p), 1e-12)
        info = z.T @ (z * w[:, None])
        step = np.linalg.solve(info, z.T @ (yes - p))
        b += step
        if np.max(np.abs(step)) < 1e-10:
            converged = True
            break
    # (quasi-)complete separation: a factor (or a combination) splits the outcomes, the likelihood
    # keeps rising as a coefficient grows and no maximum-likelihood estimate exists (Albert and
    # Anderson 1984); the coefficients' signs still say which way each factor pushes
    separated = not converged or not np.all(np.isfinite(b)) or float(np.max(np.abs(b[1:]))) > SEPARATION_COEF
    p = 1 / (1 + np.exp(-np.clip(z @ b, -700, 700)))
    info = z.T @ (z * np.maximum(p * (1 - p), 1e-12)[:, None])
    with np.errstate(all="ignore"):
        se = np.sqrt(np.abs(np.diag(np.linalg.pinv(info))))
        pv = 2 * norm.sf(np.abs(b / se))
    adj = holm(np.where(np.isfinite(pv[1:]), pv[1:], 1.0))

    def num(v: float) -> float | None:
        return float(v) if math.isfinite(v) and not separated else None
    rows = [{"parameter": names[j], "coefficient_per_std": num(b[i + 1]), "std_error": num(se[i + 1]),
             "odds_ratio_per_std": num(math.exp(min(float(b[i + 1]), 700.0))), "p_value": num(pv[i + 1]),
             "p_holm": num(adj[i]), "significant": bool(adj[i] < alpha) and not separated,
             "direction": int(np.sign(b[i + 1])) if np.isfinite(b[i + 1]) else 0,
             "factor_mean": float(mu[i]), "factor_std": float(sd[i])}
            for i, j in enumerate(keep)]
    rows.sort(key=lambda r: -abs(r["coefficient_per_std"] or 0.0))
    out = {"runs": n, "converged": converged, "separation": separated, "intercept": num(b[0]), "coefficients": rows,
           "method": "maximum likelihood (IRLS), Wald intervals, Holm-adjusted p"}
    if separated:
        out["note"] = ("the outcome is (quasi-)separated by the factors: no maximum-likelihood coefficients exist "
                       "(the values are null; 'direction' gives each factor's sign); use more runs or the "
                       "Spearman view")
    return out
