"""Frequency responses of the TVC: exact linear, and amplitude-dependent by sine dwell.

Conventions (the same in every command, table, plot and JSON; README "Conventions"):

* command -> piston is x_p / (R theta_c) (piston position in engine-angle units,
  dimensionless; 0 dB at low frequency); where x_p / theta_c in in/deg is offered too, the
  key names the unit (``piston_in_per_deg``);
* command -> engine is theta / theta_c;
* phase is continuous from low frequency (:func:`taos.linear.phase_deg_continuous`): model
  responses take the branch of the linear model's continuous phase
  (:func:`linear_phase_reference`, computed on a dense grid from 1 mHz);
* below breakaway the engine does not move: a sine-dwell engine response whose fundamental
  is below :data:`ENGINE_HELD_RATIO` of the command is reported as "engine held" (gain and
  phase null, ``engine_held`` true), not as -330 dB.

The sine-dwell response (the describing function of the nonlinear TVC) simulates
theta_c = A sin(w t) from rest, lets the transient settle for at least ``settle_cycles``
and ``settle_time_s`` (default from the slowest linear pole), and correlates the outputs
with sin and cos over ``measure_cycles`` whole cycles (steps per cycle an integer, so the
rectangle rule is exact for the fundamental of a periodic signal). With ``method="shoot"``
the dwell is measured instead from the periodic steady state found by shooting
(:mod:`taos.planar.steady`), which starts on the exact linear orbit and skips the settling
transient. A list of amplitudes is one parallel call (:func:`sine_dwell_family`, the
N(A, w) map).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..bounds import check_axis, check_choice, check_instance
from ..errors import InputError, SimulationUnstable
from ..linear import gain_db, phase_deg_continuous
from ..model import TvcModel
from .simplex import simplex_plant, simplex_state_space
from ._parallel import run_each
from .simulate import DEFAULT_DT_S, check_friction_step, kernel_args
from taos.results import model_provenance


#: engine fundamental below this fraction of the command (-80 dB) = engine held by friction
ENGINE_HELD_RATIO = 1e-4


def linear_phase_reference(model: TvcModel, freq_hz, axis: str = "pitch", f_min_hz: float = 1e-3,
                           points_per_decade: int = 100, max_step_deg: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Continuous phase [deg] of the linear command -> piston and command -> engine responses
    at ``freq_hz``: the exact response on a log grid from ``f_min_hz`` (where the phase is near
    0) merged with the requested points, refined (bisection in log f) wherever the phase moves
    more than ``max_step_deg`` between neighbours, then unwrapped in frequency order. The
    refinement follows a lightly damped notch's +180 deg turn, which a fixed grid could read
    as -180 deg; an undamped notch (a sign flip at any resolution) is taken as +180 deg."""
    ph, _ = _phase_reference(simplex_state_space(model, axis), freq_hz, f_min_hz, points_per_decade, max_step_deg)
    return ph[:, 0], ph[:, 1]


def _phase_reference(ss, freq_hz, f_min_hz: float = 1e-3, points_per_decade: int = 100,
                     max_step_deg: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`linear_phase_reference` of the simplex block ``ss``: (continuous phase [deg],
    response) of command -> (x_p [m/rad], theta [-]) at ``freq_hz``, shape (n_freq, 2) each
    (the response comes with the reference's own grid, which holds ``freq_hz``)."""
    f = np.atleast_1d(np.asarray(freq_hz, float))
    hi = max(float(f.max()), f_min_hz * 10)

    def resp(x):
        return ss.freqresp(x, "command_rad", ["x_p_m", "theta_rad"])

    grid = np.unique(np.concatenate([np.logspace(math.log10(f_min_hz), math.log10(hi),
                                                 int(points_per_decade * math.log10(hi / f_min_hz)) + 2), f]))
    h = resp(grid)
    for _ in range(40):
        step = np.abs(np.angle(h[1:] / h[:-1]))
        bad = np.flatnonzero(np.max(step, axis=1) > math.radians(max_step_deg))
        bad = bad[grid[bad + 1] / grid[bad] > 1 + 1e-12]
        if bad.size == 0:
            break
        mid = np.sqrt(grid[bad] * grid[bad + 1])
        hm = resp(mid)
        grid = np.concatenate([grid, mid])
        h = np.concatenate([h, hm])
        o = np.argsort(grid)
        grid, h = grid[o], h[o]
    d = np.angle(h[1:] / h[:-1])
    # an undamped notch (zeros on the j-w axis: the load resonance with no damping outside the
    # servo) flips the sign of H between neighbours however fine the grid: take +180 deg, the
    # limit of any positive damping (zeros in the left half-plane)
    d = np.where(np.abs(d) > math.radians(179.0), math.pi, d)
    ph = np.degrees(np.angle(h[:1]) + np.concatenate([np.zeros((1, 2)), np.cumsum(d, axis=0)]))
    idx = np.searchsorted(grid, f)
    return ph[idx], h[idx]


@dataclass(frozen=True, eq=False)
class FrequencyResponse:
    """Command -> piston and command -> engine responses of one axis.

    ``amplitude_rad`` is None for the linear response. ``piston_phase_ref_deg`` /
    ``engine_phase_ref_deg`` (optional) are the linear model's continuous phase at the same
    frequencies, used to put each point on its continuous branch (module docstring)."""

    freq_hz: np.ndarray
    piston: np.ndarray
    engine: np.ndarray
    amplitude_rad: float | None
    axis: str = "pitch"
    engine_model: str = "simplex"
    friction_model: str = "none"
    provenance: dict = field(default_factory=dict)
    piston_phase_ref_deg: np.ndarray | None = None
    engine_phase_ref_deg: np.ndarray | None = None

    def piston_phase_deg(self) -> np.ndarray:
        """Continuous piston phase [deg] (module docstring)."""
        return phase_deg_continuous(self.freq_hz, self.piston, self.piston_phase_ref_deg)

    def engine_phase_deg(self) -> np.ndarray:
        """Continuous engine phase [deg]; NaN where the engine is held."""
        ph = phase_deg_continuous(self.freq_hz, self.engine, self.engine_phase_ref_deg)
        return np.where(self.engine_held(), np.nan, ph)

    def engine_held(self) -> np.ndarray:
        """True where the engine's fundamental is below :data:`ENGINE_HELD_RATIO` of the
        command (friction holds the engine; only sine dwells can show it)."""
        e = np.abs(np.asarray(self.engine, complex))
        if self.amplitude_rad is None or "->" in self.axis:   # linear or cross-axis: never "held"
            return np.zeros(e.shape, bool)
        return e < ENGINE_HELD_RATIO

    def to_dict(self) -> dict:
        """The JSON contract of ``taos freqresp``; engine gain and phase are null
        where the engine is held (``engine_held``)."""
        held = self.engine_held()
        eg = gain_db(np.where(held, 1.0, self.engine))
        nul = lambda a: [None if hk else float(x) for x, hk in zip(a, held)]  # noqa: E731
        d = {
            "freq_hz": [float(f) for f in self.freq_hz],
            "amplitude_deg": None if self.amplitude_rad is None else math.degrees(self.amplitude_rad),
            "axis": self.axis,
            "engine_model": self.engine_model,
            "friction_model": self.friction_model,
            "piston_definition": "x_p / (R theta_c), dimensionless; phase continuous from low frequency",
            "piston": {"gain_db": gain_db(self.piston).tolist(), "phase_deg": self.piston_phase_deg().tolist()},
            "engine": {"gain_db": nul(eg), "phase_deg": nul(self.engine_phase_deg())},
            "engine_held": held.tolist(),
            "provenance": self.provenance,
        }
        if held.any():
            d["note"] = ("engine held: below breakaway the friction holds the engine (fundamental below "
                         f"{ENGINE_HELD_RATIO:g} of the command); its gain and phase are null, not a number")
        return d


#: the ``solver`` provenance of an exact linear response (no time integration runs)
LINEAR_SOLVER = {"method": "linear (exact)", "integrator": "none (the state space's response at s = j w)"}
#: the integrator each ``integrator`` setting runs, as every result names it (the same names as
#: :class:`taos.planar.simulate.SolverSettings`' ``method``)
INTEGRATOR_NAMES = {"exp": "etdrk4", "rk4": "rk4-fixed-step"}
#: what each ``method`` of :func:`sine_dwell_points` does, as its ``solver`` provenance says it
STEADY_DESCRIPTIONS = {"settle": "sine dwell, settled from rest",
                       "shoot": "sine dwell, periodic steady state by shooting"}


def linear_freqresp(model: TvcModel, freq_hz: np.typing.ArrayLike, axis: str = "pitch") -> FrequencyResponse:
    """Exact response of the linear simplex block (no friction, unity avionics)."""
    from taos.bounds import check_response_args

    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    check_response_args(freq_hz, None, axis)
    R = model.actuator.moment_arm_m
    f = np.atleast_1d(np.asarray(freq_hz, float))
    ph, h = _phase_reference(simplex_state_space(model, axis), f)   # the response with its phase reference
    return FrequencyResponse(f, h[:, 0] / R, h[:, 1], None, axis,
                             friction_model="none",
                             provenance={**model_provenance(model), "seeds": "none (deterministic)",
                                         "solver": {**LINEAR_SOLVER, "engine": "simplex"}},
                             piston_phase_ref_deg=ph[:, 0], engine_phase_ref_deg=ph[:, 1])


def settle_time_s(model: TvcModel, axis: str = "pitch", decades: float = 4.0) -> float:
    """Time for the slowest linear mode to decay by ``decades`` decades [s]."""
    p = simplex_state_space(model, axis).poles()
    sigma = np.min(np.abs(p.real[np.abs(p.real) > 1e-9]))
    return decades * math.log(10) / sigma


#: how a sine dwell reaches the periodic orbit it measures (``taos freqresp --steady``)
STEADY_METHODS = ("settle", "shoot")
#: how a dwell is integrated: exponential Runge-Kutta (:mod:`taos.planar._expstep`) or
#: the fixed-step RK4 kernel (:mod:`taos.planar.dynamics`)
INTEGRATORS = ("exp", "rk4")


@dataclass(frozen=True, eq=False)
class DwellPoints:
    """Sine-dwell responses at paired (amplitude, frequency) points: complex ``piston``
    (x_p / (R theta_c)) and ``engine`` (theta / theta_c); with ``method="shoot"`` also the
    final scaled residual of the one-period map [-], the periods integrated and whether
    shooting converged (:mod:`taos.planar.steady`); for settled dwells these are None.
    ``solver``: what ran, as :func:`sine_dwell_points` ran it (``method``, ``integrator``
    (:data:`INTEGRATOR_NAMES`) and its settings), the ``solver`` provenance of every result
    built on these points."""

    piston: np.ndarray
    engine: np.ndarray
    method: str = "settle"
    residual: np.ndarray | None = None
    periods: np.ndarray | None = None
    converged: np.ndarray | None = None
    solver: dict = field(default_factory=dict)


def _check_dwell_settings(model, amplitudes_rad, freq_hz, axis, dt_max_s, settle_cycles, measure_cycles, settle_s,
                          min_steps_per_cycle, tol, k_rre, max_cycles) -> None:
    """The settings of :func:`sine_dwell_points`, checked at the API's boundary as the command
    line checks its values: a TvcModel, paired amplitude and frequency grids, a positive step the
    RK4 rule allows, whole cycle counts, a settling time of at most 1e4 s, a job within
    :data:`taos.planar.envelope.MAX_DWELL_STEPS` integration steps (bounded work: a settle
    count of 1e12 is refused, not run forever)."""
    from taos.bounds import (MAX_DURATION_S, MAX_DWELL_STEPS, check_count, check_grid, check_number, check_step)
    from .simplex import check_rk4_step

    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    check_axis(axis)
    A = check_grid(amplitudes_rad, "amplitudes_rad", "rad", 0.0, math.pi / 2)
    F = check_grid(freq_hz, "freq_hz", "Hz", 0.0, 1e4)
    if A.size != F.size:
        raise InputError("argument", "freq_hz", f"as many frequencies as amplitudes ({A.size})", got=str(F.size))
    dt = check_step(dt_max_s, "dt_max_s")
    check_rk4_step(dt, model, "dt_max_s")
    check_count(settle_cycles, "settle_cycles", 0)
    check_count(measure_cycles, "measure_cycles", 1)
    check_count(min_steps_per_cycle, "min_steps_per_cycle", 8, 10 ** 5)
    check_number(settle_s, "settle_s", 0.0, MAX_DURATION_S, "s", optional=True)
    check_number(tol, "tol", 0.0, 1.0, lo_open=True)
    check_count(k_rre, "k_rre", 1, 64)
    check_count(max_cycles, "max_cycles", 1, 10 ** 4)
    ts = settle_time_s(model, axis) if settle_s is None else float(settle_s)
    npc = np.maximum(np.ceil(1.0 / (F * dt)), min_steps_per_cycle)
    settle = np.maximum(np.ceil(ts * F), settle_cycles)
    total = float(np.sum((settle + measure_cycles) * npc))
    if total > MAX_DWELL_STEPS:
        field = ("settle_cycles" if np.any(settle_cycles * npc > MAX_DWELL_STEPS / 2) else
                 "measure_cycles" if np.any(measure_cycles * npc > MAX_DWELL_STEPS / 2) else
                 "settle_s" if settle_s is not None else "freq_hz")
        raise InputError("argument", field, f"sine dwells needing at most {MAX_DWELL_STEPS:.0e} integration steps "
                         "(settling, then the measured cycles, per point)", got=f"{total:.3g} steps")


def sine_dwell_points(model: TvcModel, amplitudes_rad, freq_hz, axis: str = "pitch", *,
                      dt_max_s: float | None = None, settle_cycles: int = 2, measure_cycles: int | None = None,
                      settle_s: float | None = None, min_steps_per_cycle: int = 64, method: str = "settle",
                      tol: float = 1e-4, k_rre: int = 4, max_cycles: int = 8, integrator: str = "exp") -> DwellPoints:
    """Sine dwells at paired points (``amplitudes_rad`` [rad], ``freq_hz`` [Hz], equal
    lengths), all in one parallel batch (one compiled call per dwell on the threads, the longest
    first: :func:`taos.planar._parallel.run_each`); each dwell is independent, so a
    point's result does not depend on the other points (bit for bit).

    ``method="settle"``: from rest through at least ``settle_cycles`` cycles and ``settle_s``
    [s] (default: four decades of the slowest linear mode), then ``measure_cycles`` measured
    cycles (default 2). ``method="shoot"``: the periodic steady state by shooting
    (:mod:`taos.planar.steady`, to the scaled residual ``tol``, ``k_rre`` + 1 periods per
    extrapolation, at most ``max_cycles`` extrapolations, then integration for the settling
    budget), measured over ``measure_cycles`` cycles (default 1: the orbit is periodic). Steps: at most ``dt_max_s`` [s] and at least
    ``min_steps_per_cycle`` per cycle, an integer number per cycle.

    ``integrator``: ``"exp"`` (settled dwells; default) advances the linear block exactly and
    the quantised command exactly, the friction and limits by ETDRK4
    (:mod:`taos.planar._expstep`), at the step the friction loop needs
    (:mod:`taos.planar._expplan`; ``dt_max_s`` is then the fixed step kept by the dwells whose
    linear orbit reaches the rate limit or the hard stops); ``"rk4"`` the fixed-step RK4
    kernel at ``dt_max_s`` (default :data:`taos.planar.simulate.DEFAULT_DT_S`).
    Shooting integrates its periods with the same integrator."""
    check_choice(method, "method", STEADY_METHODS)
    check_choice(integrator, "integrator", INTEGRATORS)
    use_exp = integrator == "exp"
    if dt_max_s is None:
        dt_max_s = DEFAULT_DT_S
    if measure_cycles is None:
        measure_cycles = 2 if method == "settle" else 1
    _check_dwell_settings(model, amplitudes_rad, freq_hz, axis, dt_max_s, settle_cycles, measure_cycles, settle_s,
                          min_steps_per_cycle, tol, k_rre, max_cycles)
    # own copies (writable, C order: the kernels' compiled signature, whatever the caller passed)
    A = np.array(amplitudes_rad, float, ndmin=1)
    F = np.array(freq_hz, float, ndmin=1)
    plant = simplex_plant(model, axis)
    check_friction_step(model, plant.inertia_kgm2, dt_max_s)
    ts = settle_time_s(model, axis) if settle_s is None else settle_s
    args = kernel_args(plant, model)
    ks = None   # the kernel set of settled exponential dwells: C or numba (taos.planar._cdwell)
    if use_exp:
        from ._expcoef import exp_steps_per_cycle

        if method == "settle":
            from ._cdwell import dwell_kernels

            ks = plan_ks = dwell_kernels(model)
        else:   # the shooting runs on numba's kernels, its step plan too
            from ._expplan import NUMBA as plan_ks
        npc = exp_steps_per_cycle(args, model, plant.inertia_kgm2, A, F, dt_max_s, min_steps_per_cycle, plan_ks)
    else:
        npc = np.maximum(np.ceil(1.0 / (F * dt_max_s)), min_steps_per_cycle).astype(np.int64)
    nbud = np.maximum(settle_cycles, np.ceil(ts * F)).astype(np.int64)
    nmeas = (measure_cycles * npc).astype(np.int64)
    o = plant.ss.output_index
    Cy = np.ascontiguousarray(plant.ss.C[[o("x_p_m"), o("theta_rad")]])
    kern = (model.friction.entry.rates if ks is None else ks.law(model), model.friction.pack(), model.avionics.pack())
    cost = nbud * npc + nmeas   # steps: each dwell is one task, the longest first (run_each)
    out = np.zeros((A.size, 2, 3))
    status = np.full(A.size, -1, np.int64)
    extra = {}
    if use_exp and method == "settle":
        from ._expcoef import run_dwells

        run_dwells(args, Cy, kern, A, F, npc, nbud * npc, nmeas, out, status, ks)
    elif method == "settle":
        from . import dynamics as _ig

        nset = nbud * npc
        run_each(lambda b: _ig.sine_dwell_batch(*args, Cy, *kern, A, F, npc, nset, nmeas, out, status, b, b + 1), cost)
    else:
        from . import steady

        Am, Br, bc, cc, dc = args.A, args.Br, args.bc, args.cc, args.dc
        x0, mag = steady.linear_orbit_start(Am + np.outer(bc, cc), Br.sum(axis=1) + bc * dc.sum(), A, F)
        n = Am.shape[0]
        nz = 1 if model.friction.has_state else 0
        y0 = np.zeros((A.size, n + 1))
        y0[:, :n] = x0
        scale = np.ones((A.size, n + 1))
        scale[:, :n] = np.maximum(mag, 1e-9 * np.maximum(mag.max(axis=1, keepdims=True), 1e-300))
        info = np.zeros((A.size, len(steady.INFO)))
        if use_exp:
            from ._expplan import step_tables

            tabs = step_tables(Am, bc, 1.0 / (F * npc))
        else:   # unused coefficient stacks of the right types
            z3 = np.zeros((1, n, n))
            tabs = ((z3,) * 6, np.zeros((1, 2, n)), np.zeros((1, 2, n)), np.ones(1, np.int64),
                    np.zeros(A.size, np.int64))
        stack, G, D, ms, idx = tabs
        run_each(lambda b: steady.shoot_batch(*args, Cy, *kern, *stack, G, D, ms, idx, use_exp, A, F, npc, nbud, nmeas,
                                              y0, scale, nz, tol, k_rre, max_cycles, out, info, status, b, b + 1), cost)
        extra = {"residual": info[:, steady.INFO_RESIDUAL], "periods": info[:, steady.INFO_PERIODS].astype(np.int64),
                 "converged": info[:, steady.INFO_CONVERGED] > 0.5}
    bad = np.flatnonzero(status >= 0)
    if bad.size:   # the first failing dwell in input order
        b = bad[0]
        raise SimulationUnstable(status[b] / (F[b] * npc[b]),
                                 f"sine dwell {math.degrees(A[b]):.3g} deg at {F[b]:.3g} Hz")
    # fundamental: y ~ a sin + b cos  ->  complex gain (a + j b) / A relative to A sin
    h = (out[:, :, 0] + 1j * out[:, :, 1]) / A[:, None]
    R = model.actuator.moment_arm_m
    solver = {"method": STEADY_DESCRIPTIONS[method], "integrator": INTEGRATOR_NAMES[integrator],
              "step": ("per dwell, from the friction loop and the limits (taos.planar._expplan), dt_max_s where the "
                       "linear orbit reaches the rate limit or the hard stops" if use_exp else "dt_max_s or less, a "
                       "whole number of steps per cycle"),
              "dt_max_s": float(dt_max_s), "min_steps_per_cycle": int(min_steps_per_cycle),
              "settle_cycles": int(settle_cycles), "settle_s": float(ts), "measure_cycles": int(measure_cycles),
              **(ks.provenance if ks is not None else {"kernels": "numba"})}
    if method == "shoot":
        solver.update({"tol": float(tol), "k_rre": int(k_rre), "max_cycles": int(max_cycles)})
    return DwellPoints(h[:, 0] / R, h[:, 1], method, **extra, solver=solver)


def sine_dwell_grid(model: TvcModel, amplitudes_rad: np.typing.ArrayLike, freq_hz: np.typing.ArrayLike,
                    axis: str = "pitch", **kwargs: Any) -> tuple[np.ndarray, np.ndarray]:
    """Sine-dwell responses over a grid of amplitudes x frequencies in one parallel call
    (:func:`sine_dwell_points`, whose settings it takes). Returns (piston, engine) complex
    arrays of shape (n_amp, n_freq)."""
    from taos.bounds import check_response_args

    check_response_args(freq_hz, amplitudes_rad, axis)
    amps = np.atleast_1d(np.asarray(amplitudes_rad, float))
    f = np.atleast_1d(np.asarray(freq_hz, float))
    A, F = np.meshgrid(amps, f, indexing="ij")
    pts = sine_dwell_points(model, A.ravel(), F.ravel(), axis, **kwargs)
    shape = (amps.size, f.size)
    return pts.piston.reshape(shape), pts.engine.reshape(shape)


def sine_dwell_family(model: TvcModel, freq_hz, amplitudes_rad, axis: str = "pitch",
                      **kwargs) -> list[FrequencyResponse]:
    """One response per command amplitude [rad] at ``freq_hz`` [Hz], every dwell of the
    family in one parallel call (:func:`sine_dwell_points`, whose settings it takes): the
    describing-function map N(A, w) of the ``taos freqresp --amplitude-deg A1,A2,...`` call.
    Each row equals the single-amplitude call bit for bit. With ``method="shoot"`` the
    provenance carries the largest shooting residual and whether every dwell converged."""
    from taos.bounds import check_response_args

    check_response_args(freq_hz, amplitudes_rad, axis)
    amps = np.atleast_1d(np.asarray(amplitudes_rad, float))
    f = np.atleast_1d(np.asarray(freq_hz, float))
    A, F = np.meshgrid(amps, f, indexing="ij")
    pts = sine_dwell_points(model, A.ravel(), F.ravel(), axis, **kwargs)
    shape = (amps.size, f.size)
    piston, engine = pts.piston.reshape(shape), pts.engine.reshape(shape)
    rp, re = linear_phase_reference(model, f, axis)
    prov = {**model_provenance(model), "seeds": "none (deterministic)", "steady_state": pts.method,
            "solver": {**pts.solver, "engine": "simplex"}}
    fam = []
    for i, a in enumerate(amps):
        p = dict(prov)
        if pts.residual is not None:
            p.update({"shooting_max_residual": float(pts.residual.reshape(shape)[i].max()),
                      "shooting_converged": bool(pts.converged.reshape(shape)[i].all()),
                      "shooting_periods": int(pts.periods.reshape(shape)[i].sum())})
        fam.append(FrequencyResponse(f, piston[i], engine[i], float(a), axis, friction_model=model.friction.name,
                                     provenance=p, piston_phase_ref_deg=rp, engine_phase_ref_deg=re))
    return fam


def family_to_dict(family: list[FrequencyResponse]) -> dict:
    """The ``taos freqresp`` JSON of several amplitudes: the single-amplitude keys, with
    ``amplitude_deg`` a list and each gain, phase and ``engine_held`` an (amplitude x
    frequency) list of rows, each row exactly the single-amplitude call's."""
    rows = [fr.to_dict() for fr in family]
    d = dict(rows[0])
    d["amplitude_deg"] = [r["amplitude_deg"] for r in rows]
    for k in ("piston", "engine"):
        d[k] = {q: [r[k][q] for r in rows] for q in ("gain_db", "phase_deg")}
    d["engine_held"] = [r["engine_held"] for r in rows]
    notes = [r["note"] for r in rows if "note" in r]
    if notes:
        d["note"] = notes[0]
    else:
        d.pop("note", None)
    if any("shooting_max_residual" in r["provenance"] for r in rows):
        d["provenance"] = dict(rows[0]["provenance"])
        for q in ("shooting_max_residual", "shooting_converged", "shooting_periods"):
            d["provenance"][q] = [r["provenance"][q] for r in rows]
    return d


def sine_dwell_freqresp(model: TvcModel, freq_hz: np.typing.ArrayLike, amplitude_rad: float, axis: str = "pitch",
                        **kwargs: Any) -> FrequencyResponse:
    """Amplitude-dependent response at one command amplitude [rad] (:func:`sine_dwell_family`)."""
    from taos.bounds import check_number

    check_number(amplitude_rad, "amplitude_rad", 0.0, math.pi / 2, "rad", lo_open=True)
    return sine_dwell_family(model, freq_hz, [amplitude_rad], axis, **kwargs)[0]
