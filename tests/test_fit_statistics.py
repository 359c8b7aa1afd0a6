"""The distribution values every fit reports (:mod:`taos.identify.adequacy`: the chi-square p-value
of the adequacy verdict, the Student-t and normal quantiles of the confidence intervals), computed
from ``scipy.special`` without importing ``scipy.stats``, are scipy.stats' values bit for bit
(the reference: ``scipy.stats.chi2.sf``, ``t.ppf``, ``norm.ppf``, the previous path), over the
range the fits use and at the edges."""

from __future__ import annotations

import numpy as np
import pytest

from taos.identify.adequacy import chi2_sf, normal_quantile, student_t_quantile

LEVELS = np.concatenate([np.linspace(0.0, 1.0, 101), [0.95, 0.68, 0.9973, 1 - 1e-12, 1e-12]])
DOFS = [*range(1, 60), 75, 100, 250, 1000, 4321, 1e5, 1e9, 0.5, 2.5, np.inf, 0, -1, np.nan]


def _same(a, b) -> bool:
    return np.asarray(a).dtype == np.asarray(b).dtype and np.array_equal(a, b, equal_nan=True)


def test_student_t_and_normal_quantiles_are_scipy_stats_bit_for_bit():
    import scipy.stats
    for q in [*(0.5 + LEVELS / 2), 0.0, 0.25, 1e-300, 1.5, -0.1, float("nan")]:
        assert _same(normal_quantile(q), scipy.stats.norm.ppf(q)), q
        for dof in DOFS:
            assert _same(student_t_quantile(q, dof), scipy.stats.t.ppf(q, dof)), (q, dof)


@pytest.mark.parametrize("dof", [1, 2, 3, 7, 20, 113, 1000, 50_000])
def test_chi2_survival_is_scipy_stats_bit_for_bit(dof):
    import scipy.stats
    xs = np.concatenate([[0.0, -0.0, -1.0, -1e-300, 1e-300, float("inf"), float("nan"), 1e300],
                         np.geomspace(1e-6, 1e6, 241), dof * np.linspace(0.5, 2.0, 61)])
    for x in xs:
        assert _same(chi2_sf(float(x), dof), scipy.stats.chi2.sf(float(x), dof)), (x, dof)
