"""A series of test records of one hardware item, each fitted, and the trend across the series
(``taos compare --model MODEL --records R1 R2 ...``).

Each record is estimated (:func:`taos.identify.estimation.estimate`, per axis and per segment)
and fitted from the same start model (:func:`taos.identify.fit.fit_frequency_response`, by
default the load stiffness K_L and the Coulomb friction torque T_c free). Per record:

* every free parameter with its standard error (Gauss-Newton, from the fit);
* the piston notch per axis (the load resonance seen by the actuator,
  :func:`taos.planar.simplex.load_resonance_from_notch`) of the fitted model, its standard
  error by the delta method: var = g^T C g with g_j = d notch / d p_j (central differences,
  step 1e-4 p_j) and C the fit's covariance (correlation x outer product of the standard errors);
* the adequacy verdict of the fit (:mod:`taos.identify.adequacy`).

Order: by the records' ``test_date`` metadata when every record carries one (x = days since
the first test), else the order given (x = 1, 2, ...). Trend of each quantity y_i +- s_i: the
weighted least-squares line y = a + b x (weights 1/s_i^2), slope b with its standard error
sqrt((X^T W X)^-1)_bb, and chi^2 of the line on n - 2 degrees of freedom (a chi^2 per dof far
above 1 says the series is not a straight line within its errors, or the errors are optimistic).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from taos.errors import InputError
from taos.model import TvcModel

#: fewest and most records in a series
MIN_RECORDS, MAX_RECORDS = 2, 50
#: the default free parameters: load stiffness and friction level
DEFAULT_FREE = ("load_stiffness", "coulomb_torque")


@dataclass(frozen=True)
class Estimate:
    """A value and its 1-sigma standard error in ``unit``."""

    value: float
    std_error: float
    unit: str

    def to_dict(self) -> dict:
        fin = lambda x: float(x) if math.isfinite(x) else None  # noqa: E731
        return {"value": fin(self.value), "std_error": fin(self.std_error), "unit": self.unit}


@dataclass(frozen=True, eq=False)
class SeriesRecord:
    """One record of the series: its label, file, test date (ISO text or ''), position ``x``,
    estimated responses, the fit (:class:`taos.identify.fit.FitResult`) and the quantities
    {name: Estimate} (free parameters in engineering units, ``notch_<axis>_hz``)."""

    label: str
    source: str
    test_date: str
    x: float
    responses: tuple
    fit: object
    quantities: dict

    def to_dict(self) -> dict:
        ad = self.fit.adequacy()
        return {"label": self.label, "source": self.source, "test_date": self.test_date or None, "x": self.x,
                "quantities": {k: v.to_dict() for k, v in self.quantities.items()},
                "adequacy": ad.to_dict(), "segments": [s for r in self.responses for s in r.meta.get("segments") or ()],
                "fit": self.fit.to_dict()}


@dataclass(frozen=True)
class Trend:
    """Weighted straight line y = intercept + slope x through a quantity over the series."""

    slope: float
    slope_std_error: float
    intercept: float
    intercept_std_error: float
    chi2: float
    dof: int

    def to_dict(self) -> dict:
        fin = lambda x: float(x) if math.isfinite(x) else None  # noqa: E731
        return {"slope": fin(self.slope), "slope_std_error": fin(self.slope_std_error),
                "intercept": fin(self.intercept), "intercept_std_error": fin(self.intercept_std_error),
                "chi2": fin(self.chi2), "dof": self.dof}


@dataclass(frozen=True, eq=False)
class RecordSeries:
    """The series: start model, records in order, x-axis meaning, and a trend per quantity."""

    model: TvcModel
    records: tuple[SeriesRecord, ...]
    x_label: str
    trends: dict

    @property
    def quantity_names(self) -> list[str]:
        return list(dict.fromkeys(k for r in self.records for k in r.quantities))

    def table(self) -> str:
        names = self.quantity_names
        w = max(8, max(len(r.label) for r in self.records))
        head = f"{'record':{w}s} {'x':>7s} " + " ".join(f"{n:>26s}" for n in names) + "  fit"
        units = f"{'':{w}s} {'':>7s} " + " ".join(f"{'[' + self._unit(n) + ']':>26s}" for n in names)
        lines = [head, units]
        for r in self.records:
            cells = []
            for n in names:
                q = r.quantities.get(n)
                cells.append(f"{'-':>26s}" if q is None else f"{q.value:>14.6g} +- {q.std_error:<8.3g}")
            lines.append(f"{r.label:{w}s} {r.x:7.4g} " + " ".join(cells) + f"  {r.fit.adequacy().verdict}")
        lines.append(f"trend per unit of x ({self.x_label}); chi2/dof of the straight line:")
        for n in names:
            t = self.trends[n]
            lines.append(f"  {n:24s} slope {t.slope:12.5g} +- {t.slope_std_error:<10.3g} {self._unit(n)} per x; "
                         f"chi2 {t.chi2:.3g} on {t.dof} dof")
        return "\n".join(lines)

    def _unit(self, name: str) -> str:
        return next(r.quantities[name].unit for r in self.records if name in r.quantities)

    def to_dict(self) -> dict:
        return {"mode": "series", "model": self.model.source, "x_axis": self.x_label,
                "quantities": self.quantity_names,
                "records": [r.to_dict() for r in self.records],
                "trends": {k: {**t.to_dict(), "unit": self._unit(k)} for k, t in self.trends.items()}}


def weighted_line(x, y, s) -> Trend:
    """Weighted least-squares line through (x, y +- s) (module docstring)."""
    x, y, s = (np.asarray(a, float) for a in (x, y, s))
    ok = np.isfinite(y) & np.isfinite(s) & (s > 0)
    x, y, s = x[ok], y[ok], s[ok]
    if x.size < 2 or np.ptp(x) == 0:
        return Trend(math.nan, math.nan, math.nan, math.nan, math.nan, 0)
    X = np.column_stack([np.ones_like(x), x])
    W = 1.0 / s ** 2
    A = X.T @ (W[:, None] * X)
    cov = np.linalg.inv(A)
    beta = cov @ (X.T @ (W * y))
    chi2 = float(np.sum(W * (y - X @ beta) ** 2))
    return Trend(float(beta[1]), float(math.sqrt(cov[1, 1])), float(beta[0]), float(math.sqrt(cov[0, 0])), chi2,
                 int(x.size - 2))


def notch_estimates(fit) -> dict:
    """{``notch_<axis>_hz``: Estimate} of a fit's model, standard error by the delta method."""
    from taos.identify.surrogate import apply_values
    from taos.planar.simplex import load_resonance_from_notch

    cov = np.asarray(fit.correlation, float) * np.outer(fit.std_errors, fit.std_errors)
    out = {}
    for ax in fit.notch_hz:
        g = np.zeros(len(fit.names))
        for j, n in enumerate(fit.names):
            v = float(fit.values[j])
            h = 1e-4 * abs(v) if v else 1e-8
            hi = load_resonance_from_notch(apply_values(fit.model, [n], [v + h]), ax)   # model variants
            lo = load_resonance_from_notch(apply_values(fit.model, [n], [v - h]), ax)
            g[j] = (hi - lo) / (2 * h)
        var = float(g @ cov @ g)
        out[f"notch_{ax}_hz"] = Estimate(float(fit.notch_hz[ax]), math.sqrt(max(var, 0.0)), "Hz")
    return out


def parameter_estimates(fit) -> dict:
    """{parameter: Estimate} of a fit's free parameters in engineering units."""
    from taos.identify.surrogate import PARAMETERS

    out = {}
    for i, n in enumerate(fit.names):
        se = abs(fit.eng(i, fit.values[i] + fit.std_errors[i]) - fit.eng(i))
        out[n] = Estimate(float(fit.eng(i)), float(se), PARAMETERS[n].unit or "1")
    return out


def _order(datas, labels) -> tuple[list[int], list[float], list[str], str]:
    from taos.identify.data import record_date

    dates = [record_date(d) for d in datas]
    if all(d is not None for d in dates):
        import datetime as dt

        as_dt = [d if isinstance(d, dt.datetime) else dt.datetime(d.year, d.month, d.day) for d in dates]
        idx = sorted(range(len(datas)), key=lambda i: as_dt[i])
        t0 = as_dt[idx[0]]
        return idx, [(as_dt[i] - t0).total_seconds() / 86400.0 for i in idx], [dates[i].isoformat() for i in idx], \
            f"days since {dates[idx[0]].isoformat()} (test_date)"
    return list(range(len(datas))), [float(i + 1) for i in range(len(datas))], [""] * len(datas), "record order"


def fit_series(model: TvcModel, records: Sequence, free: Sequence[str] = DEFAULT_FREE, *,
               labels: Sequence[str] | None = None, method: str = "auto", axes=None, nperseg: int | None = None,
               starts: int = 1, progress: bool = False) -> RecordSeries:
    """Estimate and fit each record of a series from ``model`` (module docstring).

    Parameters
    ----------
    model : TvcModel
        Start model (the same for every record; its other values are held).
    records : sequence of TestData or paths
        The records (all read and validated before any fit).
    free : sequence of str
        Free parameters (:data:`taos.identify.surrogate.PARAMETERS`).
    labels : sequence of str, optional
        One label per record (default the file stems).
    method, axes, nperseg :
        As :func:`taos.identify.estimation.estimate`.
    starts : int
        Starts per fit.
    """
    from pathlib import Path

    from taos.identify.data import TestData, load_test_data
    from taos.identify.estimation import estimate
    from taos.identify.fit import fit_frequency_response

    if not MIN_RECORDS <= len(records) <= MAX_RECORDS:
        raise InputError("command line", "--records", f"{MIN_RECORDS} to {MAX_RECORDS} records",
                         got=str(len(records)))
    datas = [r if isinstance(r, TestData) else load_test_data(r) for r in records]
    labels = list(labels) if labels is not None else [Path(d.source).stem for d in datas]
    if len(labels) != len(datas) or not all(labels):
        raise InputError("command line", "--labels", f"{len(datas)} non-empty labels, one per record",
                         got=", ".join(labels)[:120])
    kw = {"axes": axes}
    if nperseg is not None:
        kw["nperseg"] = nperseg
    responses = [estimate(d, method=method, **kw) for d in datas]   # every record estimated before any fit
    idx, xs, dates, x_label = _order(datas, labels)
    it = idx
    if progress:
        from tqdm import tqdm
        it = tqdm(idx, desc="fitting records", unit="record")
    recs, problems = {}, {}   # records of one profile share their fit's problem (built once)
    for i in it:
        fit = fit_frequency_response(model, responses[i], list(free), starts=starts, problems=problems)
        q = {**parameter_estimates(fit), **notch_estimates(fit)}
        recs[i] = q, fit
    out = tuple(SeriesRecord(labels[i], datas[i].source, dates[k], xs[k], tuple(responses[i]), recs[i][1], recs[i][0])
                for k, i in enumerate(idx))
    names = list(dict.fromkeys(n for r in out for n in r.quantities))
    trends = {n: weighted_line([r.x for r in out if n in r.quantities],
                               [r.quantities[n].value for r in out if n in r.quantities],
                               [r.quantities[n].std_error for r in out if n in r.quantities]) for n in names}
    return RecordSeries(model, out, x_label, trends)


def series_curves(series: RecordSeries, n: int = 300) -> dict:
    """{label: {axis: linear FrequencyResponse of the fitted model}} over each record's data
    band (what the overlay plot draws behind the points)."""
    from taos.identify.fit import fitted_linear_curves

    return {r.label: fitted_linear_curves(r.fit, n) for r in series.records}
