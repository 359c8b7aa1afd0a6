"""Fit the 3-D TAOS model to two-axis vectoring records (issue 39; seed paper sec. 4, Figure 11).

Method (:func:`fit_taos`):

1. **Points.** Each record (:class:`taos.identify.data.TestData`, one or two axes, any mix of
   dwells, sweeps, multisines, steps) is estimated as ``taos estimate`` does
   (:func:`taos.identify.estimation.estimate`, per axis and segment): command -> piston
   x_p / theta_c [m/rad] and command -> engine theta / theta_c at the record's lines, with
   their 1-sigma relative errors sigma and coherences.
2. **Model points by replay.** The 3-D model at parameters p is driven by the record's own
   commands (both axes at once, the samples' cubic spline (a linear one would lose
   (w dt_rec)^2 / 12 of the gain, 0.5 % at 10 Hz and 250 Hz) on a step
   dt = dt_rec / ceil(dt_rec / 4e-4 s), recorded on the record's time stamps:
   :func:`taos.taos3d.simulate.run_samples`), and the simulated record is estimated by the
   SAME estimator and segments. So the model's points are what the test would have measured
   had the model been the hardware: the other axis' concurrent motion (vector friction
   couples the axes), transients, the estimator's own bias and the harmonics friction makes
   are in both. One run of a 40 s record takes 0.1-0.3 s.
3. **Residuals**, as the planar fit's (:mod:`taos.identify.fit`): for each point and response
   ln(H_m / H_d) = ln|H_m / H_d| + j arg(H_m / H_d), each part over the point's sigma
   (floored at ``sigma_floor``); points below ``min_coherence`` dropped, the engine where its
   coherence allows.
4. **Bounds** from physics and the record (:mod:`taos.identify.params3d`); the fit works in
   x = ln(p / p_start).
5. **Global first stage**: a log grid (``grid`` cells per axis, default 9 x 7) over the free
   load stiffness and friction level (whichever are free) within their bounds, the other
   parameters at the start, one replay per cell (run on the threads); the start and the best
   grid cell (when better) start the local stage.
6. **Local stage**: ``scipy.optimize.least_squares`` (trust-region reflective, bounds), its
   Jacobian by forward differences in x (step ``fd_step``), the n perturbed replays run at once
   on the threads (:func:`taos.planar._parallel.run_tasks`; the compiled run releases the GIL).
7. **Statistics**: covariance s^2 (J^T J)^-1 in x with s^2 = 2 cost / (m - p) (or 1 with
   ``absolute_sigma``), standard errors of p by the delta method (se_p = p se_x), correlations,
   the adequacy verdict (:mod:`taos.identify.adequacy`).
8. **Identifiability**: a parameter whose relative standard error exceeds ``max_rel_se``
   (default 0.5) or that is correlated above ``max_corr`` (0.999) with another, or a J^T J
   with reciprocal condition below 1e-12, is not identified by the record: :func:`fit_taos`
   refuses (:class:`Unidentifiable`, an :class:`~taos.errors.InputError`: one line naming the
   parameters and why; exit 2 on the command line) unless ``refuse=False``, which returns the
   result flagged (``identifiable`` false, ``unidentified`` the names).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from taos.errors import InputError, SimulationUnstable
from taos.identify.params3d import (REPLAY_DT_S, Param3d, Unidentifiable, bounds3d, check_free3d,  # noqa: F401
                                    variant_values)

MAX_REL_SE = 0.5
MAX_CORR = 0.999
#: the grid cells kept, best first, as further local starts (``starts``)
MAX_GRID_STARTS = 10
#: residual of every point when the model cannot be built or run there (a barrier far above any
#: fitted cost, so neither the grid nor the optimiser ever prefers it)
FAILED_RESIDUAL = 1e4


def estimate_record(data, method: str = "auto", axes=None, nperseg=None):
    """The responses of ``data`` (:func:`taos.identify.estimation.estimate`) and, for 'auto',
    its segments (reused for the replays: the same command gives the same segments)."""
    from taos.identify.estimation import estimate, estimate_by_segment
    from taos.identify.segments import axis_excitation, segment_record

    if method != "auto":
        kw = {"axes": axes} if axes else {}
        return estimate(data, method=method, **kw), None
    segs = segment_record(data)
    rs = estimate_by_segment(data, axes, nperseg=nperseg, segments=segs)
    return [replace(r, meta={**r.meta, "excitation": {**axis_excitation(segs[r.axis]),
                                                      "segments": r.meta["segments"]}}) for r in rs], segs


class Replay:
    """A record and its estimated points, replayable through 3-D models (steps 1-3)."""

    def __init__(self, data, method="auto", axes=None, nperseg=None, min_coherence=0.5, sigma_floor=1e-3,
                 use_engine=True):
        self.data, self.method, self.axes, self.nperseg = data, method, axes, nperseg
        self.responses, self.segments = estimate_record(data, method, axes, nperseg)
        t = np.asarray(data.t_s, float) - float(data.t_s[0])
        dt_rec = float(np.median(np.diff(t)))
        if not np.allclose(np.diff(t), dt_rec, rtol=1e-6, atol=1e-9):
            raise InputError(data.source, "time", "uniformly sampled records (load_test_data resamples)",
                             got="uneven steps")
        self.every = max(1, int(math.ceil(dt_rec / REPLAY_DT_S - 1e-9)))
        self.dt = dt_rec / self.every
        n = (t.size - 1) * self.every
        tt = np.arange(n + 1) * self.dt
        cmd = np.zeros((n + 1, 2))
        from scipy.interpolate import CubicSpline
        for i, ax in enumerate(data.axes):   # a cubic spline: a linear one would lose (w dt)^2 / 12 of the gain
            cmd[:, ("pitch", "yaw").index(ax)] = CubicSpline(t, data.command_rad[i])(tt)
        self.cmd = cmd
        # the points used: (response index, mask of points, engine used)
        self.keep = []
        for r in self.responses:
            m = (r.coherence_piston >= min_coherence) & (r.freq_hz > 0)
            e = (r.engine is not None and use_engine)
            me = m & (r.coherence_engine >= min_coherence) if e else np.zeros_like(m)
            self.keep.append((m, me))
        self.sigma_floor = sigma_floor
        self.n_residuals = int(sum(2 * m.sum() + 2 * me.sum() for m, me in self.keep))

    @property
    def duration_s(self) -> float:
        return float(self.data.t_s[-1] - self.data.t_s[0])

    def simulate(self, tm):
        """The model's responses at the record's points (a list like ``self.responses``)."""
        from taos.taos3d import dynamics as _dy
        from taos.taos3d.simulate import run_samples

        out = run_samples(tm, self.cmd, self.dt, self.every)
        col = {k: i for i, k in enumerate(_dy.REC)}
        idx = [("pitch", "yaw").index(ax) for ax in self.data.axes]
        xp = np.vstack([out[:, col[("xp_pitch", "xp_yaw")[i]]] for i in idx])
        th = np.vstack([out[:, col[("theta_pitch", "theta_yaw")[i]]] for i in idx])
        sim = replace(self.data, piston_m=xp, engine_rad=th if self.data.engine_rad is not None else None)
        if self.method == "auto":
            from taos.identify.estimation import estimate_by_segment
            rs = estimate_by_segment(sim, self.axes, nperseg=self.nperseg, segments=self.segments)
        else:
            from taos.identify.estimation import estimate
            rs = estimate(sim, method=self.method, **({"axes": self.axes} if self.axes else {}))
        for r, d in zip(rs, self.responses):
            if r.axis != d.axis or r.freq_hz.shape != d.freq_hz.shape or not np.allclose(r.freq_hz, d.freq_hz):
                raise RuntimeError(f"replayed {r.axis} points differ from the record's ({self.data.source})")
        return rs

    def residuals(self, rs) -> np.ndarray:
        """Normalised log-complex residuals of model responses ``rs`` against the record."""
        parts = []
        for r, d, (m, me) in zip(rs, self.responses, self.keep):
            sp = np.maximum(d.sigma_piston[m], self.sigma_floor)
            q = np.log(r.piston_m_per_rad[m] / d.piston_m_per_rad[m])
            parts += [q.real / sp, np.angle(np.exp(1j * q.imag)) / sp]
            if me.any():
                se = np.maximum(d.sigma_engine[me], self.sigma_floor)
                q = np.log(r.engine[me] / d.engine[me])
                parts += [q.real / se, np.angle(np.exp(1j * q.imag)) / se]
        return np.concatenate(parts) if parts else np.zeros(0)


class _Evaluator:
    """Residuals of all records at parameters x = ln(p / p0), each distinct x replayed once
    (cached), perturbed replays on the threads; counts the 3-D runs."""

    def __init__(self, tm0, params, p0, replays, threads=None):
        self.tm0, self.params, self.p0, self.replays, self.threads = tm0, params, p0, replays, threads
        self.cache: dict[bytes, np.ndarray] = {}
        self.runs = 0
        self.failures = 0
        self._lock = threading.Lock()
        self.m = sum(rp.n_residuals for rp in replays)

    def model(self, x):
        from taos.taos3d import with_values
        vals = variant_values(self.tm0, self.params, self.p0 * np.exp(np.asarray(x, float)))
        return with_values(self.tm0, vals)

    def _compute(self, x) -> np.ndarray:
        try:
            tm = self.model(x)
            r = np.concatenate([rp.residuals(rp.simulate(tm)) for rp in self.replays])
            ok = np.all(np.isfinite(r))
        except (InputError, SimulationUnstable):
            r, ok = None, False
        with self._lock:
            self.runs += len(self.replays)
            self.failures += 0 if ok else 1
        return r if ok else np.full(self.m, FAILED_RESIDUAL)

    def __call__(self, x) -> np.ndarray:
        k = np.asarray(x, float).tobytes()
        if k not in self.cache:
            self.cache[k] = self._compute(x)
        return self.cache[k]

    def many(self, xs) -> list[np.ndarray]:
        """Residuals at every x of ``xs``, the uncached ones at once on the threads."""
        from taos.planar._parallel import run_tasks
        todo = [x for x in xs if np.asarray(x, float).tobytes() not in self.cache]
        res = run_tasks([lambda x=x: self._compute(x) for x in todo], self.threads)
        for x, r in zip(todo, res):
            self.cache[np.asarray(x, float).tobytes()] = r
        return [self(x) for x in xs]

    def jacobian(self, x, h, lo, hi) -> np.ndarray:
        """Forward differences in x (backward at an upper bound), the n replays at once."""
        x = np.asarray(x, float)
        steps = np.where(x + h <= hi, h, -h)
        steps = np.where((x + steps < lo), h, steps)
        xs = [x + steps[j] * np.eye(x.size)[j] for j in range(x.size)]
        r0 = self(x)
        rs = self.many(xs)
        return np.column_stack([(r - r0) / steps[j] for j, r in enumerate(rs)])


def _grid(ev, params, lo, hi, cells) -> dict | None:
    """The global first stage over load_stiffness and the friction level (module docstring); a
    free ``load_stiffness_yaw`` moves with ``load_stiffness`` on the grid (the same factor), or
    takes its place when that is held."""
    names = [p.name for p in params]
    kl = "load_stiffness" if "load_stiffness" in names else "load_stiffness_yaw"
    dims = [j for j, n in enumerate(names) if n in (kl, "coulomb_torque", "friction_coefficient")]
    tied = [j for j, n in enumerate(names) if n == "load_stiffness_yaw" and kl == "load_stiffness"]
    if not dims:
        return None
    t0 = time.perf_counter()
    axes_x = [np.linspace(lo[j], hi[j], cells[0] if names[j] == kl else cells[1]) for j in dims]
    mesh = np.meshgrid(*axes_x, indexing="ij")
    xs = []
    for idx in np.ndindex(mesh[0].shape):
        x = np.zeros(len(params))
        for k, j in enumerate(dims):
            x[j] = mesh[k][idx]
        for j in tied:   # K_L,yaw by the factor of K_L (within its own bounds)
            x[j] = min(max(x[names.index(kl)], lo[j]), hi[j])
        xs.append(x)
    rs = ev.many(xs)
    costs = np.array([0.5 * float(r @ r) for r in rs])
    b = int(np.argmin(costs))
    return {"parameters": [names[j] for j in dims], "grid": [a.size for a in axes_x], "cells": len(xs),
            "best_x": xs[b], "best_cost": float(costs[b]),
            "ranked_x": np.array([xs[i] for i in np.argsort(costs, kind="stable")[:MAX_GRID_STARTS]]),
            "best_si": {names[j]: float(ev.p0[j] * math.exp(xs[b][j])) for j in dims + tied},
            "wall_s": time.perf_counter() - t0}


def fit_taos(model, records: Sequence, free: Sequence[str], *, start: dict | None = None, method: str = "auto",
             axes=None, nperseg=None, min_coherence: float = 0.5, sigma_floor: float = 1e-3, use_engine: bool = True,
             global_stage: bool = True, grid=(9, 7), fd_step: float = 2e-3, max_nfev: int = 30,
             absolute_sigma: bool = False, refuse: bool = True, max_rel_se: float = MAX_REL_SE,
             max_corr: float = MAX_CORR, threads: int | None = None, starts: int | None = None,
             bounds: dict | None = None):
    """Fit ``free`` parameters (:data:`taos.identify.params3d.PARAMETERS3D`) of the 3-D model to
    ``records`` (:class:`~taos.identify.data.TestData`) (module docstring).

    ``model``: a :class:`~taos.taos3d.TaosModel` or a :class:`~taos.model.TvcModel` loaded from
    a file with ``[gimbal]``/``[geometry]`` (built by :func:`taos.taos3d.taos_model`);
    ``start``: name -> SI value; ``grid``: cells of the global stage (K_L, friction level);
    ``fd_step``: the forward-difference step in ln p; ``max_nfev``: the local stage's
    evaluations per start; ``starts``: local stages from the start and the ``starts`` - 1 best
    grid cells (None: the start, and the best cell when it is better); ``bounds``: name ->
    (lower, upper) [SI] replacing the physical bounds of those free parameters. Returns a :class:`taos.identify.fit3d_result.Fit3dResult`; raises
    :class:`Unidentifiable` when ``refuse`` and a parameter is not identified."""
    from taos.identify.fit3d_result import Fit3dResult
    from taos.taos3d import TaosModel, taos_model, with_values

    t0 = time.perf_counter()
    tm0 = model if isinstance(model, TaosModel) else taos_model(model)
    params = check_free3d(tm0, list(free))
    if start:
        unknown = [k for k in start if k not in {p.name for p in params}]
        if unknown:
            raise InputError("command line", "--start", "names among the free parameters " + ",".join(free),
                             got=",".join(unknown))
        tm0 = with_values(tm0, variant_values(tm0, [p for p in params if p.name in start],
                                              [start[p.name] for p in params if p.name in start]))
    replays = [Replay(d, method, axes, nperseg, min_coherence, sigma_floor, use_engine) for d in records]
    if not replays:
        raise InputError("command line", "DATA", "one or more records", got="none")
    p0 = np.array([p.get(tm0) for p in params], float)
    freqs = np.concatenate([r.freq_hz for rp in replays for r in rp.responses])
    axs = [r.axis for rp in replays for r in rp.responses for _ in r.freq_hz]
    lo_si, hi_si, basis = bounds3d(tm0, params, freqs, axs)
    for k, (b_lo, b_hi) in (bounds or {}).items():
        if k not in {p.name for p in params}:
            raise InputError("command line", "--bounds", "names among the free parameters " + ",".join(free),
                             got=repr(k))
        j = [p.name for p in params].index(k)
        lo_si[j], hi_si[j], basis = b_lo, b_hi, basis[:j] + ("given (--bounds)",) + basis[j + 1:]
    bad = np.flatnonzero((p0 <= lo_si) | (p0 >= hi_si))
    if bad.size:
        k = int(bad[0])
        raise InputError(tm0.base.source, params[k].key, f"a start value of {params[k].name} inside its bounds "
                         f"({basis[k]})", got=f"{p0[k]:.6g} SI, bounds [{lo_si[k]:.6g}, {hi_si[k]:.6g}]")
    lo, hi = np.log(lo_si / p0), np.log(hi_si / p0)
    ev = _Evaluator(tm0, params, p0, replays, threads)
    gs = _grid(ev, params, lo, hi, grid) if global_stage else None
    x_starts = [np.zeros(len(params))]
    if starts is not None:
        x_starts += list(gs["ranked_x"][:max(0, starts - 1)]) if gs is not None else []
        x_starts = x_starts[:starts]
    elif gs is not None and gs["best_cost"] < 0.5 * float(ev(x_starts[0]) @ ev(x_starts[0])):
        x_starts.append(gs["best_x"])
    import scipy.optimize as so
    best = None
    for x0 in x_starts:
        sol = so.least_squares(ev, x0, jac=lambda x: ev.jacobian(x, fd_step, lo, hi), bounds=(lo, hi),
                               method="trf", x_scale=1.0, max_nfev=max_nfev, xtol=1e-6, ftol=1e-8, gtol=1e-8)
        if best is None or sol.cost < best.cost:
            best = sol
    x = best.x
    r = ev(x)
    J = ev.jacobian(x, fd_step, lo, hi)
    return Fit3dResult.build(tm0, params, p0, x, r, J, lo_si, hi_si, basis, replays, ev, gs,
                             absolute_sigma=absolute_sigma, refuse=refuse, max_rel_se=max_rel_se, max_corr=max_corr,
                             wall_s=time.perf_counter() - t0, nfev=int(best.nfev), fd_step=fd_step,
                             local_starts=len(x_starts))
