"""Worst-point (minimax) refinement of a residual fit: min over x of max_i |r_i(x)|.

A least-squares fit minimises sum_i r_i^2; an acceptance stated as "every point within a
tolerance" is a statement about max_i |r_i|, and the two optima differ where a few points
disagree with the rest (:mod:`taos.identify.reduce`: the plain-LuGre flight model's gain error
peaks between its grid points). :func:`minimax` takes the least-squares solution on to the
minimax one by a trust-region sequential linear programme (Madsen's method, K. Madsen, "An
algorithm for minimax solution of overdetermined systems of non-linear equations", J. Inst.
Maths Applics 16, 1975):

* at x_k, with the residuals r and their Jacobian J (forward differences of step ``step`` in x,
  backward at an upper bound), solve the linear programme (HiGHS, :func:`scipy.optimize.linprog`)

      min_{d, t} t   s.t.   -t <= r_i + J_i d <= t,   |d_j| <= Delta,   lower <= x_k + d <= upper;

* F = max_i |r_i(x_k)|, predicted F - t*, actual F - F(x_k + d); the step is taken when the
  ratio rho of actual to predicted exceeds 0.01; Delta is multiplied by 2 when rho > 0.75 and
  divided by 4 when rho < 0.25;
* it ends when the predicted decrease is below ``ftol`` F (a minimax point to that accuracy),
  Delta below ``min_delta`` or after ``max_nfev`` evaluations of ``fun``.

The steps are bounded below by the evaluation noise the caller names (``step``, ``min_delta``):
the dwells behind the reduction's residuals carry a step-plan jitter, and a finite difference
or a step below it measures that jitter, not the slope.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class MinimaxResult:
    """``x`` the refined parameters, ``residuals`` r(x), ``max_abs`` = max |r(x)|, ``start_max_abs``
    the same at the start, ``nfev`` evaluations of the residual function, ``iterations`` linear
    programmes solved, ``message`` why it ended."""

    x: np.ndarray
    residuals: np.ndarray
    max_abs: float
    start_max_abs: float
    nfev: int
    iterations: int
    message: str


def _jacobian(fun, x, r, lower, upper, step):
    """Forward differences of ``fun`` at ``x`` (backward where x + step passes ``upper``)."""
    J = np.empty((r.size, x.size))
    for j in range(x.size):
        h = step if x[j] + step <= upper[j] else -step
        if x[j] + h < lower[j]:   # a bound gap narrower than the step: the whole gap
            h = upper[j] - x[j] if upper[j] - x[j] >= x[j] - lower[j] else lower[j] - x[j]
        xh = x.copy()
        xh[j] += h
        J[:, j] = (fun(xh) - r) / h if h != 0 else 0.0
    return J


def minimax(fun: Callable[[np.ndarray], np.ndarray], x0, lower, upper, *, r0=None, jac0=None, step: float = 0.02,
            delta0: float = 0.1, min_delta: float = 2e-3, ftol: float = 1e-3, max_nfev: int = 40) -> MinimaxResult:
    """Minimise max_i |fun(x)_i| over ``lower`` <= x <= ``upper`` from ``x0`` (module docstring).

    ``r0``/``jac0``: the residuals and Jacobian at ``x0`` if known (a least-squares solution's,
    saving their evaluations); ``step`` the finite-difference step in x; ``delta0`` the first
    trust radius (infinity norm, in x); ``max_nfev`` the budget of ``fun`` evaluations."""
    import scipy.optimize as so

    x = np.clip(np.asarray(x0, float), lower, upper)
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    nfev = 0

    def f(z):
        nonlocal nfev
        nfev += 1
        return np.asarray(fun(z), float)

    r = f(x) if r0 is None else np.asarray(r0, float)
    F0 = F = float(np.max(np.abs(r)))
    J = _jacobian(f, x, r, lower, upper, step) if jac0 is None else np.asarray(jac0, float)
    delta, it, msg = delta0, 0, f"budget of {max_nfev} evaluations spent"
    n, m = x.size, r.size
    c = np.r_[np.zeros(n), 1.0]
    ones = np.ones((m, 1))
    while nfev < max_nfev:
        it += 1
        A = np.vstack([np.hstack([J, -ones]), np.hstack([-J, -ones])])
        b = np.r_[-r, r]
        bounds = [(max(lo - xi, -delta), min(hi - xi, delta)) for xi, lo, hi in zip(x, lower, upper)] + [(0, None)]
        lp = so.linprog(c, A_ub=A, b_ub=b, bounds=bounds, method="highs")
        if lp.status != 0:
            msg = f"linear programme failed: {lp.message}"
            break
        d, L = lp.x[:n], float(lp.x[n])
        pred = F - L
        if pred <= ftol * max(F, 1e-12):
            msg = "minimax point (predicted decrease below ftol)"
            break
        rn = f(x + d)
        Fn = float(np.max(np.abs(rn)))
        rho = (F - Fn) / pred
        if rho > 0.01:
            x, r, F = x + d, rn, Fn
            if nfev + n > max_nfev:
                msg = f"budget of {max_nfev} evaluations spent"
                break
            J = _jacobian(f, x, r, lower, upper, step)
        if rho > 0.75:
            delta = min(2.0 * delta, 1.0)
        elif rho < 0.25:
            delta /= 4.0
        if delta < min_delta:
            msg = "trust radius below the evaluation noise"
            break
    return MinimaxResult(x=x, residuals=r, max_abs=F, start_max_abs=F0, nfev=nfev, iterations=it, message=msg)
