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
  counted in units of the acceptance tolerance (0.5 dB, 5 deg).

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

    def to_dict(self) -> dict:
        g = lambda h: 20.0 * np.log10(np.abs(h))
        p = lambda h: np.degrees(np.angle(h))
        return {"quantity": self.quantity, "max_gain_error_db": self.max_gain_error_db,
                "max_phase_error_deg": self.max_phase_error_deg,
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
    same for the unreduced planar model; ``greenrun_engine``/``greenrun_piston``: reduced planar
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
    records: tuple = ()
    fit_header: tuple = ()
    nfev: int = 0
    wall_s: float = 0.0
    status: str = ""
    provenance: Mapping[str, Any] = field(default_factory=lambda: types.MappingProxyType({}))

    @property
    def within_tolerance(self) -> bool:
        """Every fit-grid point within :data:`TOLERANCE_DB` and :data:`TOLERANCE_DEG`."""
        return self.match.within()

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
                "match_before": self.match_before.to_dict(),
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
                   f"(unreduced planar {b.max_gain_error_db:.3f} dB, {b.max_phase_error_deg:.2f} deg); "
                   f"{'within' if self.within_tolerance else 'NOT within'} {TOLERANCE_DB:g} dB / {TOLERANCE_DEG:g} deg")
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
    and :data:`taos.bounds.MODEL_BOUNDS`. ``None``: :data:`DEFAULT_FREE` keys the law has."""
    from taos.bounds import MODEL_BOUNDS

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
        if k in MODEL_BOUNDS:
            a, b = max(a, MODEL_BOUNDS[k][0]), min(b, MODEL_BOUNDS[k][1])
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


def _residuals(target: dict, planar: dict, axes) -> np.ndarray:
    """ln(Hp/H3) per point as [gain / TOLERANCE_DB, phase / TOLERANCE_DEG] (engine)."""
    r = np.concatenate([np.log(planar[ax][0].ravel() / target[ax][0].ravel()) for ax in axes])
    return np.concatenate([r.real * (20.0 / math.log(10.0)) / TOLERANCE_DB, np.degrees(r.imag) / TOLERANCE_DEG])


def reduce_to_planar(source, *, freq_hz: Sequence[float] = DEFAULT_FREQ_HZ,
                     amplitudes_deg: Sequence[float] = DEFAULT_AMPLITUDES_DEG, axes=("pitch",),
                     free: Sequence[str] | None = None, records: Sequence[str] = (),
                     greenrun_freq_hz: Sequence[float] = GREENRUN_FREQ_HZ, max_nfev: int = 60) -> ReductionResult:
    """The planar model whose friction reproduces the 3-D model's low-frequency engine response.

    ``source``: a :class:`~taos.taos3d.model.TaosModel`, a loaded model or a model-file path (with
    ``[gimbal]`` and ``[geometry]``); ``freq_hz`` [Hz] x ``amplitudes_deg`` [deg] the fit grid
    (each axis of ``axes``); ``free`` the keys reduced (:data:`FREE_KEYS`; default
    :data:`DEFAULT_FREE` those the law has); ``records`` the test-record files behind the 3-D
    model (named, with their SHA-256, in the provenance); ``max_nfev`` the solver's budget of
    model evaluations. Method in the module docstring. Raises
    :class:`~taos.errors.InputError` for a model that is not a 3-D model, a bad grid or free
    key, a missing record."""
    from taos.results import base_provenance, file_sha256, model_provenance

    from .reduce_file import fit_header

    t0 = time.perf_counter()
    axes = _axes(axes)
    f = check_grid(freq_hz, "freq_hz", 1e-3, 50.0, "Hz")
    a_deg = check_grid(amplitudes_deg, "amplitudes_deg", 1e-4, 5.0, "deg")
    fg = check_grid(greenrun_freq_hz, "greenrun_freq_hz", 1e-2, 50.0, "Hz")
    if f.size * a_deg.size > MAX_POINTS:
        raise InputError("argument", "freq_hz x amplitudes_deg", f"at most {MAX_POINTS} dwells per axis",
                         got=f"{f.size} x {a_deg.size}")
    if not (isinstance(max_nfev, int) and 1 <= max_nfev <= 1000):
        raise InputError("argument", "max_nfev", "a whole number from 1 to 1000", got=repr(max_nfev))
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
    a_rad = np.radians(a_deg)
    target = _dwells_3d(tm, axes, f, a_rad)

    def variant(x):
        return base.with_values(dict(zip(keys, (float(v) for v in np.exp(x)))))

    def fun(x):
        try:
            return _residuals(target, _dwells_planar(variant(x), axes, f, a_rad), axes)
        except (InputError, SimulationUnstable):   # a trial the loader or the dwell refuses: steer away
            return np.full(2 * f.size * a_deg.size * len(axes), 1e3)

    import scipy.optimize as so

    x0, xl, xh = np.log(start), np.log(lo), np.log(hi)
    before = _dwells_planar(base, axes, f, a_rad)
    sol = so.least_squares(fun, np.clip(x0, xl, xh), bounds=(xl, xh), diff_step=DIFF_STEP, x_scale=1.0,
                           xtol=1e-4, ftol=1e-6, max_nfev=max_nfev)
    reduced = variant(sol.x)
    after = _dwells_planar(reduced, axes, f, a_rad)
    g3 = _dwells_3d(tm, axes, fg, np.radians([GREENRUN_AMPLITUDE_DEG]))
    gr, gb = _dwells_planar(reduced, axes, fg, np.radians([GREENRUN_AMPLITUDE_DEG])), \
        _dwells_planar(base, axes, fg, np.radians([GREENRUN_AMPLITUDE_DEG]))
    ga = np.radians([GREENRUN_AMPLITUDE_DEG])
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
                        "greenrun_amplitude_deg": GREENRUN_AMPLITUDE_DEG, "max_nfev": max_nfev}
    return ReductionResult(
        model=reduced, source=base, free=keys, start_si=tuple(map(float, start)),
        values_si=tuple(float(v) for v in np.exp(sol.x)), lower_si=tuple(map(float, lo)),
        upper_si=tuple(map(float, hi)), axes=axes,
        match=_table("engine", axes, f, a_rad, target, after), match_before=_table("engine", axes, f, a_rad, target,
                                                                                    before),
        greenrun_engine=_table("engine", axes, fg, ga, g3, gr), greenrun_piston=_table("piston", axes, fg, ga, g3, gr),
        greenrun_engine_before=_table("engine", axes, fg, ga, g3, gb), records=tuple(recs), fit_header=header,
        nfev=int(sol.nfev), wall_s=time.perf_counter() - t0, status=str(sol.message),
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
