"""Is the fitted model an explanation of the data? The verdict every fit reports.

For a fit that minimises 0.5 sum r_i^2 with residuals r_i normalised by each point's
1-sigma error (:mod:`taos.identify.fit`), an adequate model leaves sum r_i^2 distributed as
chi-square with m - p degrees of freedom (m residuals, p parameters; e.g. Bevington &
Robinson, *Data Reduction and Error Analysis*, 3rd ed., sec. 11.1). Reported:

* ``normalised_residual_rms`` = sqrt(sum r^2 / m) (1 when the model explains the data to the
  stated errors);
* ``chi2``, ``dof``, ``p_value`` = P(chi2_dof >= chi2) (:func:`chi2_sf`, the value of
  ``scipy.stats.chi2.sf``);
* the parameters that end on a bound (their standard errors do not mean anything there);
* ``verdict``:

  - ``"adequate"``: p_value >= ``alpha`` and no parameter at a bound;
  - ``"marginal"``: p_value < ``alpha`` but the residuals stay within ``rms_limit`` sigma
    (the estimator's sigmas hold noise only; the harmonics a friction law makes are not
    noise, so a right model on real data often sits a little above 1);
  - ``"inadequate"``: the residual rms is above ``rms_limit`` sigma, or a parameter is at a
    bound. The model (structure or held values) cannot explain the data; the parameter
    values and their errors are not to be used.

Defaults: alpha = 1e-3, rms_limit = 3 (a fit whose typical point misses by more than 3 sigma).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

ALPHA = 1e-3
RMS_LIMIT = 3.0
BOUND_TOL = 1e-4


@dataclass(frozen=True)
class Adequacy:
    """The model-adequacy verdict of one fit (module docstring)."""

    verdict: str
    normalised_residual_rms: float
    chi2: float
    dof: int
    p_value: float
    at_bound: tuple[str, ...]
    alpha: float = ALPHA
    rms_limit: float = RMS_LIMIT

    @property
    def ok(self) -> bool:
        return self.verdict != "inadequate"

    def message(self) -> str:
        """One line for the text output."""
        s = (f"model adequacy: {self.verdict.upper()} (normalised residual rms {self.normalised_residual_rms:.3g} "
             f"sigma; chi2 {self.chi2:.4g} on {self.dof} dof, p = {self.p_value:.3g})")
        if self.at_bound:
            s += f"; at a bound: {', '.join(self.at_bound)}"
        if self.verdict == "inadequate":
            s = ("WARNING: " + s + ". The model cannot explain the data: do not use these values "
                 "(check the friction law, the held parameters, the estimator, the bounds)")
        elif self.verdict == "marginal":
            s += f" (p below {self.alpha:g} but residuals within {self.rms_limit:g} sigma)"
        return s

    def to_dict(self) -> dict:
        return {"verdict": self.verdict, "adequate": self.verdict == "adequate", "ok": self.ok,
                "normalised_residual_rms": self.normalised_residual_rms, "chi2": self.chi2, "dof": self.dof,
                "p_value": self.p_value, "at_bound": list(self.at_bound), "alpha": self.alpha,
                "rms_limit": self.rms_limit, "message": self.message()}


def parameters_at_bound(names, values, lower, upper, tol: float = BOUND_TOL) -> tuple[str, ...]:
    """Names whose value lies within ``tol`` (relative) of its lower or upper bound."""
    out = []
    for n, v, lo, hi in zip(names, values, lower, upper):
        if abs(v - lo) <= tol * max(abs(lo), 1e-300) or abs(v - hi) <= tol * max(abs(hi), 1e-300):
            out.append(n)
    return tuple(out)


def assess(cost: float, n_residuals: int, n_parameters: int, at_bound=(), *, alpha: float = ALPHA,
           rms_limit: float = RMS_LIMIT) -> Adequacy:
    """Verdict from the fit's cost 0.5 sum r^2 over ``n_residuals`` normalised residuals."""
    chi2 = 2.0 * float(cost)
    dof = max(1, int(n_residuals) - int(n_parameters))
    p = float(chi2_sf(chi2, dof))
    rms = math.sqrt(chi2 / max(1, n_residuals))
    if at_bound or not np.isfinite(rms) or rms > rms_limit:
        verdict = "inadequate"
    elif p >= alpha:
        verdict = "adequate"
    else:
        verdict = "marginal"
    return Adequacy(verdict, rms, chi2, dof, p, tuple(at_bound), alpha, rms_limit)


# -- the three distribution values the fits report, from scipy.special --------------------------
# scipy.stats' distributions compute these with the same scipy.special functions (their _ppf and
# _sf; loc 0 and scale 1 leave the bits as they are), but importing scipy.stats costs about 0.4
# CPU-s a process (its distributions' docstrings are built at import), paid by every fitting
# command for three numbers. tests/test_fit_statistics.py checks the values bit for bit.

def chi2_sf(x: float, dof: float):
    """P(X >= x) for X chi-square with ``dof`` degrees of freedom (``scipy.stats.chi2.sf``:
    the complemented incomplete gamma function Q(dof / 2, x / 2), ``scipy.special.chdtrc``;
    1 for x < 0, outside the support)."""
    import scipy.special
    return np.float64(1.0) if x < 0 else scipy.special.chdtrc(dof, x)


def student_t_quantile(q: float, dof: float):
    """The q-quantile of Student's t with ``dof`` degrees of freedom (``scipy.stats.t.ppf``:
    ``scipy.special.stdtrit``; -inf at q = 0, NaN outside [0, 1] or for dof <= 0)."""
    import scipy.special
    return np.float64(-np.inf) if q == 0 and dof > 0 else scipy.special.stdtrit(dof, q)


def normal_quantile(q: float):
    """The q-quantile of the standard normal distribution (``scipy.stats.norm.ppf``: the
    inverse of Phi, ``scipy.special.ndtri``)."""
    import scipy.special
    return scipy.special.ndtri(q)
