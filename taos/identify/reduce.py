"""From the 3-D model to the flight loop: the planar (simplex) model whose friction reproduces
the 3-D TAOS model's low-frequency engine response (issue 39.4; seed paper sec. 4).

The paper's flight rationale ran "the linear planar simplex model with adjustments to load
stiffness, augmented with a nonlinear friction element", its modified-LuGre parameters "tuned
to produce low frequency amplitude dependence under the assumptions of the simplex model
(planar, no gimbal stiffness element) while still maintaining a reasonably good match to the
Green Run data". :func:`reduce_to_planar` does that tuning against the 3-D model:

* targets: the 3-D model's command -> engine sine dwells H3(A, f) = theta / theta_c
  (:func:`taos.taos3d.simulate.taos_freqresp_axes`, single-axis dwells from rest) on a grid of
  flight-like amplitudes A (default 0.01-0.5 deg) x low frequencies f (default 0.05-2 Hz);
* model: the planar simplex sine dwells Hp(A, f) (:func:`taos.planar.freqresp.sine_dwell_grid`)
  of the 3-D model's own model file with the free friction keys given other values
  (:meth:`taos.model.TvcModel.with_values`, so every trial is a loader-checked variant);
* fit: least squares (SciPy ``least_squares``, trust-region reflective, in log parameters
  within :data:`FREE_KEYS`' physical bounds) of the residuals, per point,
  ``20 log10|Hp/H3| / TOLERANCE_DB`` and ``arg(Hp/H3) [deg] / TOLERANCE_DEG``: each error
  counted in units of the acceptance tolerance (0.5 dB, 5 deg);
* worst point: least squares minimises the sum of squares, the acceptance is about the worst
  point, so the least-squares solution is refined to the minimax one,
  min max_i |r_i| (:func:`taos.identify.minimax.minimax`, a trust-region sequential linear
  programme), with an exchange against a CHECK grid denser than the fit grid (default the
  acceptance grid 0.1-2 Hz x 0.02-0.5 deg, 9 x 9, both axes): after each minimax the check
  points whose error exceeds the fit set's worst (at most :data:`EXCHANGE_POINTS` of them, the
  worst first) join the fit set and the minimax runs again, at most :data:`MAX_EXCHANGES`
  times, until the fit set bounds the check grid;
* verdict: the reduction is within tolerance when every fit-grid and check-grid dwell is
  (``ReductionResult.within_tolerance``; ``taos reduce`` refuses to write one that is not).

The load path needs no reduction: the model file's ``structure.load_stiffness`` is the fitted
TOTAL K_L, and the 3-D model's actuator-line stiffness is derived so that, with the FEM gimbal
halves in series, its linear command -> piston notch sits on that total's load resonance
(:mod:`taos.taos3d.calibrate`); the planar structure is already the simplex equivalent. What
the planar model lacks is the gimbal stiffness element between the bearing and the engine:
in the 3-D model a stuck bearing still lets the engine move through the gimbal halves, so the
pre-sliding branch is softer and less damped than the same bristles on the engine; the reduced
bristle stiffness and damping absorb it. ``structure.load_stiffness`` may be freed as well.

The Green Run dwell match the reduced model keeps is reported alongside (3-D vs planar at the
Green Run dwell amplitude :data:`GREENRUN_AMPLITUDE_DEG` up to 7 Hz, engine and piston), as is
the match of the unreduced planar model (the file's own friction), for comparison.
"""

from __future__ import annotations

import dataclasses
import math
import time
import types
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from taos.errors import InputError, SimulationUnstable

#: default grids of the fit: low frequencies [Hz] x flight-like command amplitudes [deg]
DEFAULT_FREQ_HZ = (0.05, 0.1, 0.2, 0.5, 1.0, 2.0)
DEFAULT_AMPLITUDES_DEG = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5)
#: the Green Run dwell check: amplitude [deg] and frequencies [Hz] (paper sec. 5.1: 0.4 deg dwells)
GREENRUN_AMPLITUDE_DEG = 0.4
GREENRUN_FREQ_HZ = (0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
#: acceptance of a reduction (issue 39.4): planar within these of the 3-D engine response
TOLERANCE_DB = 0.5
TOLERANCE_DEG = 5.0
#: keys the reduction may free -> (lowest, highest) factor on the 3-D model's value: physical
#: bounds around the hardware (a friction LEVEL within 4x, the pre-sliding branch within 20x)
FREE_KEYS = {
    "friction.coulomb_torque": (0.25, 4.0),
    "friction.bristle_stiffness": (0.05, 20.0),
    "friction.bristle_damping": (0.01, 20.0),
    "friction.vibration_velocity": (0.05, 20.0),
    "friction.damping_decay_velocity": (0.05, 20.0),
    "friction.stribeck_velocity": (0.1, 10.0),
    "structure.load_stiffness": (0.5, 2.0),
}
#: freed by default, those the law has
DEFAULT_FREE = ("friction.coulomb_torque", "friction.bristle_stiffness", "friction.bristle_damping",
                "friction.vibration_velocity")
#: at most this many dwells per axis on the fit grid (bounded work)
MAX_POINTS = 200
#: relative finite-difference step in the log parameters (above the dwells' step-plan jitter)
DIFF_STEP = 0.02
#: the check grid (the acceptance grid of issue 39.4, 9 x 9 geometric): frequencies [Hz] x
#: command amplitudes [deg], every axis of :data:`CHECK_AXES` (the reduced file serves both)
DEFAULT_CHECK_FREQ_HZ = tuple(float(f"{v:.4g}") for v in np.geomspace(0.1, 2.0, 9))
DEFAULT_CHECK_AMPLITUDES_DEG = tuple(float(f"{v:.4g}") for v in np.geomspace(0.02, 0.5, 9))
CHECK_AXES = ("pitch", "yaw")
#: the worst-point refinement: exchanges with the check grid, points joining per exchange,
#: default budget of planar evaluations
MAX_EXCHANGES = 3
EXCHANGE_POINTS = 6
REFINE_NFEV = 40


@dataclass(frozen=True, eq=False)
class MatchTable:
    """Planar vs 3-D complex responses at paired points: ``axis``, ``amplitude_deg`` (command
    amplitude [deg]), ``freq_hz`` [Hz], ``target`` (3-D) and ``planar`` of ``quantity``
    ('engine': theta/theta_c; 'piston': x_p/(R theta_c)). Errors are planar relative to 3-D:
    gain 20 log10|Hp/H3| [dB], phase arg(Hp/H3) [deg]."""

    quantity: str
    axis: tuple
    amplitude_deg: np.ndarray
    freq_hz: np.ndarray
    target: np.ndarray
    planar: np.ndarray

    @property
    def gain_error_db(self) -> np.ndarray:
        return 20.0 * np.log10(np.abs(self.planar) / np.abs(self.target))

    @property
    def phase_error_deg(self) -> np.ndarray:
        return np.degrees(np.angle(self.planar / self.target))

    @property
    def max_gain_error_db(self) -> float:
        return float(np.max(np.abs(self.gain_error_db)))

    @property
    def max_phase_error_deg(self) -> float:
        return float(np.max(np.abs(self.phase_error_deg)))

    def within(self, tol_db: float = TOLERANCE_DB, tol_deg: float = TOLERANCE_DEG) -> bool:
        return self.max_gain_error_db <= tol_db and self.max_phase_error_deg <= tol_deg

    @property
    def worst(self) -> dict:
        """The point of the largest error in units of the tolerance, max(|gain| / 0.5 dB,
        |phase| / 5 deg): its axis, amplitude [deg], frequency [Hz], errors and that ratio."""
        e = np.maximum(np.abs(self.gain_error_db) / TOLERANCE_DB, np.abs(self.phase_error_deg) / TOLERANCE_DEG)
        i = int(np.argmax(e))
        return {"axis": self.axis[i], "amplitude_deg": float(self.amplitude_deg[i]), "freq_hz": float(self.freq_hz[i]),
                "gain_error_db": float(self.gain_error_db[i]), "phase_error_deg": float(self.phase_error_deg[i]),
                "tolerance_ratio": float(e[i])}

    def worst_text(self) -> str:
        w = self.worst
        return (f"{w['axis']} {w['amplitude_deg']:g} deg at {w['freq_hz']:g} Hz: {w['gain_error_db']:+.3f} dB, "
                f"{w['phase_error_deg']:+.2f} deg ({w['tolerance_ratio']:.2f} x the tolerance)")

    def to_dict(self) -> dict:
        g = lambda h: 20.0 * np.log10(np.abs(h))
        p = lambda h: np.degrees(np.angle(h))
        return {"quantity": self.quantity, "max_gain_error_db": self.max_gain_error_db,
                "max_phase_error_deg": self.max_phase_error_deg, "worst": self.worst,
                "points": [{"axis": a, "amplitude_deg": float(A), "freq_hz": float(f),
                            "gain_3d_db": float(g(t)), "phase_3d_deg": float(p(t)),
                            "gain_planar_db": float(g(h)), "phase_planar_deg": float(p(h)),
                            "gain_error_db": float(e), "phase_error_deg": float(q)}
                           for a, A, f, t, h, e, q in zip(self.axis, self.amplitude_deg, self.freq_hz, self.target,
                                                          self.planar, self.gain_error_db, self.phase_error_deg)]}


@dataclass(frozen=True, eq=False)
class ReductionResult:
    """The planar reduction of a 3-D model (:func:`reduce_to_planar`).

    ``model``: the reduced planar model (the 3-D model's file with ``free`` at ``values_si``, a
    variant recording them); ``source``: the 3-D model's planar base (its file, hashes,
    overrides); ``start_si``, ``lower_si``, ``upper_si``: the 3-D model's values and the bounds
    [SI]; ``match``: reduced planar vs 3-D engine dwells on the fit grid; ``match_before``: the
    same for the unreduced planar model; ``check``: reduced planar vs 3-D engine dwells on the
    check grid (both axes); ``refine``: what the worst-point refinement did (``method``,
    ``nfev``, ``exchanges``, ``points_added``, the worst normalised error after the least squares
    and after the refinement, ``message``); ``greenrun_engine``/``greenrun_piston``: reduced planar
    vs 3-D at the Green Run dwell amplitude, ``greenrun_engine_before`` unreduced; ``records``:
    ``{"file", "sha256"}`` of the test records behind the 3-D model (as given), ``fit_header``:
    the lines the input file's fit wrote at its head; ``nfev`` model evaluations in
    ``wall_s`` [s]; ``status`` the solver's message; ``provenance`` for every output."""

    model: Any
    source: Any
    free: tuple
    start_si: tuple
    values_si: tuple
    lower_si: tuple
    upper_si: tuple
    axes: tuple
    match: MatchTable
    match_before: MatchTable
    greenrun_engine: MatchTable
    greenrun_piston: MatchTable
    greenrun_engine_before: MatchTable
    check: MatchTable
    refine: Mapping[str, Any] = field(default_factory=lambda: types.MappingProxyType({}))
    records: tuple = ()
    fit_header: tuple = ()
    nfev: int = 0
    wall_s: float = 0.0
    status: str = ""
    provenance: Mapping[str, Any] = field(default_factory=lambda: types.MappingProxyType({}))

    @property
    def within_tolerance(self) -> bool:
        """Every fit-grid and check-grid point within :data:`TOLERANCE_DB` and :data:`TOLERANCE_DEG`."""
        return self.match.within() and self.check.within()

    @property
    def worst_text(self) -> str:
        """The worst point of the fit and check grids, in one phrase."""
        m = max((self.match, self.check), key=lambda t: t.worst["tolerance_ratio"])
        return m.worst_text()

    @property
    def at_bound(self) -> tuple:
        """Free keys ending within 0.1 % (in log) of a bound."""
        return tuple(k for k, v, lo, hi in zip(self.free, self.values_si, self.lower_si, self.upper_si)
                     if min(abs(math.log(v / lo)), abs(math.log(hi / v))) < 1e-3)

    def to_dict(self) -> dict:
        return {"free": {k: {"value_si": v, "start_si": s, "ratio": v / s, "lower_si": lo, "upper_si": hi}
                         for k, v, s, lo, hi in zip(self.free, self.values_si, self.start_si, self.lower_si,
                                                    self.upper_si)},
                "at_bound": list(self.at_bound), "axes": list(self.axes),
                "tolerance": {"gain_db": TOLERANCE_DB, "phase_deg": TOLERANCE_DEG},
                "within_tolerance": self.within_tolerance, "match": self.match.to_dict(),
                "match_before": self.match_before.to_dict(), "check": self.check.to_dict(),
                "refine": dict(self.refine),
                "greenrun": {"amplitude_deg": GREENRUN_AMPLITUDE_DEG, "engine": self.greenrun_engine.to_dict(),
                             "piston": self.greenrun_piston.to_dict(),
                             "engine_before": self.greenrun_engine_before.to_dict()},
                "nfev": self.nfev, "wall_s": self.wall_s, "status": self.status,
                "provenance": dict(self.provenance)}

    def summary_lines(self) -> list[str]:
        """The reduction in a few lines (values, fit-grid match before/after, Green Run match)."""
        m, b = self.match, self.match_before
        out = [f"{k} = {v:.6g} SI ({v / s:.3g} x the 3-D model's {s:.6g})"
               for k, v, s in zip(self.free, self.values_si, self.start_si)]
        if self.at_bound:
            out.append("at a bound: " + ", ".join(self.at_bound))
        f, a = np.unique(m.freq_hz), np.unique(m.amplitude_deg)
        out.append(f"engine match over {f.min():g}-{f.max():g} Hz x {a.min():g}-{a.max():g} deg ({m.freq_hz.size} dwells, "
                   f"{'/'.join(self.axes)}): max {m.max_gain_error_db:.3f} dB, {m.max_phase_error_deg:.2f} deg "
                   f"(unreduced planar {b.max_gain_error_db:.3f} dB, {b.max_phase_error_deg:.2f} deg)")
        c = self.check
        f, a = np.unique(c.freq_hz), np.unique(c.amplitude_deg)
        rf = self.refine
        if rf:
            out.append(f"worst point, in units of the tolerance: {rf['least_squares_worst']:.3f} after least squares, "
                       f"{rf['worst']:.3f} after the minimax refinement ({rf['nfev']} planar evaluations, "
                       f"{rf['exchanges']} exchange(s) with the check grid, {rf['points_added']} point(s) added)")
        out.append(f"check over {f.min():g}-{f.max():g} Hz x {a.min():g}-{a.max():g} deg ({c.freq_hz.size} dwells, "
                   f"{'/'.join(dict.fromkeys(c.axis))}): max {c.max_gain_error_db:.3f} dB, {c.max_phase_error_deg:.2f} deg; "
                   f"{'within' if self.within_tolerance else 'NOT within'} {TOLERANCE_DB:g} dB / {TOLERANCE_DEG:g} deg "
                   f"(worst {self.worst_text})")
        g, gp, gb = self.greenrun_engine, self.greenrun_piston, self.greenrun_engine_before
        out.append(f"Green Run dwells {GREENRUN_AMPLITUDE_DEG:g} deg, {g.freq_hz.min():g}-{g.freq_hz.max():g} Hz: engine "
                   f"max {g.max_gain_error_db:.3f} dB, {g.max_phase_error_deg:.2f} deg (unreduced "
                   f"{gb.max_gain_error_db:.3f} dB, {gb.max_phase_error_deg:.2f} deg); piston max "
                   f"{gp.max_gain_error_db:.3f} dB, {gp.max_phase_error_deg:.2f} deg")
        return out

    def write_model(self, path) -> None:
        """Write the reduced planar model file (:func:`taos.identify.reduce_file.write_planar_model`)."""
        from .reduce_file import write_planar_model

        write_planar_model(self, path)


# -- inputs -------------------------------------------------------------------------------------
def _as_taos(source):
    """A TaosModel from a TaosModel, a loaded model (TvcModel) or a model-file path."""
    from taos.taos3d import load_taos_model, taos_model
    from taos.taos3d.model import TaosModel

    if isinstance(source, TaosModel):
        return source
    if hasattr(source, "friction") and hasattr(source, "structure"):
        return taos_model(source)
    return load_taos_model(source)


def key_value(model, key: str) -> float | None:
    """SI value of free key ``key`` in planar model ``model`` (None: the law has no such key)."""
    if key == "structure.load_stiffness":
        return model.structure.load_stiffness_N_per_m
    section, _, k = key.partition(".")
    if section != "friction":
        return None
    for f in dataclasses.fields(model.friction):
        if f.metadata.get("key") == k:
            return float(getattr(model.friction, f.name))
    return None


def check_free(model, free: Sequence[str] | None) -> tuple[tuple, np.ndarray, np.ndarray, np.ndarray]:
    """(keys, start, lower, upper) [SI] of the free keys: each one of :data:`FREE_KEYS`, a
    parameter of the model's law with a positive value (fitted in log), bounded by its factors
    and the loader's bounds (:func:`taos.friction.bounds.loader_bound`). ``None``: :data:`DEFAULT_FREE` keys the law has."""
    from taos.friction.bounds import loader_bound

    src = "argument"
    if free is None:
        free = [k for k in DEFAULT_FREE if key_value(model, k) is not None]
    free = tuple(free)
    if not free or len(set(free)) != len(free):
        raise InputError(src, "free", "one or more distinct keys of " + ", ".join(FREE_KEYS), got=repr(free)[:80])
    start, lo, hi = [], [], []
    for k in free:
        if k not in FREE_KEYS:
            raise InputError(src, "free", "keys of " + ", ".join(FREE_KEYS), got=repr(k)[:60])
        v = key_value(model, k)
        if v is None:
            raise InputError(model.source, k, f"a parameter of the friction law {model.friction.name!r} "
                             "(it has no such key)", got="a key of another law")
        if not (v > 0 and math.isfinite(v)):
            raise InputError(model.source, k, "a positive value in the 3-D model to reduce from", got=f"{v!r}")
        flo, fhi = FREE_KEYS[k]
        a, b = v * flo, v * fhi
        bound = loader_bound(k)   # the model file's and the friction set's bounds (issue 40)
        if bound is not None:
            a, b = max(a, bound[0]), min(b, bound[1])
        start.append(v), lo.append(a), hi.append(b)
    return free, np.array(start), np.array(lo), np.array(hi)


def check_grid(values, name: str, lo: float, hi: float, unit: str) -> np.ndarray:
    """A sorted, distinct, finite grid within [lo, hi] ``unit`` (InputError naming ``name``)."""
    try:
        v = np.unique(np.asarray(values, float).ravel())
    except (TypeError, ValueError):
        raise InputError("argument", name, f"numbers in {unit}", got=repr(values)[:60]) from None
    if v.size == 0 or not np.all(np.isfinite(v)) or v[0] < lo or v[-1] > hi:
        raise InputError("argument", name, f"values from {lo:g} to {hi:g} {unit}", got=repr(values)[:60])
    return v


def _axes(axes) -> tuple:
    axes = (axes,) if isinstance(axes, str) else tuple(axes)
    if not axes or any(a not in ("pitch", "yaw") for a in axes) or len(set(axes)) != len(axes):
        raise InputError("argument", "axes", "'pitch', 'yaw' or both", got=repr(axes)[:40])
    return axes


# -- the reduction ------------------------------------------------------------------------------
def _dwells_3d(tm, axes, f, a_rad) -> dict:
    """axis -> complex (n_amp, n_freq) 3-D engine and piston dwells, every axis in one parallel call."""
    from taos.taos3d.simulate import taos_freqresp_axes

    res = taos_freqresp_axes(tm, {ax: (f, a_rad) for ax in axes})
    return {ax: (np.array([r.engine for r in res[ax]]), np.array([r.piston for r in res[ax]])) for ax in axes}


def _dwells_planar(model, axes, f, a_rad) -> dict:
    from taos.planar.freqresp import sine_dwell_grid

    out = {}
    for ax in axes:
        p, e = sine_dwell_grid(model, a_rad, f, ax)
        out[ax] = (e, p)
    return out


def _table(quantity, axes, f, a_rad, target: dict, planar: dict) -> MatchTable:
    q = 0 if quantity == "engine" else 1
    A, F = np.meshgrid(np.degrees(a_rad), f, indexing="ij")
    n = A.size
    return MatchTable(quantity, tuple(ax for ax in axes for _ in range(n)), np.tile(A.ravel(), len(axes)),
                      np.tile(F.ravel(), len(axes)), np.concatenate([target[ax][q].ravel() for ax in axes]),
                      np.concatenate([planar[ax][q].ravel() for ax in axes]))


_DB = 20.0 / math.log(10.0)


def _grid_points(axes, f, a_rad, target: dict) -> dict:
    """axis -> (amplitudes [rad], frequencies [Hz], 3-D engine responses), paired points of the grid."""
    A, F = (g.ravel() for g in np.meshgrid(a_rad, f, indexing="ij"))
    return {ax: (A, F, target[ax][0].ravel()) for ax in axes}


def _engine_at(model, pts: dict) -> dict:
    """axis -> planar engine responses at the paired points ``pts``."""
    from taos.planar.freqresp import sine_dwell_points

    return {ax: sine_dwell_points(model, a, f, ax).engine for ax, (a, f, _) in pts.items()}


def _residuals(pts: dict, planar: dict) -> np.ndarray:
    """ln(Hp/H3) per point as [gain / TOLERANCE_DB, phase / TOLERANCE_DEG] (engine)."""
    r = np.concatenate([np.log(planar[ax] / t) for ax, (_, _, t) in pts.items()])
    return np.concatenate([r.real * _DB / TOLERANCE_DB, np.degrees(r.imag) / TOLERANCE_DEG])


def _pointwise(r: np.ndarray) -> np.ndarray:
    """Per point max(|gain|, |phase|) in units of the tolerance, from :func:`_residuals`."""
    n = r.size // 2
    return np.maximum(np.abs(r[:n]), np.abs(r[n:]))


def _add_points(fit: dict, check: dict, idx) -> dict:
    """``fit`` with the check points of flat indices ``idx`` (axis-major order) joined."""
    out = {ax: tuple(np.array(v) for v in p) for ax, p in fit.items()}
    offsets, o = {}, 0
    for ax, p in check.items():
        offsets[ax], o = (o, o + p[0].size), o + p[0].size
    for ax, (lo, hi) in offsets.items():
        k = [i - lo for i in idx if lo <= i < hi]
        if not k:
            continue
        new = tuple(v[k] for v in check[ax])
        old = out.get(ax, tuple(np.empty(0, v.dtype) for v in new))
        out[ax] = tuple(np.concatenate([u, v]) for u, v in zip(old, new))
    return out


def _refine(fun_for, fit_pts, check_pts, x, lo, hi, r0, jac0, budget):
    """The minimax refinement with exchanges (module docstring): (x, refine info)."""
    from .minimax import minimax

    x_ls, e_ls = x, _pointwise(fun_for(check_pts)(x))   # the least squares' worst over fit AND check grids
    start = max(float(np.max(_pointwise(r0))), float(np.max(e_ls)))
    nfev, added, exchanges, msg, pts = 0, 0, 0, "", fit_pts
    for exchanges in range(1, MAX_EXCHANGES + 1):
        mm = minimax(fun_for(pts), x, lo, hi, r0=r0, jac0=jac0, step=DIFF_STEP, max_nfev=max(budget - nfev, 2))
        x, nfev, msg = mm.x, nfev + mm.nfev, mm.message
        e = _pointwise(fun_for(check_pts)(x))
        nfev += 1
        worse = np.flatnonzero(e > float(np.max(_pointwise(mm.residuals))) * (1 + 1e-3))
        if worse.size == 0 or exchanges == MAX_EXCHANGES or nfev >= budget:
            break
        idx = worse[np.argsort(e[worse])[::-1][:EXCHANGE_POINTS]]
        pts, added, r0, jac0 = _add_points(pts, check_pts, idx.tolist()), added + idx.size, None, None
    if max(float(np.max(e)), float(np.max(_pointwise(mm.residuals)))) > start:   # never worse than least squares
        x, msg = x_ls, msg + "; worse than the least squares over the fit and check grids: kept the least squares"
    return x, {"method": "minimax (trust-region sequential linear programme) with exchanges against the check grid",
               "nfev": nfev + 1, "exchanges": exchanges, "points_added": added, "least_squares_worst": start,
               "message": msg}


def reduce_to_planar(source: object, *, freq_hz: Sequence[float] = DEFAULT_FREQ_HZ,
                     amplitudes_deg: Sequence[float] = DEFAULT_AMPLITUDES_DEG, axes: Sequence[str] = ("pitch",),
                     free: Sequence[str] | None = None, records: Sequence[str] = (),
                     greenrun_freq_hz: Sequence[float] = GREENRUN_FREQ_HZ, max_nfev: int = 60,
                     check_freq_hz: Sequence[float] = DEFAULT_CHECK_FREQ_HZ,
                     check_amplitudes_deg: Sequence[float] = DEFAULT_CHECK_AMPLITUDES_DEG,
                     refine_nfev: int = REFINE_NFEV) -> ReductionResult:
    """The planar model whose friction reproduces the 3-D model's low-frequency engine response.

    ``source``: a :class:`~taos.taos3d.model.TaosModel`, a loaded model or a model-file path (with
    ``[gimbal]`` and ``[geometry]``); ``freq_hz`` [Hz] x ``amplitudes_deg`` [deg] the fit grid
    (each axis of ``axes``); ``check_freq_hz`` x ``check_amplitudes_deg`` the check grid (both
    axes; default the acceptance grid, 9 x 9); ``free`` the keys reduced (:data:`FREE_KEYS`;
    default :data:`DEFAULT_FREE` those the law has); ``records`` the test-record files behind
    the 3-D model (named, with their SHA-256, in the provenance); ``max_nfev`` the least
    squares' budget of model evaluations, ``refine_nfev`` the worst-point refinement's
    (0: none). Method in the module docstring. Raises :class:`~taos.errors.InputError` for a
    model that is not a 3-D model, a bad grid or free key, a missing record."""
    from taos.results import base_provenance, file_sha256, model_provenance

    from ._args import check_reduce_source
    from .reduce_file import fit_header

    check_reduce_source(source)
    t0 = time.perf_counter()
    axes = _axes(axes)
    f = check_grid(freq_hz, "freq_hz", 1e-3, 50.0, "Hz")
    a_deg = check_grid(amplitudes_deg, "amplitudes_deg", 1e-4, 5.0, "deg")
    fc = check_grid(check_freq_hz, "check_freq_hz", 1e-3, 50.0, "Hz")
    ac_deg = check_grid(check_amplitudes_deg, "check_amplitudes_deg", 1e-4, 5.0, "deg")
    fg = check_grid(greenrun_freq_hz, "greenrun_freq_hz", 1e-2, 50.0, "Hz")
    for name, n in (("freq_hz x amplitudes_deg", f.size * a_deg.size),
                    ("check_freq_hz x check_amplitudes_deg", fc.size * ac_deg.size)):
        if n > MAX_POINTS:
            raise InputError("argument", name, f"at most {MAX_POINTS} dwells per axis", got=f"{n}")
    for name, v, least in (("max_nfev", max_nfev, 1), ("refine_nfev", refine_nfev, 0)):
        if not (isinstance(v, int) and not isinstance(v, bool) and least <= v <= 1000):
            raise InputError("argument", name, f"a whole number from {least} to 1000", got=repr(v))
    recs = []
    for r in records:
        from taos.errors import check_input_file

        check_input_file(r, "a test-record file behind the 3-D model", field="records")
        recs.append({"file": str(r), "sha256": file_sha256(r)})
    tm = _as_taos(source)
    base = tm.base
    if any(k.startswith("code.") for k, _ in base.overrides):
        raise InputError(base.source, "(model)", "a model a file can hold (variants made with with_values)",
                         got="changes made in code (replace)")
    keys, start, lo, hi = check_free(base, free)
    a_rad, ac_rad = np.radians(a_deg), np.radians(ac_deg)
    target = _dwells_3d(tm, axes, f, a_rad)
    fit_pts = _grid_points(axes, f, a_rad, target)

    def variant(x):
        return base.with_values(dict(zip(keys, (float(v) for v in np.exp(x)))))

    def fun_for(pts):
        n = 2 * sum(p[0].size for p in pts.values())

        def fun(x):
            try:
                return _residuals(pts, _engine_at(variant(x), pts))
            except (InputError, SimulationUnstable):   # a trial the loader or the dwell refuses: steer away
                return np.full(n, 1e3)
        return fun

    import scipy.optimize as so

    x0, xl, xh = np.log(start), np.log(lo), np.log(hi)
    before = _dwells_planar(base, axes, f, a_rad)
    sol = so.least_squares(fun_for(fit_pts), np.clip(x0, xl, xh), bounds=(xl, xh), diff_step=DIFF_STEP, x_scale=1.0,
                           xtol=1e-4, ftol=1e-6, max_nfev=max_nfev)
    target_c = _dwells_3d(tm, CHECK_AXES, fc, ac_rad)
    check_pts = _grid_points(CHECK_AXES, fc, ac_rad, target_c)
    x, refine = sol.x, {}
    if refine_nfev:
        x, refine = _refine(fun_for, fit_pts, check_pts, sol.x, xl, xh, sol.fun, sol.jac, refine_nfev)
    reduced = variant(x)
    after = _dwells_planar(reduced, axes, f, a_rad)
    after_c = _dwells_planar(reduced, CHECK_AXES, fc, ac_rad)
    ga = np.radians([GREENRUN_AMPLITUDE_DEG])
    g3 = _dwells_3d(tm, axes, fg, ga)
    gr, gb = _dwells_planar(reduced, axes, fg, ga), _dwells_planar(base, axes, fg, ga)
    prov = dict(base_provenance())
    prov.update({f"source_{k}": v for k, v in model_provenance(base).items()})
    prov["source_model_inputs"] = {r: {"file": p, "sha256": h} for r, (p, h) in base.input_files.items()}
    prov["source_engine"] = "taos (3-D two-half FEM gimbal, vector friction)"
    prov["source_stiffness"] = tm.stiffness_source
    prov["records"] = recs
    header = fit_header(base.source)
    prov["source_fit_header"] = list(header)
    prov["settings"] = {"freq_hz": f.tolist(), "amplitudes_deg": a_deg.tolist(), "axes": list(axes),
                        "free": list(keys), "greenrun_freq_hz": fg.tolist(),
                        "greenrun_amplitude_deg": GREENRUN_AMPLITUDE_DEG, "max_nfev": max_nfev,
                        "check_freq_hz": fc.tolist(), "check_amplitudes_deg": ac_deg.tolist(),
                        "check_axes": list(CHECK_AXES), "refine_nfev": refine_nfev}
    match, check = _table("engine", axes, f, a_rad, target, after), _table("engine", CHECK_AXES, fc, ac_rad, target_c,
                                                                           after_c)
    if refine:
        refine["worst"] = max(match.worst["tolerance_ratio"], check.worst["tolerance_ratio"])
    return ReductionResult(
        model=reduced, source=base, free=keys, start_si=tuple(map(float, start)),
        values_si=tuple(float(v) for v in np.exp(x)), lower_si=tuple(map(float, lo)),
        upper_si=tuple(map(float, hi)), axes=axes,
        match=match, match_before=_table("engine", axes, f, a_rad, target,
                                                                                    before),
        greenrun_engine=_table("engine", axes, fg, ga, g3, gr), greenrun_piston=_table("piston", axes, fg, ga, g3, gr),
        greenrun_engine_before=_table("engine", axes, fg, ga, g3, gb),
        check=check,
        refine=types.MappingProxyType(refine), records=tuple(recs), fit_header=header,
        nfev=int(sol.nfev) + int(refine.get("nfev", 0)), wall_s=time.perf_counter() - t0, status=str(sol.message),
        provenance=types.MappingProxyType(prov))


def match_table(source, planar_model, freq_hz: Sequence[float], amplitudes_deg: Sequence[float],
                axes=("pitch",)) -> MatchTable:
    """Engine dwells of ``planar_model`` against the 3-D model ``source`` (as
    :func:`reduce_to_planar` takes it) on ``freq_hz`` [Hz] x ``amplitudes_deg`` [deg] of each
    axis: the check of a reduction on any grid (e.g. the acceptance grid 0.1-2 Hz x 0.02-0.5 deg)."""
    axes = _axes(axes)
    f = check_grid(freq_hz, "freq_hz", 1e-3, 50.0, "Hz")
    a_rad = np.radians(check_grid(amplitudes_deg, "amplitudes_deg", 1e-4, 5.0, "deg"))
    tm = _as_taos(source)
    return _table("engine", axes, f, a_rad, _dwells_3d(tm, axes, f, a_rad), _dwells_planar(planar_model, axes, f, a_rad))
