"""Ascent flight definition: a time-varying vehicle, boosters, winds and programmed test inputs.

The seed paper's figures 7-9 come from a 6-DOF simulation of the whole ascent: the core stage
shares control with the boosters until separation near 125 s, then flies on TVC alone;
programmed test inputs (PTIs: multisines and sweeps) are injected at scheduled times. This module
holds the definition of such a flight (file ``models/flight/ascent.toml``, loaded by
:func:`load_ascent`); :mod:`taos.flight.ascent_sim` flies it.

Model, per axis (pitch, yaw; planar, small angles, as :mod:`taos.flight.vehicle`)::

    I_v(t) theta'' = n_e T_e(t) l_c(t) delta + n_e K_twd delta''           core TVC (+ tail wags dog)
                   + n_b T_b(t) l_b delta_b + I_v M_a(t) (theta + alpha_w(t))
    tau_b delta_b' = delta_c - delta_b                                       booster TVC (first order)
    M_a(t) = q(t) S C_Na x_cp / I_v(t)                                       aerodynamic instability
    alpha_w(t) = w_axis(t) / V(t)                                            wind angle of attack

with the gimbal arm l_c, thrusts T_e, T_b, inertia I_v, dynamic pressure q and speed V
interpolated linearly in the ``[trajectory]`` table, booster thrust zero after separation. The
flight-control system is the one of the ``flight`` file (:class:`~taos.flight.vehicle.FlightControl`),
its gains scheduled on control effectiveness: every gain is multiplied by a_ref / a(t), with
a(t) = (n_e T_e l_c + n_b T_b l_b) / I_v the total control acceleration per radian and a_ref the
flight file's own (core stage at separation), so the rigid-body loop keeps its shape along the
trajectory (Greensite, *Analysis and Design of Space Vehicle Flight Control Systems*, 1970,
ch. 1 and 6). Before separation the core TVC carries only the share n_e T_e l_c / (I_v a) of the
loop, which is why a friction-degraded core TVC does not limit-cycle there.

Wind along the flight path: a steady profile (table), a 1-cosine gust, and first-order
(Dryden-like) turbulence of a given RMS and correlation time drawn from a seeded generator; the
pitch plane sees cos(azimuth) of it, the yaw plane sin(azimuth).

Any launcher: the engine count, thrust, inertia and gains come from the files only. A stage
without boosters leaves out ``[boosters]`` (and the ``booster_thrust`` column), an
exo-atmospheric one ``[aero]``, ``[wind]`` and the ``dynamic_pressure`` / ``wind_speed`` columns
(all zero). Every key, unit and frame: ``docs/reference/flight_files.md``; a template:
``taos ascent --template OUT.toml`` (the shipped non-SLS example
``models/flight/generic_upper_ascent.toml``).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from taos.errors import InputError
from taos.flight.vehicle import FlightModel, load_flight
from taos.model import read_toml
from taos.profiles import Multisine, SineSweep
from taos.shipped import resolve, resolve_reference
from taos.units import to_si

#: trajectory column -> (unit kind for to_si-style checks, SI unit)
TRAJECTORY_COLUMNS = {
    "time": "s", "mass": "kg", "inertia": "kg*m**2", "gimbal_arm": "m", "core_thrust_per_engine": "N",
    "booster_thrust": "N", "dynamic_pressure": "Pa", "velocity": "m/s", "wind_speed": "m/s",
}
PTI_KINDS = ("multisine", "sweep")
MAX_TABLE_ROWS = 10_000
MAX_DURATION_S = 2_000.0


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Vehicle properties along the ascent (SI arrays on the increasing ``time_s`` grid)."""

    time_s: np.ndarray
    mass_kg: np.ndarray
    inertia_kgm2: np.ndarray
    gimbal_arm_m: np.ndarray
    core_thrust_per_engine_N: np.ndarray
    booster_thrust_N: np.ndarray
    dynamic_pressure_Pa: np.ndarray
    velocity_m_s: np.ndarray
    wind_speed_m_s: np.ndarray

    def at(self, name: str, t_s):
        """Column ``name`` (a field of this class) interpolated linearly at ``t_s`` [s]."""
        return np.interp(t_s, self.time_s, getattr(self, name))


@dataclass(frozen=True)
class Boosters:
    """Boosters: count n_b, separation time [s], c.g. to nozzle-plane arm l_b [m], first-order
    TVC time constant tau_b [s], attitude-rate kick at separation [rad/s]."""

    count: int
    separation_time_s: float
    gimbal_arm_m: float
    actuator_time_constant_s: float
    separation_rate_kick_rad_s: float


@dataclass(frozen=True)
class Aero:
    """Reference area S [m^2], normal-force slope C_N_alpha [1/rad], centre of pressure ahead of
    the c.g. x_cp [m]."""

    reference_area_m2: float
    normal_force_slope_per_rad: float
    center_of_pressure_ahead_m: float


@dataclass(frozen=True)
class Wind:
    """Wind direction from the pitch plane [rad], 1-cosine gust (time, amplitude [m/s],
    duration [s]), turbulence RMS [m/s] and correlation time [s]; ``scale`` multiplies all of it
    (dispersions)."""

    azimuth_rad: float
    gust_time_s: float
    gust_amplitude_m_s: float
    gust_duration_s: float
    turbulence_intensity_m_s: float
    turbulence_time_constant_s: float
    scale: float = 1.0


@dataclass(frozen=True)
class Pti:
    """One programmed test input window: start [s], kind (multisine or sweep), duration [s], peak
    amplitude [rad], band [Hz], axes it drives."""

    start_s: float
    kind: str
    duration_s: float
    amplitude_rad: float
    low_frequency_hz: float
    high_frequency_hz: float
    axes: tuple[str, ...]

    def signal(self):
        """The command shape (a :mod:`taos.profiles` profile, time from the window start)."""
        if self.kind == "sweep":
            return SineSweep(self.amplitude_rad, self.low_frequency_hz, self.high_frequency_hz, self.duration_s)
        n = max(2, int(round(4 * math.log2(self.high_frequency_hz / self.low_frequency_hz))) + 1)
        freqs = tuple(float(f) for f in np.geomspace(self.low_frequency_hz, self.high_frequency_hz, n))
        return Multisine(self.amplitude_rad, freqs, self.duration_s)

    @property
    def end_s(self) -> float:
        return self.start_s + self.duration_s


@dataclass(frozen=True)
class Ascent:
    """A whole ascent: trajectory, boosters, aerodynamics, wind, PTIs, the flight file (FCS and
    reference vehicle) and the TVC model file it pairs with."""

    name: str
    trajectory: Trajectory
    boosters: Boosters
    aero: Aero
    wind: Wind
    ptis: tuple[Pti, ...]
    flight: FlightModel
    update_interval_s: float
    tvc_model: str = ""
    source: str = "<code>"
    sha256: str = ""

    @property
    def end_time_s(self) -> float:
        return float(self.trajectory.time_s[-1])

    def pti_windows(self, axis: str) -> list[tuple[float, float]]:
        """(start, end) [s] of the PTI windows on ``axis``."""
        return [(p.start_s, p.end_s) for p in self.ptis if axis in p.axes]


# -- loading ---------------------------------------------------------------------------------
def _table(doc: Mapping, name: str, src: str) -> Mapping:
    t = doc.get(name)
    if not isinstance(t, Mapping):
        raise InputError(src, f"[{name}]", f"a [{name}] table", got="nothing (section missing)")
    return t


def _keys(t: Mapping, allowed, src: str, section: str) -> None:
    import difflib
    for k in t:
        if k not in allowed:
            near = difflib.get_close_matches(k, list(allowed), n=1)
            hint = f" (did you mean '{near[0]}'?)" if near else ""
            raise InputError(src, f"{section}.{k}", "one of " + ", ".join(sorted(allowed)) + hint,
                             got="an unknown key")


def _need(t: Mapping, key: str, kind: str, src: str, section: str, **checks) -> float:
    if key not in t:
        raise InputError(src, f"{section}.{key}", f"a {kind.replace('_', ' ')} with its unit", got="nothing (key missing)")
    return to_si(t[key], kind, source=src, field=f"{section}.{key}", **checks)


def _column(t: Mapping, key: str, si_unit: str, src: str) -> np.ndarray:
    fld = f"trajectory.{key}"
    col = t.get(key)
    if not isinstance(col, Mapping) or set(col) != {"unit", "values"}:
        raise InputError(src, fld, "a table { unit = \"...\", values = [numbers] }", got=repr(col)[:80])
    vals = col["values"]
    if (not isinstance(vals, list) or not vals or len(vals) > MAX_TABLE_ROWS
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals)):
        raise InputError(src, f"{fld}.values", f"a list of 1 to {MAX_TABLE_ROWS} numbers", got=repr(vals)[:80])
    from taos.units import Q_, check_unit_text

    check_unit_text(col["unit"], src, f"{fld}.unit", f"a unit convertible to {si_unit}")
    try:
        factor = Q_(1.0, str(col["unit"])).to(si_unit).magnitude
    except Exception:
        raise InputError(src, f"{fld}.unit", f"a unit convertible to {si_unit}", got=repr(col["unit"])) from None
    out = np.asarray(vals, float) * factor
    if not np.all(np.isfinite(out)) or np.any(out < 0):
        raise InputError(src, f"{fld}.values", "finite non-negative numbers", got=repr(vals)[:80])
    return out


def _trajectory(doc: Mapping, src: str) -> Trajectory:
    t = _table(doc, "trajectory", src)
    _keys(t, TRAJECTORY_COLUMNS, src, "trajectory")
    cols = {k: _column(t, k, u, src) for k, u in TRAJECTORY_COLUMNS.items() if k in t or k not in OPTIONAL_COLUMNS}
    n = cols["time"].size
    for k in OPTIONAL_COLUMNS:
        cols.setdefault(k, np.zeros(n))
    for k, v in cols.items():
        if v.size != n:
            raise InputError(src, f"trajectory.{k}.values", f"{n} values (as many as trajectory.time)", got=str(v.size))
    if n < 2 or np.any(np.diff(cols["time"]) <= 0) or cols["time"][0] != 0.0:
        raise InputError(src, "trajectory.time.values", "strictly increasing times starting at 0")
    if cols["time"][-1] > MAX_DURATION_S:
        raise InputError(src, "trajectory.time.values", f"an ascent of at most {MAX_DURATION_S:g} s",
                         got=f"{cols['time'][-1]:g} s")
    for k in ("mass", "inertia", "gimbal_arm", "velocity"):
        if np.any(cols[k] <= 0):
            raise InputError(src, f"trajectory.{k}.values", "positive values")
    return Trajectory(time_s=cols["time"], mass_kg=cols["mass"], inertia_kgm2=cols["inertia"],
                      gimbal_arm_m=cols["gimbal_arm"], core_thrust_per_engine_N=cols["core_thrust_per_engine"],
                      booster_thrust_N=cols["booster_thrust"], dynamic_pressure_Pa=cols["dynamic_pressure"],
                      velocity_m_s=cols["velocity"], wind_speed_m_s=cols["wind_speed"])


#: an ascent without a ``[boosters]`` table: no boosters, no separation (the TVC engines alone
#: from the start; the trajectory's ``booster_thrust`` column may then be left out)
NO_BOOSTERS = Boosters(count=0, separation_time_s=0.0, gimbal_arm_m=1.0, actuator_time_constant_s=0.1,
                       separation_rate_kick_rad_s=0.0)
#: an ascent without an ``[aero]`` table: no aerodynamic moment (exo-atmospheric)
NO_AERO = Aero(reference_area_m2=0.0, normal_force_slope_per_rad=0.0, center_of_pressure_ahead_m=0.0)
#: an ascent without a ``[wind]`` table: no gust, no turbulence (a ``wind_speed`` column still applies)
NO_WIND = Wind(azimuth_rad=0.0, gust_time_s=0.0, gust_amplitude_m_s=0.0, gust_duration_s=1.0,
               turbulence_intensity_m_s=0.0, turbulence_time_constant_s=1.0)
#: trajectory columns an ascent may leave out, with their value (zero along the whole ascent)
OPTIONAL_COLUMNS = ("booster_thrust", "dynamic_pressure", "wind_speed")


def _boosters(doc: Mapping, src: str) -> Boosters:
    if "boosters" not in doc:
        return NO_BOOSTERS
    b = _table(doc, "boosters", src)
    _keys(b, {"count", "separation_time", "gimbal_arm", "actuator_time_constant", "separation_rate_kick"},
          src, "boosters")
    n = b.get("count")
    if not isinstance(n, int) or isinstance(n, bool) or not 0 <= n <= 16:
        raise InputError(src, "boosters.count", "a whole number from 0 to 16", got=repr(n))
    return Boosters(count=n,
                    separation_time_s=_need(b, "separation_time", "time", src, "boosters", nonnegative=True),
                    gimbal_arm_m=_need(b, "gimbal_arm", "length", src, "boosters", positive=True),
                    actuator_time_constant_s=_need(b, "actuator_time_constant", "time", src, "boosters", positive=True),
                    separation_rate_kick_rad_s=_need(b, "separation_rate_kick", "angular_velocity", src, "boosters"))


def _aero(doc: Mapping, src: str) -> Aero:
    from taos.units import Q_

    if "aero" not in doc:
        return NO_AERO
    a = _table(doc, "aero", src)
    _keys(a, {"reference_area", "normal_force_slope", "center_of_pressure_ahead"}, src, "aero")
    slope = a.get("normal_force_slope")
    if isinstance(slope, str):
        from taos.units import check_value_text
        check_value_text(slope, src, "aero.normal_force_slope", "a non-negative slope with its unit, like '4 1/rad'")
    try:
        s = float(Q_(slope).to("1/rad").magnitude) if isinstance(slope, str) else None
    except Exception:
        s = None
    if s is None or not math.isfinite(s) or s < 0:
        raise InputError(src, "aero.normal_force_slope", "a non-negative slope with its unit, like '4 1/rad'",
                         got=repr(slope))
    return Aero(reference_area_m2=_need(a, "reference_area", "area", src, "aero", nonnegative=True),
                normal_force_slope_per_rad=s,
                center_of_pressure_ahead_m=_need(a, "center_of_pressure_ahead", "length", src, "aero"))


def _wind(doc: Mapping, src: str) -> Wind:
    if "wind" not in doc:
        return NO_WIND
    w = _table(doc, "wind", src)
    keys = {"azimuth": ("angle", {}), "gust_time": ("time", {"nonnegative": True}),
            "gust_amplitude": ("velocity", {}), "gust_duration": ("time", {"positive": True}),
            "turbulence_intensity": ("velocity", {"nonnegative": True}),
            "turbulence_time_constant": ("time", {"positive": True})}
    _keys(w, keys, src, "wind")
    v = {k: _need(w, k, kind, src, "wind", **chk) for k, (kind, chk) in keys.items()}
    return Wind(azimuth_rad=v["azimuth"], gust_time_s=v["gust_time"], gust_amplitude_m_s=v["gust_amplitude"],
                gust_duration_s=v["gust_duration"], turbulence_intensity_m_s=v["turbulence_intensity"],
                turbulence_time_constant_s=v["turbulence_time_constant"])


def _ptis(doc: Mapping, src: str) -> tuple[Pti, ...]:
    items = doc.get("pti", [])
    if not isinstance(items, list) or len(items) > 100:
        raise InputError(src, "pti", "a list of at most 100 [[pti]] tables", got=repr(items)[:60])
    out = []
    for i, p in enumerate(items):
        sec = f"pti[{i}]"
        if not isinstance(p, Mapping):
            raise InputError(src, sec, "a [[pti]] table", got=repr(p)[:60])
        _keys(p, {"start", "kind", "duration", "amplitude", "low_frequency", "high_frequency", "axis"}, src, sec)
        kind = p.get("kind")
        if kind not in PTI_KINDS:
            raise InputError(src, f"{sec}.kind", "'multisine' or 'sweep'", got=repr(kind))
        axis = p.get("axis", "both")
        if axis not in ("pitch", "yaw", "both"):
            raise InputError(src, f"{sec}.axis", "'pitch', 'yaw' or 'both'", got=repr(axis))
        lo = _need(p, "low_frequency", "frequency", src, sec, positive=True)
        hi = _need(p, "high_frequency", "frequency", src, sec, positive=True)
        if not lo < hi <= 50.0:
            raise InputError(src, f"{sec}.high_frequency", f"a frequency above low_frequency ({lo:g} Hz), at most 50 Hz",
                             got=repr(p.get("high_frequency")))
        amp = _need(p, "amplitude", "angle", src, sec, positive=True)
        if amp > math.radians(5.0):
            raise InputError(src, f"{sec}.amplitude", "a PTI amplitude of at most 5 deg", got=repr(p.get("amplitude")))
        out.append(Pti(start_s=_need(p, "start", "time", src, sec, nonnegative=True), kind=kind,
                       duration_s=_need(p, "duration", "time", src, sec, positive=True), amplitude_rad=amp,
                       low_frequency_hz=lo, high_frequency_hz=hi,
                       axes=("pitch", "yaw") if axis == "both" else (axis,)))
        from taos.bounds import check_pti_bounds
        check_pti_bounds(out[-1], src, sec)
    return tuple(sorted(out, key=lambda q: q.start_s))


def load_ascent(path: str | Path) -> Ascent:
    """Load an ascent file (``models/flight/ascent.toml``, or a shipped name like ``ascent``).

    Raises :class:`~taos.errors.InputError` (one line: file, field, expectation) on bad input."""
    p = resolve(path, "flight")
    src = str(p)
    raw, doc = read_toml(p, "a readable ascent file")
    _keys(doc, {"name", "description", "flight", "tvc_model", "update_interval", "trajectory", "boosters",
                "aero", "wind", "pti"}, src, "(top level)")
    fl = doc.get("flight")
    if not isinstance(fl, str) or not fl:
        raise InputError(src, "flight", "the flight file (FCS) this ascent uses, a path", got=repr(fl))
    flight = load_flight(resolve_reference(fl, p, field="flight", kind="flight", what="a flight file"))
    tvc = doc.get("tvc_model", "")
    if not isinstance(tvc, str):
        raise InputError(src, "tvc_model", "a path string", got=repr(tvc))
    if tvc:
        tvc = str(resolve_reference(tvc, p, field="tvc_model", kind="flight", what="a TVC model file"))
    dt_up = to_si(doc.get("update_interval", "1 s"), "time", source=src, field="update_interval", positive=True)
    if not 0.01 <= dt_up <= 10.0:
        raise InputError(src, "update_interval", "an interval from 0.01 s to 10 s", got=repr(doc.get("update_interval")))
    from taos.bounds import check_ascent_bounds
    a = Ascent(name=str(doc.get("name", p.stem)), trajectory=_trajectory(doc, src), boosters=_boosters(doc, src),
               aero=_aero(doc, src), wind=_wind(doc, src), ptis=_ptis(doc, src), flight=flight,
               update_interval_s=dt_up, tvc_model=tvc, source=src, sha256=hashlib.sha256(raw).hexdigest())
    check_ascent_bounds(a)   # the documented bounds (docs/reference/bounds.md), before any work
    return a


# -- derived quantities ----------------------------------------------------------------------
def control_acceleration(ascent: Ascent, t_s) -> tuple[np.ndarray, np.ndarray]:
    """(core, booster) control acceleration per radian of deflection [1/s^2] at ``t_s``:
    n_e T_e l_c / I_v and n_b T_b l_b / I_v (booster part zero after separation)."""
    tr, b = ascent.trajectory, ascent.boosters
    t = np.asarray(t_s, float)
    inertia = tr.at("inertia_kgm2", t)
    core = ascent.flight.vehicle.engine_count * tr.at("core_thrust_per_engine_N", t) * tr.at("gimbal_arm_m", t) / inertia
    boost = np.where(t < b.separation_time_s, b.count * tr.at("booster_thrust_N", t) * b.gimbal_arm_m / inertia, 0.0)
    return core, boost


def aero_instability(ascent: Ascent, t_s) -> np.ndarray:
    """M_a = q S C_N_alpha x_cp / I_v [1/s^2] at ``t_s``."""
    tr, a = ascent.trajectory, ascent.aero
    return (tr.at("dynamic_pressure_Pa", t_s) * a.reference_area_m2 * a.normal_force_slope_per_rad
            * a.center_of_pressure_ahead_m / tr.at("inertia_kgm2", t_s))


def wind_speed(ascent: Ascent, t_s: np.ndarray, rng: np.random.Generator, dt_s: float) -> np.ndarray:
    """Wind along the flight path [m/s] on the uniform grid ``t_s`` (step ``dt_s``): steady
    profile + 1-cosine gust + first-order turbulence w' = (-w + sigma sqrt(2 tau) xi) / tau
    (stationary RMS sigma), all times ``scale``. The turbulence is drawn on a coarse grid of
    tau / 20 and interpolated, so it does not depend on ``dt_s``."""
    w = ascent.wind
    t = np.asarray(t_s, float)
    steady = ascent.trajectory.at("wind_speed_m_s", t)
    g = (t - w.gust_time_s) / w.gust_duration_s
    gust = np.where((g >= 0) & (g <= 1), 0.5 * w.gust_amplitude_m_s * (1 - np.cos(2 * np.pi * g)), 0.0)
    h = w.turbulence_time_constant_s / 20.0
    tc = np.arange(t[0], t[-1] + 2 * h, h)
    phi = math.exp(-h / w.turbulence_time_constant_s)
    xi = rng.standard_normal(tc.size)
    turb = np.empty(tc.size)
    turb[0] = w.turbulence_intensity_m_s * xi[0]
    s = w.turbulence_intensity_m_s * math.sqrt(1 - phi * phi)
    if tc.size > 1:  # exact discretisation of the first-order (Ornstein-Uhlenbeck) process,
        # turb[k] = phi turb[k-1] + s xi[k] (taos.flight._turbulence)
        from taos.flight._turbulence import ou_recursion
        ou_recursion(turb, float(phi), float(s), xi)
    return w.scale * (steady + gust + np.interp(t, tc, turb))


def pti_command(ascent: Ascent, axis: str, t_s) -> np.ndarray:
    """Sum of the PTI windows on ``axis`` at ``t_s`` [rad]."""
    t = np.asarray(t_s, float)
    out = np.zeros_like(t)
    for p in ascent.ptis:
        if axis in p.axes:
            sel = (t >= p.start_s) & (t <= p.end_s)
            out[sel] += p.signal()(t[sel] - p.start_s)
    return out
