"""Fit model parameters to measured frequency responses with CasADi (seed paper secs. 2.2, 4).

Method (:func:`fit_frequency_response`):

1. Residuals. For each measured point (axis, w, command amplitude A) and each response
   (command -> piston, and command -> engine where measured) the log-complex error
   ln(H_model / H_data) = ln|H_m / H_d| + j arg(H_m / H_d), each part divided by the point's
   1-sigma relative error (from the estimator; floored at ``sigma_floor``). The logarithm
   weights the notch (where |H| is small) as much as the rest and keeps gain and phase in
   one scale. Points below ``min_coherence`` are dropped. The engine DC gain is never used
   (unobservable without an absolute engine reference; the estimators return no 0 Hz point).
2. Model. :mod:`taos.identify.surrogate`: the linear simplex block with CasADi parameters (the one
   definition of the dynamics), exact responses by :func:`taos.linear.freqresp_symbolic`, and
   describing functions for the avionics and friction (closed form for Coulomb, exact
   periodic Dahl loop for Dahl/LuGre, with the amplitude as an implicit NLP variable).
3. NLP. ``ca.nlpsol('s', 'ipopt', ...)`` minimises 0.5 sum r^2 over the scaled parameters
   s = p / p_start (bounds from physics: every fitted quantity is positive, held within
   [lo, hi] times its start, see :data:`taos.identify.surrogate.PARAMETERS`) and the implicit
   amplitudes, with exact first and second derivatives (SX). ``starts`` multiple starts
   (the start values, then log-uniform draws within a factor of 2), best objective kept.
4. Defect correction (when the model has friction, or its actuator is pressure limited): the
   describing function neglects harmonics, and the surrogate knows nothing of the square-root
   valve law and cross-port relief (:mod:`taos.planar.saturation`, of which the linear block is
   the null-load-pressure linearisation), so the surrogate is corrected against the
   time-domain sine dwell of the full nonlinear model (:func:`simulate_points`, the path of
   :func:`taos.planar.freqresp.sine_dwell_points`) at the current estimate:
   c_k = H_sim / H_surrogate, data H_d / c_k refitted, until the parameters change by less
   than ``correction_tol`` (a fixed point where the *simulated* responses match the data to
   first order; noise-free data from the model class are recovered exactly).
5. Statistics. Jacobian J of the residuals with respect to the parameters along the
   implicit-amplitude manifold (implicit function theorem), covariance
   s^2 (J^T J)^-1 with s^2 = 2 cost / (m - p) (or the stated sigmas when
   ``absolute_sigma``), standard errors and the correlation matrix; confidence intervals with
   Student's t. (Gauss-Newton statistics: first order in the noise.)
"""

from __future__ import annotations

import datetime as _dt
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from taos.errors import InputError
from taos.friction.bounds import loader_bound
from taos.identify._args import check_fit_args
from taos.identify.estimation import MeasuredResponse
from taos.identify.globalstage import grid_search
from taos.identify.surrogate import PARAMETERS, apply_values, build_surrogate, check_free, solve_implicit
from taos.identify.model_file import inline_actuator_parameter_set
from taos.model import TvcModel, load_model, resolve_parameter_set
from taos.results import atomic_write
from taos.units import from_si


@dataclass(frozen=True, eq=False)
class FitResult:
    """Result of a fit: values in SI (``values``) and in engineering units (``table()``)."""

    model: TvcModel
    initial: TvcModel
    names: tuple[str, ...]
    values: np.ndarray
    start_values: np.ndarray
    std_errors: np.ndarray
    correlation: np.ndarray
    cost: float
    n_residuals: int
    sigma2: float
    data: tuple[MeasuredResponse, ...]
    fitted_piston: tuple[np.ndarray, ...]
    fitted_engine: tuple[np.ndarray | None, ...]
    notch_hz: dict
    load_resonance_hz: dict
    corrections: int = 0
    starts: int = 1
    wall_s: float = 0.0
    method: str = "casadi-ipopt"
    absolute_sigma: bool = False
    history: list = field(default_factory=list)
    lower_si: np.ndarray | None = None
    upper_si: np.ndarray | None = None
    bound_basis: tuple[str, ...] = ()
    global_search: dict | None = None

    @property
    def dof(self) -> int:
        return max(1, self.n_residuals - len(self.names))

    @property
    def at_bound(self) -> tuple[str, ...]:
        """Parameters that ended on a bound (their standard errors mean nothing)."""
        from taos.identify.adequacy import parameters_at_bound
        if self.lower_si is None:
            return ()
        return parameters_at_bound(self.names, self.values, self.lower_si, self.upper_si)

    def adequacy(self, **kwargs):
        """The model-adequacy verdict (:mod:`taos.identify.adequacy`)."""
        from taos.identify.adequacy import assess
        return assess(self.cost, self.n_residuals, len(self.names), self.at_bound, **kwargs)

    def units(self) -> list[str]:
        return [PARAMETERS[n].unit for n in self.names]

    def eng(self, i: int, value: float | None = None) -> float:
        """Parameter ``i`` (or ``value``) in its engineering unit."""
        p = PARAMETERS[self.names[i]]
        v = self.values[i] if value is None else value
        return v if not p.unit else from_si(v, _si_unit(p.kind), p.unit)

    def confidence_interval(self, level: float = 0.95) -> np.ndarray:
        """(n, 2) two-sided interval [SI] with Student's t on ``dof`` degrees of freedom."""
        from taos.identify.adequacy import normal_quantile, student_t_quantile
        q = student_t_quantile(0.5 + level / 2, self.dof) if not self.absolute_sigma else \
            normal_quantile(0.5 + level / 2)
        return np.column_stack([self.values - q * self.std_errors, self.values + q * self.std_errors])

    def to_dict(self) -> dict:
        ci = self.confidence_interval(0.95)
        lo = self.lower_si if self.lower_si is not None else np.full(len(self.names), np.nan)
        hi = self.upper_si if self.upper_si is not None else np.full(len(self.names), np.nan)
        return {
            "adequacy": self.adequacy().to_dict(),
            "parameters": {n: {"value_si": float(self.values[i]), "std_error_si": float(self.std_errors[i]),
                               "start_si": float(self.start_values[i]), "ci95_si": ci[i].tolist(),
                               "bounds_si": [float(lo[i]), float(hi[i])],
                               "bounds": [self.eng(i, float(lo[i])), self.eng(i, float(hi[i]))],
                               "bounds_basis": self.bound_basis[i] if self.bound_basis else "",
                               "at_bound": n in self.at_bound,
                               "unit": PARAMETERS[n].unit or "1", "value": self.eng(i),
                               "std_error": abs(self.eng(i, self.values[i] + self.std_errors[i]) - self.eng(i)),
                               "si_unit": _si_unit(PARAMETERS[n].kind)}
                           for i, n in enumerate(self.names)},
            "correlation": self.correlation.tolist(),
            "cost": self.cost, "n_residuals": self.n_residuals, "dof": self.dof,
            "residual_rms": math.sqrt(2 * self.cost / self.n_residuals),
            "notch_frequency_hz": self.notch_hz, "load_resonance_hz": self.load_resonance_hz,
            "breakaway_deflection_deg": math.degrees(self.model.breakaway_deflection_rad()),
            "friction_model": self.model.friction.name, "defect_corrections": self.corrections,
            "starts": self.starts, "wall_s": self.wall_s, "method": self.method,
            "global_stage": self.global_search,
            "data": [{"source": d.source, "axis": d.axis, "method": d.method, "points": len(d),
                      "condition": d.condition, "engine_dc_observable": d.engine_dc_observable} for d in self.data],
        }

    def table(self) -> str:
        lines = [f"{'parameter':24s} {'start':>14s} {'fitted':>14s} {'std error':>12s} {'bounds':>25s}  unit"]
        atb = self.at_bound
        for i, n in enumerate(self.names):
            se = abs(self.eng(i, self.values[i] + self.std_errors[i]) - self.eng(i))
            b = (f"[{self.eng(i, float(self.lower_si[i])):.4g}, {self.eng(i, float(self.upper_si[i])):.4g}]"
                 if self.lower_si is not None else "")
            lines.append(f"{n:24s} {self.eng(i, self.start_values[i]):14.6g} {self.eng(i):14.6g} {se:12.3g} "
                         f"{b:>25s}  {PARAMETERS[n].unit or '-'}" + ("  AT BOUND" if n in atb else ""))
        for ax, v in self.notch_hz.items():
            lines.append(f"notch ({ax}) {v:.4f} Hz, load resonance {self.load_resonance_hz[ax]:.4f} Hz")
        g = self.global_search
        if g:
            lines.append(f"global first stage: {g['grid'][0]} x {g['grid'][1]} describing-function grid over "
                         f"load stiffness x friction level within the physical bounds ({g['wall_s']:.2f} s), "
                         f"best {self.starts} of the start and {g['candidates']} grid minima refined by IPOPT")
        lines.append(f"residual rms {math.sqrt(2 * self.cost / self.n_residuals):.3g} (sigma units), "
                     f"{self.n_residuals} residuals, {self.corrections} defect corrections, {self.wall_s:.2f} s")
        lines.append(self.adequacy().message())
        return "\n".join(lines)

    def write_model(self, path, data_label: str = "") -> None:
        write_fitted_model(self, path, data_label)


def fitted_linear_curves(result: FitResult, n: int = 300) -> dict:
    """axis -> exact linear FrequencyResponse of the fitted model on a log grid of ``n``
    points spanning the data's frequencies (x 1/1.5 .. x 1.5) [Hz]: the grey lines that
    :func:`taos.plotting.fit.plot_fit` draws behind the data."""
    from taos.planar.freqresp import linear_freqresp

    fmin = min(float(np.min(d.freq_hz)) for d in result.data)
    fmax = max(float(np.max(d.freq_hz)) for d in result.data)
    f = np.geomspace(fmin / 1.5, fmax * 1.5, n)
    return {ax: linear_freqresp(result.model, f, ax) for ax in sorted({d.axis for d in result.data})}


def _si_unit(kind: str) -> str:
    from taos.units import DIMENSIONS
    return DIMENSIONS[kind][1]


# -- the problem ---------------------------------------------------------------------------
@dataclass(eq=False)
class FitProblem:
    """A built NLP for one model, free set and point layout; data enter as NLP parameters,
    so repeated fits (noise studies, defect corrections, multiple starts) reuse the solver."""

    model: TvcModel
    free: tuple[str, ...]
    axes: np.ndarray
    freq_hz: np.ndarray
    amp_rad: np.ndarray
    bounds: dict | None = None   # name -> (lower, upper) [SI]; default physbounds, else PARAMETERS' lo/hi x start

    def __post_init__(self):
        import casadi as ca

        from taos.identify.physbounds import physical_bounds

        self.params = check_free(self.model, self.free)
        phys = physical_bounds(self.model, self.free, self.axes, self.freq_hz)
        given = dict(self.bounds or {})
        self.bound_basis = {n: ("--bounds" if n in given else phys[n].basis if n in phys else
                                f"{PARAMETERS[n].lo:g} to {PARAMETERS[n].hi:g} x the start") for n in self.free}
        self.bounds = {**{n: (b.lower, b.upper) for n, b in phys.items()}, **given}
        self.sur = build_surrogate(self.model, self.params, self.axes, self.freq_hz, self.amp_rad)
        npar, nu, m = len(self.params), self.sur.n_u, self.freq_hz.size
        s = ca.SX.sym("s", npar)
        u = ca.SX.sym("u", nu)
        P = ca.SX.sym("P", 6 * m)
        xr, xi, er, ei, g = self.sur.fn(s, u)
        dr, di, Er, Ei, wx, we = (P[i * m:(i + 1) * m] for i in range(6))

        def logerr(hr, hi, drr, dii):
            num_r = hr * drr + hi * dii
            num_i = hi * drr - hr * dii
            return 0.5 * ca.log((hr ** 2 + hi ** 2) / (drr ** 2 + dii ** 2)), ca.atan2(num_i, num_r)

        lx, px = logerr(xr, xi, dr, di)
        le, pe = logerr(er, ei, Er, Ei)
        r = ca.vertcat(wx * lx, wx * px, we * le, we * pe)
        x = ca.vertcat(s, u)
        self.r_fn = ca.Function("r", [s, u, P], [r])
        self.jac_fn = ca.Function("J", [s, u, P], [ca.jacobian(r, s), ca.jacobian(r, u),
                                                   ca.jacobian(g, s), ca.jacobian(g, u)])
        nlp = {"x": x, "p": P, "f": 0.5 * ca.sumsqr(r), "g": g}
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.tol": 1e-10,
                "ipopt.acceptable_iter": 5, "ipopt.acceptable_tol": 1e-7, "ipopt.max_iter": 200}
        self.solver = ca.nlpsol("s", "ipopt", nlp, opts)
        lo, hi = self.scaled_bounds()
        self.lbx = np.concatenate([lo, np.full(nu, -30.0)])
        self.ubx = np.concatenate([hi, np.full(nu, 6.0)])

    def scaled_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) of the scaled parameters s = p / p_start."""
        b = self.bounds or {}
        lo = np.array([b[p.name][0] / r if p.name in b else p.lo for p, r in zip(self.params, self.sur.p_ref)])
        hi = np.array([b[p.name][1] / r if p.name in b else p.hi for p, r in zip(self.params, self.sur.p_ref)])
        for k, (p, r) in enumerate(zip(self.params, self.sur.p_ref)):   # never a value the loader refuses
            bound = loader_bound(f"{p.section}.{p.toml_key}") if r > 0 else None
            if bound is not None:
                lo[k], hi[k] = max(lo[k], bound[0] / r), min(hi[k], bound[1] / r)
        if np.any(lo >= 1.0) or np.any(hi <= 1.0):
            k = int(np.flatnonzero((lo >= 1.0) | (hi <= 1.0))[0])
            name = self.params[k].name
            where = ("command line", "--bounds") if self.bound_basis[name] == "--bounds" else \
                (self.model.source, f"{self.params[k].section}.{self.params[k].toml_key}")
            raise InputError(*where, f"a start value of {name} inside its bounds ({self.bound_basis[name]})",
                             got=f"start {self.sur.p_ref[k]:.6g} SI, bounds [{lo[k] * self.sur.p_ref[k]:.6g}, "
                                 f"{hi[k] * self.sur.p_ref[k]:.6g}] SI")
        return lo, hi

    @property
    def p_ref(self) -> np.ndarray:
        return self.sur.p_ref

    def surrogate(self, s, u=None):
        """Numeric surrogate responses (hx [m/rad], he) at scaled parameters s."""
        u = solve_implicit(self.sur, s) if u is None else u
        xr, xi, er, ei, _ = self.sur.fn(s, u)
        return (np.asarray(xr).ravel() + 1j * np.asarray(xi).ravel(),
                np.asarray(er).ravel() + 1j * np.asarray(ei).ravel())

    def solve(self, P, s0) -> tuple[np.ndarray, np.ndarray, float]:
        s0 = np.clip(np.asarray(s0, float), self.lbx[:len(self.params)], self.ubx[:len(self.params)])
        u0 = solve_implicit(self.sur, s0)
        res = self.solver(x0=np.concatenate([s0, u0]), p=P, lbx=self.lbx, ubx=self.ubx, lbg=0, ubg=0)
        x = np.asarray(res["x"]).ravel()
        return x[:len(self.params)], x[len(self.params):], float(res["f"])

    def jacobian(self, s, u, P) -> np.ndarray:
        """dr/ds along g(s, u) = 0: J_s - J_u (dg/du)^-1 dg/ds."""
        Jrs, Jru, Jgs, Jgu = (np.asarray(v) for v in self.jac_fn(s, u, P))
        if Jru.size:
            Jrs = Jrs - Jru @ np.linalg.solve(Jgu, Jgs)
        return Jrs


def _stack_points(data, use_engine: bool, min_coherence: float, sigma_floor: float):
    axes, f, A, hx, he, wx, we = [], [], [], [], [], [], []
    for d in data:
        ok = d.coherence_piston >= min_coherence
        for k in np.flatnonzero(ok & (d.freq_hz > 0)):
            axes.append(d.axis)
            f.append(d.freq_hz[k])
            A.append(d.amplitude_rad[k])
            hx.append(d.piston_m_per_rad[k])
            wx.append(1.0 / max(d.sigma_piston[k], sigma_floor))
            if use_engine and d.engine is not None and d.coherence_engine[k] >= min_coherence:
                he.append(d.engine[k])
                we.append(1.0 / max(d.sigma_engine[k], sigma_floor))
            else:
                he.append(1.0 + 0j)
                we.append(0.0)
    if not f:
        raise InputError(data[0].source if data else "data", "coherence",
                         f"points with coherence >= {min_coherence}", got="none")
    return (np.array(axes), np.array(f), np.array(A), np.array(hx), np.array(he), np.array(wx), np.array(we))


def _pack(hx, he, wx, we):
    return np.concatenate([hx.real, hx.imag, he.real, he.imag, wx, we])


def _apply(model: TvcModel, names, values) -> TvcModel:
    return apply_values(model, list(names), [float(v) for v in values])


def simulate_points(model: TvcModel, axes, freq_hz, amp_rad) -> tuple[np.ndarray, np.ndarray]:
    """Sine-dwell responses of the full nonlinear model at the points (hx [m/rad], he): every
    point of an axis in one parallel call (:func:`taos.planar.freqresp.sine_dwell_points`, the path
    of ``taos freqresp`` and of the LCO describing-function map)."""
    from taos.planar.freqresp import sine_dwell_points
    hx = np.empty(freq_hz.size, complex)
    he = np.empty(freq_hz.size, complex)
    R = model.actuator.moment_arm_m
    for ax in np.unique(axes):
        idx = np.flatnonzero(axes == ax)
        pts = sine_dwell_points(model, amp_rad[idx], freq_hz[idx], str(ax))
        hx[idx] = pts.piston * R
        he[idx] = pts.engine
    return hx, he


def _first_starts(prob: FitProblem, P, grid, starts: int, seed: int) -> list[np.ndarray]:
    """IPOPT's starts (scaled): with a grid (:mod:`taos.identify.globalstage`), the ``starts``
    best of {the start values, the grid's local minima} by the surrogate's exact cost; without
    one, the start values then log-uniform draws within a factor of 2 of them."""
    npar = len(prob.free)
    if grid is None:
        rng = np.random.default_rng(seed)
        return [np.ones(npar) if k == 0 else np.exp(rng.uniform(-math.log(2), math.log(2), npar))
                for k in range(starts)]
    pool = [np.ones(npar), *grid.candidates]
    costs = []
    for s0 in pool:
        r = np.asarray(prob.r_fn(s0, solve_implicit(prob.sur, s0), P)).ravel()
        costs.append(0.5 * float(r @ r) if np.all(np.isfinite(r)) else math.inf)
    return [pool[k] for k in np.argsort(costs, kind="stable")[:starts]]


def fit_frequency_response(model: TvcModel, data: Sequence[MeasuredResponse], free: Sequence[str], *, start: dict | None = None, starts: int = 3,
                           seed: int = 0, use_engine: bool = True, min_coherence: float = 0.5,
                           sigma_floor: float = 1e-3, correct: bool | None = None, max_corrections: int = 6,
                           correction_tol: float = 1e-4, absolute_sigma: bool = False,
                           problem: FitProblem | None = None, bounds: dict | None = None,
                           global_stage: bool = True, problems: dict | None = None) -> FitResult:
    """Fit ``free`` parameters of ``model`` to measured responses (module docstring).

    Parameters
    ----------
    model : TvcModel
        The model whose other values are held (its friction law decides the surrogate).
    data : list of MeasuredResponse
        From :mod:`taos.identify.estimation` (or synthetic).
    free : list of str
        Names from :data:`taos.identify.surrogate.PARAMETERS`.
    start : dict name -> SI value, optional
        Start values (default: the model's).
    starts : int
        Number of IPOPT starts: with the global stage the best of the start values and the
        grid's local minima, else the start values then random draws within a factor of 2.
    global_stage : bool
        Grid the surrogate's cost over the free ``load_stiffness`` and ``coulomb_torque`` within
        their physical bounds first (:mod:`taos.identify.globalstage`), so the fit does not
        depend on the start model; ``False``: local starts only.
    correct : bool, optional
        Defect correction against the time-domain sine dwell (default: when the model has
        friction or a pressure-limited actuator, i.e. whenever the surrogate is not the
        model's exact response).
    problem : FitProblem, optional
        A built problem to reuse (same model, free set and points).
    problems : dict, optional
        Built problems kept by the caller between fits (e.g. a series of records of one
        profile): the problem of this fit's model, free set, bounds and point layout is taken
        from it when there, else built and stored (the same problem either way).
    bounds : dict name -> (lower, upper) SI, optional
        Bounds of free parameters (default: the physical ranges of
        :mod:`taos.identify.physbounds`, else :data:`taos.identify.surrogate.PARAMETERS`' lo/hi
        times the start value). The result reports them and flags any value that ends on one.
    """
    check_fit_args(**{k: v for k, v in locals().items() if k not in ("problem", "problems")})   # before any work
    if problems is not None and not isinstance(problems, dict):
        raise InputError("argument", "problems", "None or a dict kept between fits", got=repr(problems)[:40])
    t0 = time.perf_counter()
    data = tuple(data)
    free = tuple(free)
    m0 = _apply(model, list((start or {}).keys()), list((start or {}).values()))
    axes, f, A, hx, he, wx, we = _stack_points(data, use_engine, min_coherence, sigma_floor)
    prob = problem
    if prob is None and problems is not None:   # the caller's problems, by content and point layout
        key = (m0.sha256, free, repr(bounds), str(axes.dtype), axes.tobytes(), f.tobytes(), A.tobytes())
        if key not in problems:
            problems[key] = FitProblem(m0, free, axes, f, A, bounds)
        prob = problems[key]
    prob = prob or FitProblem(m0, free, axes, f, A, bounds)
    P = _pack(hx, he, wx, we)
    npar = len(free)
    grid = grid_search(prob, hx, he, wx, we, keep=max(1, starts)) if global_stage else None
    best = None
    for s0 in _first_starts(prob, P, grid, max(1, starts), seed):
        s, u, cost = prob.solve(P, s0)
        if best is None or cost < best[2] - 1e-12 * abs(best[2]):
            best = (s, u, cost)
    s, u, cost = best
    fam = prob.sur.family
    if correct is None:  # the surrogate is exact only for a linear valve without friction
        correct = fam != "none" or m0.actuator.pressure_limited
    ncorr = 0
    history = [s * prob.p_ref]
    if correct:
        for _ in range(max_corrections):
            mfit = _apply(m0, free, s * prob.p_ref)
            sx, se = simulate_points(mfit, axes, f, A)
            gx, ge = prob.surrogate(s, u)
            cx, ce = sx / gx, np.where(np.abs(ge) > 0, se / np.where(ge == 0, 1, ge), 1.0)
            P = _pack(hx / cx, he / np.where(we > 0, ce, 1.0), wx, we)
            s_new, u, cost = prob.solve(P, s)
            ncorr += 1
            history.append(s_new * prob.p_ref)
            done = np.max(np.abs(s_new / s - 1)) < correction_tol
            s = s_new
            if done:
                break
    r = np.asarray(prob.r_fn(s, u, P)).ravel()
    J = prob.jacobian(s, u, P)
    keep = np.any(J != 0, axis=1) | (r != 0)
    nres = int(np.count_nonzero(np.concatenate([wx, wx, we, we]) > 0))
    sigma2 = 1.0 if absolute_sigma else 2 * cost / max(1, nres - npar)
    JtJ = J[keep].T @ J[keep]
    cov_s = sigma2 * np.linalg.pinv(JtJ)
    se_s = np.sqrt(np.clip(np.diag(cov_s), 0, None))
    d = np.where(se_s > 0, se_s, 1.0)
    corr = cov_s / np.outer(d, d)
    values = s * prob.p_ref
    mfit = _apply(m0, free, values)
    gx, ge = prob.surrogate(s, u)
    if ncorr:  # (max_corrections=0: no correction factors, the surrogate's own response)
        gx, ge = gx * cx, ge * ce
    fitted_p, fitted_e, pos = [], [], 0
    for dset in data:
        n = int(np.count_nonzero((dset.coherence_piston >= min_coherence) & (dset.freq_hz > 0)))
        fitted_p.append(gx[pos:pos + n])
        fitted_e.append(ge[pos:pos + n] if dset.engine is not None else None)
        pos += n
    from taos.planar.simplex import load_resonance_from_notch
    ax_set = sorted(set(map(str, axes)))
    return FitResult(model=mfit, initial=m0, names=free, values=values, start_values=prob.p_ref.copy(),
                     std_errors=se_s * prob.p_ref, correlation=corr, cost=cost, n_residuals=nres, sigma2=sigma2,
                     data=tuple(dset.select((dset.coherence_piston >= min_coherence) & (dset.freq_hz > 0))
                                for dset in data),
                     fitted_piston=tuple(fitted_p), fitted_engine=tuple(fitted_e),
                     notch_hz={a: load_resonance_from_notch(mfit, a) for a in ax_set},
                     load_resonance_hz={a: mfit.load_resonance_hz(a) for a in ax_set}, corrections=ncorr,
                     starts=max(1, starts), wall_s=time.perf_counter() - t0, absolute_sigma=absolute_sigma,
                     history=history, lower_si=prob.lbx[:npar] * prob.p_ref, upper_si=prob.ubx[:npar] * prob.p_ref,
                     bound_basis=tuple(prob.bound_basis[n] for n in free),
                     global_search=grid.to_dict() if grid is not None else None)


# -- writing the fitted model ------------------------------------------------------------------
def _toml_value(p, v_si: float):
    """A fitted value as written to the model file: a string with the parameter's unit, or a
    plain number for a dimensionless parameter (6 significant digits)."""
    if not p.unit:
        return float(f"{v_si:.6g}")
    return f"{from_si(v_si, _si_unit(p.kind), p.unit):.6g} {p.unit}"


def _keep_law_shape(result: FitResult, doc, todo: dict, note_stamp: str) -> None:
    """A fitted Coulomb torque T_c is the friction level: the fit scaled every held torque-like
    parameter of the law with it (:func:`taos.identify.surrogate.apply_values`), so the fitted
    file scales those written in its own ``[friction]`` table by T_c fitted / T_c of the file
    (the static torque T_s above all, so T_s >= T_c, which loading a model requires:
    docs/reference/bounds.md; also keys of other laws, for a law swapped by ``--friction``);
    those of a shared parameter set follow the file's ``coulomb_torque`` through its
    ``reference_torque``."""
    from taos.model_keys import torque_like_kinds
    from taos.units import DIMENSIONS, to_si

    ftab = doc.get("friction", {})
    if "coulomb_torque" not in result.names or "coulomb_torque" not in ftab:
        return
    src = result.initial.source
    tc_file = to_si(str(ftab["coulomb_torque"]), "torque", source=src, field="friction.coulomb_torque")
    if not tc_file > 0:
        return
    ratio = result.values[result.names.index("coulomb_torque")] / tc_file
    kinds = torque_like_kinds()
    for key, kind in kinds.items():
        if key not in ftab or key in result.names:
            continue
        v = to_si(str(ftab[key]), kind, source=src, field=f"friction.{key}") * ratio
        unit = "in*lbf" if kind == "torque" else DIMENSIONS[kind][1]
        todo[("friction", key)] = (f"{from_si(v, DIMENSIONS[kind][1], unit):.6g} {unit}",
                                   f"# scaled with the fitted coulomb_torque by taos fit ({note_stamp}): "
                                   f"the law's shape kept")


def fitted_model_text(result: FitResult, data_label: str = "") -> str:
    """The model file of ``result.initial`` with the fitted values replaced and commented
    (edited with tomlkit: every other line and comment stays as it was)."""
    import tomlkit

    from taos.results import toml_set

    src = result.initial.source
    try:
        doc = tomlkit.parse(Path(src).read_text())
    except OSError as e:
        raise InputError(src, "(file)", "the model file the fit started from", got=e.strerror) from None
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    label = data_label or ", ".join(sorted({d.source for d in result.data}))
    todo = {}   # (section, key) -> (value, comment)
    for i, n in enumerate(result.names):
        p = PARAMETERS[n]
        se = abs(result.eng(i, result.values[i] + result.std_errors[i]) - result.eng(i))
        note = f"# fitted by taos fit ({label}, {stamp}): {result.eng(i):.6g} +- {se:.3g} {p.unit or ''} (1-sigma)"
        if n == "avionics_gain":
            g = result.model.avionics.gain_table
            todo[(p.section, p.toml_key)] = ([float(f"{x:.6g}") for x in g],
                                             note.replace("fitted by", "scaled by the gain fitted by"))
            if len(result.initial.avionics.gain_table) == 0:
                todo[(p.section, "crossover_command")] = (["0 deg"], "# added by taos fit")
        else:
            todo[(p.section, p.toml_key)] = (_toml_value(p, result.values[i]), note)
    _keep_law_shape(result, doc, todo, note_stamp=stamp)
    file_law = str(result.initial.friction_table.get("model", result.initial.friction.name))
    if result.initial.friction.name != file_law:
        todo[("friction", "model")] = (result.initial.friction.name,
                                       f'# law used by the fit (--friction; the file had "{file_law}")')
    if any(s == "actuator" and k not in doc.get("actuator", {}) for s, k in todo):
        # a fitted actuator value: the fitted file describes its own actuator, not the shared set
        inline_actuator_parameter_set(doc, Path(src), src)
    for section in ("actuator", "friction"):
        ref = doc.get(section, {}).get("parameter_set")
        if ref:  # a shared set is named relative to the model file: keep it reachable
            toml_set(doc, section, "parameter_set", resolve_parameter_set(str(ref), Path(src)).as_posix(),
                     f"the shared set of {Path(src).name}")
    if "name" in doc:
        toml_set(doc, "", "name", f"{result.initial.name} (fitted)")
    for (section, key), (value, comment) in todo.items():
        try:
            toml_set(doc, section, key, value, comment)
        except KeyError:
            raise InputError(src, f"[{section}]", "the section of a fitted value", got="no such section") from None
    head = f"# Model fitted by taos fit on {stamp} to {label}; values marked '# fitted' were estimated.\n"
    return head + tomlkit.dumps(doc)


def _law_values(law) -> dict:
    import dataclasses as _dc
    return {f.name: float(getattr(law, f.name)) for f in _dc.fields(law)}


def write_fitted_model(result: FitResult, path, data_label: str = "") -> None:
    """Write the fitted model file (TOML with units, fitted values commented), atomically,
    after checking that it loads back to the fitted values."""
    text = fitted_model_text(result, data_label)

    def write(tmp: Path):
        tmp.write_text(text)
        back = load_model(tmp)
        for i, n in enumerate(result.names):
            got = PARAMETERS[n].get(back) if n != "avionics_gain" else None
            if got is not None and not math.isclose(got, result.values[i], rel_tol=1e-5):
                raise RuntimeError(f"written {n} reads back as {got}, not {result.values[i]}")
        for k, v in _law_values(result.model.friction).items():   # the fitted law, held parameters too
            got = _law_values(back.friction).get(k)
            if got is None or not math.isclose(got, v, rel_tol=1e-5, abs_tol=1e-12):
                raise RuntimeError(f"written friction {k} reads back as {got}, not {v}")
    atomic_write(path, write)
