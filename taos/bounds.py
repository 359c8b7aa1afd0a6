"""Documented limits of the inputs and of the physical envelope, checked before work starts.

Every check raises :class:`~taos.errors.InputError` (exit 2: one line naming the value and the
limit) or, for a model that is unstable or a run that leaves its envelope,
:class:`~taos.errors.UnstableModel` / :class:`~taos.errors.EnvelopeExceeded` (exit 3).

The physical bounds of every model, flight, campaign, ascent and profile-file value, each with
its reason, are the tables :data:`MODEL_BOUNDS`, :data:`FLIGHT_BOUNDS`, :data:`CAMPAIGN_BOUNDS`,
:data:`ASCENT_BOUNDS` and :data:`PROFILE_BOUNDS` (checked when a file is loaded, with the
cross-field checks of :func:`check_model_bounds`, :func:`check_campaign_bounds` and
:func:`check_ascent_bounds`); the Python API's grids and axes are checked by
:func:`check_response_args`. All are listed in docs/reference/bounds.md.

Limits of a run (SI inside; shown here in the units of the messages):

=============================  ==================================  ==========================================
quantity                       limit                               why
=============================  ==================================  ==========================================
engine-angle command           abs(theta_c) <= 10.5 deg             RS-25 gimbal range (DESIGN.md, public)
engine angle in a run          abs(theta) <= 12.6 deg               notional hard stops, 1.2 x the gimbal range
load force in a run            abs(F_L) <= 3 x A P_s                pressure far beyond supply: the linear
                                                                   actuator has no pressure saturation, and
                                                                   the Green Run profile's 14 Hz dwells reach
                                                                   1.6 A P_s in the shipped models, so the
                                                                   envelope is set at 3 x the stall force
command frequency              1e-3 Hz .. 1e3 Hz                    test and flight content is 0.1-30 Hz
frequency-response frequency   1e-4 Hz .. 1e4 Hz                    beyond, the linear block is flat/zero
integration step dt            dt |lambda|_max <= 2.0               RK4 stability boundary on the imaginary
                                                                   axis is 2.83; the fastest linear mode
                                                                   lambda_max of the model
steps per command cycle        f_max dt <= 1/20                     20 steps per cycle (10 x Nyquist)
simulated duration             <= 1e4 s                             about 3 h of test
integration steps of one job   <= 2e8                               minutes of compute, not days
memory of one job              <= 4 GiB (estimated before work)     the 24 GiB machine, shared
profile cycle count            <= 1e6                               a whole-number count
data file samples              <= 5e7, resampled <= 4 x the file   one mistyped time stamp cannot ask for
                                                                   petabytes
H1 segment length (nperseg)    8 .. number of samples
number of fit starts           1 .. 64
=============================  ==================================  ==========================================
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import numpy as np

from .errors import InputError

DEG = math.pi / 180.0
GIMBAL_RANGE_RAD = 10.5 * DEG
HARD_STOP_RAD = 1.2 * GIMBAL_RANGE_RAD
LOAD_FORCE_FACTOR = 3.0
COMMAND_FREQ_HZ = (1e-3, 1e3)
RESPONSE_FREQ_HZ = (1e-4, 1e4)
RK4_STEP_LIMIT = 2.0
MIN_STEPS_PER_CYCLE = 20
MAX_DURATION_S = 1e4
MAX_STEPS = 2e8
MAX_JOB_BYTES = 4 * 2 ** 30
MAX_CYCLES = 10 ** 6
MAX_DATA_SAMPLES = 5 * 10 ** 7
MAX_RESAMPLE_FACTOR = 4.0
NPERSEG_MIN = 8
MAX_STARTS = 64
MAX_VIEW_SCALE = 1e4   # the largest exaggeration [-] of a drawn angle or deflection (taos.viewer)
MAX_VIEW_FPS = 1e5     # the highest keyframe rate [1/s] of a view (never closer than a 10 us record)


#: the load resonance and the oil-column and valve frequencies of a model lie in this band [Hz];
#: a value orders of magnitude beyond it (a stiffness of 1e300 lbf/in) is refused by field
MODEL_FREQ_HZ = (1e-3, 1e5)


def check_model_plausible(src: str, engine, actuator, structure) -> None:
    """Refuse model values whose derived frequencies overflow or are physically absurd by
    orders of magnitude (outside :data:`MODEL_FREQ_HZ`), naming the field that drives them."""
    lo, hi = MODEL_FREQ_HZ
    R = actuator.moment_arm_m
    with np.errstate(all="ignore"):
        checks = [
            ("structure.load_stiffness", "load resonance sqrt((K_L R^2 + K_n)/J_n)",
             math.sqrt((structure.load_stiffness_N_per_m * R * R + engine.rotational_stiffness_Nm_per_rad)
                       / min(engine.inertia_pitch_kgm2, engine.inertia_yaw_kgm2)) / (2 * math.pi)),
            ("structure.load_stiffness_yaw", "yaw load resonance sqrt((K_L,yaw R^2 + K_n)/J_n)",
             math.sqrt((structure.stiffness_N_per_m("yaw") * R * R + engine.rotational_stiffness_Nm_per_rad)
                       / engine.inertia_yaw_kgm2) / (2 * math.pi)),
            ("actuator.oil_bulk_modulus", "oil-column frequency sqrt(4 beta A^2 / (V_t M_p))",
             math.sqrt(4 * actuator.oil_bulk_modulus_Pa * actuator.piston_area_m2 ** 2
                       / (actuator.trapped_volume_m3 * actuator.piston_mass_kg)) / (2 * math.pi)),
            ("actuator.valve_natural_frequency", "servovalve frequency", actuator.valve_natural_frequency_hz),
            ("actuator.loop_gain", "position-loop bandwidth K_v / 2 pi", actuator.loop_gain_per_s / (2 * math.pi)),
        ]
    for field, what, f in checks:
        if not (math.isfinite(f) and f <= hi):
            raise InputError(src, field, f"a value giving a {what} below {hi:g} Hz", got=f"{f:.3g} Hz")


def _fmt_deg(rad: float) -> str:
    return f"{math.degrees(rad):.6g} deg"


def check_command_angle(value_rad: float, source: str, field: str) -> float:
    """|theta_c| within the gimbal range (commands beyond it are refused at the edge)."""
    if not math.isfinite(value_rad) or abs(value_rad) > GIMBAL_RANGE_RAD * (1 + 1e-12):
        raise InputError(source, field, f"a command within the gimbal range +-{math.degrees(GIMBAL_RANGE_RAD):g} deg",
                         got=_fmt_deg(value_rad))
    return value_rad


def check_amplitude(amp_rad: float, model, field: str, source: str = "command line") -> float:
    """A sine-dwell amplitude of at least one command LSB (else the quantised command is zero
    and the gain -inf) and within the gimbal range."""
    lsb = model.avionics.lsb_rad
    if amp_rad < lsb:
        raise InputError(source, field, f"an amplitude of at least one command LSB ({math.degrees(lsb):.4g} deg)",
                         got=_fmt_deg(amp_rad))
    return check_command_angle(amp_rad, source, field)


def check_range(value: float, lo: float, hi: float, source: str, field: str, unit: str, why: str = "") -> float:
    """``lo <= value <= hi`` (finite), else one line naming value and limits."""
    if not (math.isfinite(value) and lo <= value <= hi):
        exp = f"a value from {lo:g} to {hi:g} {unit}" + (f" ({why})" if why else "")
        raise InputError(source, field, exp, got=f"{value:g} {unit}".strip())
    return value


def check_command_frequency(f_hz: float, source: str, field: str) -> float:
    return check_range(f_hz, *COMMAND_FREQ_HZ, source, field, "Hz", "the documented command range")


def check_response_frequencies(freqs_hz, source: str = "command line", field: str = "--freq-hz") -> None:
    for f in np.atleast_1d(freqs_hz):
        check_range(float(f), *RESPONSE_FREQ_HZ, source, field, "Hz", "the documented analysis range")


def check_duration(duration_s: float, source: str, field: str) -> float:
    return check_range(duration_s, 0.0, MAX_DURATION_S, source, field, "s", "the documented run length limit")


def check_cycles(cycles: int, source: str, field: str) -> int:
    if cycles > MAX_CYCLES:
        raise InputError(source, field, f"at most {MAX_CYCLES} cycles", got=str(cycles))
    return cycles


# -- physical bounds of every model-file value (docs/reference/bounds.md) --------------------

#: field -> (lowest, highest) in SI, SI unit, why. A value outside is refused when the model file
#: is loaded, before any work (one line naming the field, the value and the bounds). The bounds
#: are orders of magnitude around launch-vehicle TVC hardware, not tolerances: they refuse a
#: mistyped unit or exponent ("1e-300 lbf/in", "400 deg", "1000 m"), never a real design.
MODEL_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "engine.mass": (1.0, 1e5, "kg", "a thruster to ten F-1 engines (8.4 t each)"),
    "engine.inertia_pitch": (1e-2, 1e7, "kg*m**2", "RS-25 12400 kg m^2; 1e7 is a whole stage"),
    "engine.inertia_yaw": (1e-2, 1e7, "kg*m**2", "RS-25 12400 kg m^2; 1e7 is a whole stage"),
    "engine.rotational_stiffness": (0.0, 1e10, "N*m/rad", "feedlines and gravity: 5e5 N m/rad for RS-25"),
    "engine.thrust": (0.0, 1e8, "N", "F-1 6.8 MN; 1e8 N is fifteen of them"),
    "engine.gimbal_range": (1e-3 * DEG, 30.0 * DEG, "rad", "TVC gimbals swing 5-15 deg; the planar "
                            "small-angle model means nothing beyond 30 deg"),
    "engine.hard_stop_stiffness": (1e3, 1e13, "N*m/rad", "a stop must be stiffer than the load path"),
    "engine.hard_stop_damping_ratio": (0.0, 10.0, "1", "a damping ratio beyond 10 is no contact model"),
    "actuator.moment_arm": (0.01, 5.0, "m", "lever arms are 0.1-1.5 m (RS-25 0.8 m); 5 m is longer than "
                            "the engine"),
    "actuator.piston_area": (1e-5, 0.1, "m**2", "0.016-155 in^2; RS-25 actuator 15 in^2"),
    "actuator.supply_pressure": (1e5, 1e8, "Pa", "1 bar to 14500 psi; flight hydraulics 3000-8000 psi"),
    "actuator.oil_bulk_modulus": (1e7, 1e10, "Pa", "aerated oil 10 MPa to stiffer than any oil; "
                                  "mineral oil 1.4-1.7 GPa"),
    "actuator.trapped_volume": (1e-7, 1.0, "m**3", "0.1 cm^3 to 1 m^3; RS-25 actuator 100 in^3"),
    "actuator.piston_mass": (1e-2, 1e4, "kg", "10 g to 10 t; RS-25 actuator 45 kg"),
    "actuator.piston_damping": (0.0, 1e9, "N*s/m", "1e4 N s/m typical"),
    "actuator.loop_gain": (1e-2, 1e4, "1/s", "position-loop gains are 10-100 1/s"),
    "actuator.valve_natural_frequency": (1.0, 1e4, "Hz", "servovalves are 50-500 Hz"),
    "actuator.valve_damping_ratio": (1e-3, 10.0, "1", "servovalves 0.5-1"),
    "actuator.flow_pressure_coefficient": (0.0, 1e-6, "m**3/s/Pa", "K_c is 1e-13-1e-10 m^3/(s Pa)"),
    "actuator.leakage_coefficient": (0.0, 1e-6, "m**3/s/Pa", "as K_c"),
    "actuator.pressure_feedback_gain": (0.0, 1e-5, "m/s/Pa", "1e-8 m/(s Pa) typical: 0.2 m/s at supply"),
    "actuator.pressure_feedback_time_constant": (0.0, 100.0, "s", "washout of 0.01-1 s"),
    "actuator.max_rate": (1e-4, 10.0, "m/s", "TVC piston rates are 0.1-0.5 m/s"),
    "actuator.relief_flow_coefficient": (0.0, 1e-4, "m**3/s/Pa", "a relief valve passes at most the pump flow"),
    "actuator.rated_flow": (1e-7, 0.1, "m**3/s", "servovalves 0.1-1000 gal/min; 0: no limit"),
    "actuator.pump_capacity": (1e-7, 0.1, "m**3/s", "TVC hydraulic pumps 10-200 gal/min; 0: no limit"),
    "structure.load_stiffness": (1e4, 1e11, "N/m", "57 lbf/in to 5.7e8 lbf/in; RS-25 load path "
                                 "1.15e5-2.05e5 lbf/in"),
    "structure.load_stiffness_yaw": (1e4, 1e11, "N/m", "as structure.load_stiffness (the yaw axis' own)"),
    "structure.load_damping_ratio": (0.0, 10.0, "1", "structures are 0.005-0.05"),
    "friction.coulomb_torque": (0.0, 1e7, "N*m", "RS-25 hot fire 1.3e4 N m; 1e7 N m would hold a stage"),
    "friction.static_torque": (0.0, 1e7, "N*m", "as the Coulomb torque"),
    "avionics.command_range": (1e-3 * DEG, 90.0 * DEG, "rad", "the command word spans the gimbal range "
                               "(RS-25 +-21 deg full scale)"),
    "gimbal.upper_stiffness_scale": (1e-3, 1e3, "1", "a factor on the FEM half's stiffness: a fit's correction "
                                     "of the FEM (tens of percent), never three orders of magnitude"),
    "gimbal.lower_stiffness_scale": (1e-3, 1e3, "1", "as gimbal.upper_stiffness_scale"),
}
#: longest piston travel at the hard stops, R tan(theta_max) [m]: TVC actuator strokes are
#: +-5 to +-15 cm; stops beyond half a metre of piston travel lie outside any actuator's stroke
MAX_STROKE_M = 0.5
#: agreement of ``actuator.moment_arm`` with the lever arm the ``[geometry]`` attachment points
#: give (distance from the gimbal point to the actuator line): a relative difference of at most
#: this (the planar and 3-D models would otherwise describe different engines)
MOMENT_ARM_TOLERANCE = 0.1


#: flight-file fields (``[vehicle]``, ``[fcs]``), as :data:`MODEL_BOUNDS`: launch vehicles from a
#: sounding rocket to a super-heavy stack; flight-control gains of a stable attitude loop
FLIGHT_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "vehicle.mass": (1e2, 1e8, "kg", "a sounding rocket to 30 times a Saturn V (2.9e6 kg)"),
    "vehicle.pitch_inertia": (1.0, 1e12, "kg*m**2", "SLS core stage 4.5e8 kg m^2"),
    "vehicle.yaw_inertia": (1.0, 1e12, "kg*m**2", "SLS core stage 4.5e8 kg m^2"),
    "vehicle.thrust_per_engine": (1.0, 1e8, "N", "F-1 6.8 MN"),
    "vehicle.gimbal_arm": (0.1, 300.0, "m", "c.g. to gimbal of a 110 m stack is under 60 m"),
    "vehicle.engine_mass": (0.0, 1e5, "kg", "as engine.mass of a model file"),
    "vehicle.engine_cg_offset": (0.0, 20.0, "m", "an engine is at most ~6 m long"),
    "vehicle.engine_inertia": (0.0, 1e7, "kg*m**2", "as engine.inertia_pitch"),
    "vehicle.aero_instability": (0.0, 100.0, "1/s**2", "a divergence rate of 10 rad/s is no flyable vehicle"),
    "vehicle.bending_frequency": (0.0, 1e3, "Hz", "first bending modes are 1-10 Hz"),
    "vehicle.bending_damping_ratio": (1e-5, 10.0, "1", "structures are 0.005-0.05"),
    "vehicle.bending_gain": (0.0, 1e3, "1", "a modal slope ratio"),
    "fcs.attitude_gain": (1e-3, 100.0, "rad/rad", "1-3 deg/deg typical"),
    "fcs.integral_gain": (0.0, 100.0, "1/s", "below the attitude bandwidth"),
    "fcs.rate_gain": (0.0, 100.0, "s", "0.5-5 s typical"),
    "fcs.lag_time_constant": (0.0, 10.0, "s", "command lags are 0.01-0.5 s"),
    "fcs.notch_frequency": (0.0, 1e3, "Hz", "at the bending mode, 1-10 Hz"),
    "fcs.notch_zeta_num": (0.0, 10.0, "1", "a damping ratio"),
    "fcs.notch_zeta_den": (1e-5, 10.0, "1", "a damping ratio"),
    "fcs.delay": (0.0, 2.0, "s", "sensor and computer delays are tens of ms"),
}
#: most engines of one flight file (N1: 30)
MAX_ENGINES = 64


def check_bound(value: float, field: str, src: str) -> float:
    """``value`` (SI) within :data:`MODEL_BOUNDS` or :data:`FLIGHT_BOUNDS` ``[field]``, else one
    line with the bounds."""
    lo, hi, unit, why = MODEL_BOUNDS[field] if field in MODEL_BOUNDS else FLIGHT_BOUNDS[field]
    if not (math.isfinite(value) and lo <= value <= hi):
        raise InputError(src, field, f"a value from {lo:.4g} to {hi:.4g} {unit} ({why})", got=f"{value:.4g} {unit}")
    return value


def _lever_arm(geometry: dict, axis: str, src: str) -> float | None:
    """Distance [m] from the gimbal point (origin) to the line through the axis' structure and
    engine attachment points of ``[geometry]``, or None when they are not given."""
    from .units import to_si

    pts = []
    for key in (f"{axis}_structure_attach", f"{axis}_engine_attach"):
        v = geometry.get(key)
        if not isinstance(v, list) or len(v) != 3:
            return None
        pts.append(np.array([to_si(c, "length", source=src, field=f"geometry.{key}[{i}]") for i, c in enumerate(v)]))
    d = pts[0] - pts[1]
    n = float(np.linalg.norm(d))
    if not n > 0:
        raise InputError(src, f"geometry.{axis}_engine_attach", "an attachment point apart from the structure's",
                         got="the same point")
    return float(np.linalg.norm(np.cross(pts[1], d / n)))


def check_model_bounds(src: str, engine, actuator, structure, avionics, friction_table, extra) -> None:
    """Every value of a loaded model within :data:`MODEL_BOUNDS`, and the cross-field checks:
    static torque at least the Coulomb torque (breakaway needs at least the sliding torque), the
    hard stops inside the stroke (:data:`MAX_STROKE_M`), the moment arm against the
    ``[geometry]`` lever arms (:data:`MOMENT_ARM_TOLERANCE`)."""
    from .units import to_si

    objs = {"engine": engine, "actuator": actuator, "structure": structure}
    for field, _ in MODEL_BOUNDS.items():
        sec, key = field.split(".")
        if sec in objs:
            obj = objs[sec]
            attr = next((a for a in vars(obj) if a == key or a.startswith(key + "_")), None)
            value = getattr(obj, attr) if attr is not None else None
            optional_zero = key in ("gimbal_range", "hard_stop_stiffness", "max_rate", "relief_flow_coefficient",
                                    "load_stiffness_yaw", "rated_flow", "pump_capacity")
            if value is None or (optional_zero and value == 0.0):
                continue
            check_bound(float(value), field, src)
        elif sec == "friction" and key in friction_table:
            check_bound(to_si(friction_table[key], "torque", source=src, field=field), field, src)
        elif sec in ("gimbal", "geometry") and isinstance(extra.get(sec), Mapping) and key in extra[sec]:
            # the 3-D model's keys, bounded at load like every other (their kind from the bound's unit)
            kind = {"1": "dimensionless", "m": "length", "N/m": "stiffness"}[MODEL_BOUNDS[field][2]]
            check_bound(to_si(extra[sec][key], kind, source=src, field=field), field, src)
    check_bound(avionics.command_range_rad, "avionics.command_range", src)
    if "static_torque" in friction_table and "coulomb_torque" in friction_table:
        ts = to_si(friction_table["static_torque"], "torque", source=src, field="friction.static_torque")
        tc = to_si(friction_table["coulomb_torque"], "torque", source=src, field="friction.coulomb_torque")
        if ts < tc * (1 - 1e-12):
            raise InputError(src, "friction.static_torque", f"at least the Coulomb torque {tc:.6g} N*m (breakaway "
                             "takes at least the sliding torque)", got=f"{ts:.6g} N*m")
    if engine.gimbal_range_rad > 0:
        travel = actuator.moment_arm_m * math.tan(engine.gimbal_range_rad)
        if travel > MAX_STROKE_M:
            raise InputError(src, "engine.gimbal_range", f"hard stops inside the actuator stroke: piston travel "
                             f"R tan(theta_max) at most {MAX_STROKE_M:g} m", got=f"{travel:.3g} m")
    geometry = extra.get("geometry")
    if isinstance(geometry, dict):
        for axis in ("pitch", "yaw"):
            arm = _lever_arm(geometry, axis, src)
            R = actuator.moment_arm_m
            if arm is not None and abs(arm - R) > MOMENT_ARM_TOLERANCE * R:
                raise InputError(src, f"geometry.{axis}_engine_attach", f"attach points giving a moment arm of "
                                 f"{R:.4g} m (actuator.moment_arm) within {100 * MOMENT_ARM_TOLERANCE:g} %",
                                 got=f"{arm:.4g} m")


# -- the Python API's arguments, checked as the command line checks them --------------------

AXES = ("pitch", "yaw")


def check_axis(axis, field: str = "axis", source: str = "argument") -> str:
    """``axis`` is 'pitch' or 'yaw' (InputError naming the argument otherwise)."""
    if axis not in AXES:
        raise InputError(source, field, "'pitch' or 'yaw'", got=repr(axis)[:40])
    return axis


def check_grid(values, field: str, unit: str, lo: float = 0.0, hi: float = math.inf,
               source: str = "argument") -> np.ndarray:
    """A non-empty grid (a number or a 1-D sequence) of finite real values in (``lo``, ``hi``]
    (frequencies [Hz], amplitudes [rad]) as a float array; InputError naming ``field`` for an
    empty grid, text, booleans or None, a nested array, a NaN, a zero or negative value: the
    API never answers them with NaN or a silent result."""
    try:
        raw = np.asarray(values)
    except (TypeError, ValueError):
        raise InputError(source, field, f"numbers in {unit}", got=repr(values)[:60]) from None
    if raw.dtype.kind not in "iuf":   # text ('1'), booleans (True is not 1 Hz), None, objects
        raise InputError(source, field, f"numbers in {unit} (not text, booleans or None)", got=repr(values)[:60])
    if raw.ndim > 1:
        raise InputError(source, field, f"a number or a 1-D sequence of numbers in {unit}", got=f"shape {raw.shape}")
    a = np.atleast_1d(raw.astype(float))
    if a.size == 0:
        raise InputError(source, field, f"at least one value in {unit}", got="an empty grid")
    bad = np.flatnonzero(~(np.isfinite(a) & (a > lo) & (a <= hi)))
    if bad.size:
        raise InputError(source, field, f"finite values above {lo:g} {unit}" + ("" if hi == math.inf else
                         f" and at most {hi:g} {unit}"), got=f"{a[bad[0]]:g} {unit}")
    return a


def check_number(value, field: str, lo: float = -math.inf, hi: float = math.inf, unit: str = "",
                 *, lo_open: bool = False, optional: bool = False, source: str = "argument") -> float | None:
    """A finite real number in [``lo``, ``hi``] (``(lo, hi]`` with ``lo_open``) as a float, or
    None when ``optional``; InputError naming ``field`` for text, booleans, None, arrays, NaN,
    infinities and values out of range."""
    if value is None and optional:
        return None
    u = f" {unit}" if unit else ""
    if lo > -math.inf:
        rng = (f"above {lo:g}" + (f" and at most {hi:g}" if hi < math.inf else "") if lo_open else
               f"from {lo:g}" + (f" to {hi:g}" if hi < math.inf else " up"))
    else:
        rng = f"at most {hi:g}" if hi < math.inf else ""
    want = f"{'None or ' if optional else ''}a finite number{(' ' + rng) if rng else ''}{u}"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(source, field, want, got=repr(value)[:40])
    v = float(value)
    if not (math.isfinite(v) and (v > lo if lo_open else v >= lo) and v <= hi):
        raise InputError(source, field, want, got=repr(value)[:40])
    return v


def check_count(value, field: str, lowest: int, highest: int = MAX_CYCLES, source: str = "argument") -> int:
    """A whole number from ``lowest`` to ``highest`` (cycles, steps per cycle, record interval,
    runs): never a boolean, a float or text."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not lowest <= value <= highest:
        raise InputError(source, field, f"a whole number from {lowest} to {highest}", got=repr(value)[:40])
    return int(value)


def check_flag(value, field: str, source: str = "argument") -> bool:
    """True or False (never 'no', 0.5 or None, which Python would take as true or false)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(source, field, "True or False", got=repr(value)[:40])
    return bool(value)


def check_choice(value, field: str, choices, source: str = "argument") -> str:
    """One of the names ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise InputError(source, field, "one of " + ", ".join(repr(c) for c in choices), got=repr(value)[:40])
    return value


def check_instance(value, field: str, cls, what: str, source: str = "argument"):
    """``value`` is a ``cls`` (``what`` names it, e.g. "a TvcModel (taos.load_model)")."""
    if not isinstance(value, cls):
        raise InputError(source, field, what, got=f"{type(value).__name__} {repr(value)[:30]}")
    return value


def check_profile(profile, field: str = "profile", source: str = "argument"):
    """A command profile (:mod:`taos.profiles`, ``taos.load_profile``): callable on times, with a
    finite duration of at most :data:`MAX_DURATION_S`."""
    T = getattr(profile, "duration_s", None)
    if not callable(profile) or isinstance(T, bool) or not isinstance(T, (int, float)) \
            or not (math.isfinite(T) and 0 <= T <= MAX_DURATION_S):
        raise InputError(source, field, f"a profile (taos.load_profile) of at most {MAX_DURATION_S:g} s",
                         got=f"{type(profile).__name__} {repr(profile)[:30]}")
    return profile


#: integration steps of one sine-dwell job of the API (as taos.planar.envelope.MAX_DWELL_STEPS)
MAX_DWELL_STEPS = 5e7


def check_step(dt_s, field: str, duration_s: float | None = None, hi: float = math.inf,
               source: str = "argument") -> float:
    """A finite positive step [s] of at most ``hi`` (and, with ``duration_s``, a job within the
    step and memory limits :data:`MAX_STEPS`, :data:`MAX_JOB_BYTES`, estimated as the command
    line does)."""
    dt = check_number(dt_s, field, 0.0, hi, "s", lo_open=True, source=source)
    if duration_s is not None:
        n = duration_s / dt
        if n > MAX_STEPS or n * 8 * 12 > MAX_JOB_BYTES:   # time, two commands and their copies, float64
            raise InputError(source, field, f"at most {MAX_STEPS:.0e} steps within {MAX_JOB_BYTES / 2 ** 30:g} GiB "
                             f"for the {duration_s:g} s run", got=f"{dt:g} s")
    return dt


def check_response_args(freq_hz, amplitudes_rad=None, axis: str = "pitch") -> None:
    """The arguments of the frequency-response and describing-function API: frequencies in
    :data:`RESPONSE_FREQ_HZ`, amplitudes positive and within 90 deg, a known axis."""
    check_axis(axis)
    check_grid(freq_hz, "freq_hz", "Hz", 0.0, RESPONSE_FREQ_HZ[1])
    if amplitudes_rad is not None:
        check_grid(amplitudes_rad, "amplitudes_rad", "rad", 0.0, math.pi / 2)


# -- campaign, ascent and profile files (docs/reference/bounds.md) ----------------------------

def _check_in(table: dict, key: str, value: float, src: str, field: str | None = None) -> float:
    """``value`` (SI) within ``table[key]`` (lowest, highest, SI unit, why), else one line naming
    ``field`` (default ``key``), the value and the bounds."""
    lo, hi, unit, why = table[key]
    if not (math.isfinite(value) and lo <= value <= hi):
        raise InputError(src, field or key, f"a value from {lo:.4g} to {hi:.4g} {unit} ({why})",
                         got=f"{value:.4g} {unit}")
    return value


#: campaign-file fields (``models/montecarlo/*.toml``, :mod:`taos.montecarlo.campaign`), as
#: :data:`MODEL_BOUNDS`; ``dispersions.*`` are factors on the case's nominal value. The run count,
#: batch size and workers are command-line values (``taos.montecarlo.executor``: 1 to 200,000
#: runs, 1 to 1000 runs per task, 0 to 64 workers).
CAMPAIGN_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "seed": (0.0, 2.0 ** 63 - 1, "1", "an entropy word of NumPy's SeedSequence, kept a signed 64-bit integer"),
    "start": (0.0, 2000.0, "s", "a time of the ascent (ascent files are at most 2000 s)"),
    "duration": (10.0, 2000.0, "s", "at least the shortest analysis window; at most an ascent"),
    "dt": (1e-5, 1e-2, "s", "the oil column needs an RK4 step of at most 2 ms; ETDRK4 (`integrator = \"etdrk4\"`) "
           "up to 10 ms, dividing the 20 ms records; below 0.01 ms a run takes hours"),
    "analysis_window": (10.0, 2000.0, "s", "a 0.1 Hz limit cycle needs a whole cycle; at most the duration"),
    "trace_interval": (1e-5, 200.0, "s", "from dt to a tenth of the duration"),
    "update_interval": (0.01, 10.0, "s", "vehicle properties change by < 1.5 % in 5 s after separation"),
    "dispersions.mean": (0.01, 100.0, "1", "a factor on the nominal value: dispersions are percent-level, a "
                         "stress campaign pushes a gain to 16 times; 100 times nominal is another vehicle"),
    "dispersions.std": (0.0, 1.0, "1", "preflight 3-sigma spreads are 5-45 %; one sigma of 100 % is no dispersion"),
    "dispersions.low": (0.0, 100.0, "1", "factors stay non-negative; as mean"),
    "dispersions.high": (0.0, 100.0, "1", "as mean"),
    "cases": (1.0, 64.0, "", "named variants of one campaign, run one at a time"),
}


def check_campaign_bounds(c, model_fields: dict[str, str]) -> None:
    """A loaded :class:`~taos.montecarlo.campaign.Campaign` within :data:`CAMPAIGN_BOUNDS`; a
    normal dispersion's mean inside its [low, high] (else the clipping piles the runs on a
    bound); every case override within the model bound (:data:`MODEL_BOUNDS`) of its model-file
    field (``model_fields``: parameter name -> "section.key")."""
    src, T = c.source, CAMPAIGN_BOUNDS
    for key, value in (("seed", c.seed), ("start", c.start_s), ("duration", c.duration_s), ("dt", c.dt_s),
                       ("analysis_window", c.analysis_window_s), ("trace_interval", c.trace_interval_s),
                       ("update_interval", c.update_interval_s), ("cases", len(c.cases))):
        if value is not None:
            _check_in(T, key, float(value), src)
    for d in c.dispersions:
        fld = f"dispersions.{d.name}"
        vals = {"low": d.low, "high": d.high} | ({"mean": d.mean, "std": d.std} if d.distribution == "normal" else {})
        for k, v in vals.items():
            if math.isfinite(v) or k in ("mean", "std"):      # an infinite low/high is "not given"
                _check_in(T, f"dispersions.{k}", v, src, f"{fld}.{k}")
        if d.distribution == "normal" and not d.low <= d.mean <= d.high:
            raise InputError(src, f"{fld}.mean", f"a mean inside [low, high] = [{d.low:g}, {d.high:g}] (the "
                             "clipping would pile the runs on a bound)", got=f"{d.mean:g}")
    for case, over in c.cases.items():
        for name, v in over.items():
            if model_fields.get(name) in MODEL_BOUNDS:
                _check_in(MODEL_BOUNDS, model_fields[name], v, src, f"cases.{case}.{name}")


#: ascent-file fields (``models/flight/ascent.toml``, :mod:`taos.flight.ascent`), as
#: :data:`MODEL_BOUNDS`; ``trajectory.*`` bound every value of the column, ``pti.*`` every
#: ``[[pti]]``. Signed quantities have a negative lowest value.
ASCENT_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "update_interval": (0.01, 10.0, "s", "a zero-order hold of the vehicle properties: 10 ms to 10 s"),
    "trajectory.time": (0.0, 2000.0, "s", "an ascent to orbit lasts 8-10 min"),
    "trajectory.mass": (1e2, 1e8, "kg", "as vehicle.mass of a flight file"),
    "trajectory.inertia": (1.0, 1e12, "kg*m**2", "as vehicle.pitch_inertia"),
    "trajectory.gimbal_arm": (0.1, 300.0, "m", "as vehicle.gimbal_arm"),
    "trajectory.core_thrust_per_engine": (0.0, 1e8, "N", "as vehicle.thrust_per_engine (0: engine off)"),
    "trajectory.booster_thrust": (0.0, 1e8, "N", "per booster: an SLS five-segment booster 16 MN"),
    "trajectory.dynamic_pressure": (0.0, 1e6, "Pa", "max-q is 30-40 kPa; 1 MPa is Mach 3.7 at sea level"),
    "trajectory.velocity": (1.0, 1.2e4, "m/s", "the wind angle of attack w/V means nothing below 1 m/s; "
                            "escape velocity is 11.2 km/s"),
    "trajectory.wind_speed": (0.0, 200.0, "m/s", "jet-stream cores reach 100 m/s"),
    "boosters.separation_time": (0.0, 2000.0, "s", "a time of the ascent"),
    "boosters.gimbal_arm": (0.1, 300.0, "m", "as vehicle.gimbal_arm"),
    "boosters.actuator_time_constant": (1e-3, 10.0, "s", "booster TVC servos are 0.02-0.2 s"),
    "boosters.separation_rate_kick": (-0.2, 0.2, "rad/s", "separation disturbances are a fraction of a deg/s; "
                                      "11 deg/s would tumble the stack"),
    "aero.reference_area": (0.0, 1000.0, "m**2", "SLS 55 m^2 (8.4 m); 1000 m^2 is a 36 m diameter"),
    "aero.normal_force_slope": (0.0, 50.0, "1/rad", "C_N_alpha of slender launch vehicles is 2-10 1/rad"),
    "aero.center_of_pressure_ahead": (-300.0, 300.0, "m", "within the stack (SLS 98 m)"),
    "wind.azimuth": (-2 * math.pi, 2 * math.pi, "rad", "a direction: one turn either way"),
    "wind.gust_time": (0.0, 2000.0, "s", "a time of the ascent"),
    "wind.gust_amplitude": (-100.0, 100.0, "m/s", "design discrete gusts are 9-30 m/s"),
    "wind.gust_duration": (0.01, 1000.0, "s", "1-cosine gusts last 1-20 s"),
    "wind.turbulence_intensity": (0.0, 50.0, "m/s", "severe turbulence has an RMS of 3-7 m/s"),
    "wind.turbulence_time_constant": (0.1, 1000.0, "s", "Dryden correlation times are 0.5-10 s; the turbulence "
                                      "is drawn every tau/20, so 0.1 s bounds it to 4e5 points over 2000 s"),
    "pti.start": (0.0, 2000.0, "s", "a time of the ascent"),
    "pti.duration": (0.01, 2000.0, "s", "flight PTIs last 10-30 s"),
    "pti.amplitude": (1e-4 * DEG, 5.0 * DEG, "rad", "PTIs are 0.1-0.5 deg; below 1e-4 deg (1/40 of a command LSB) "
                      "no test input; 5 deg is half the gimbal range"),
    "pti.low_frequency": (1e-3, 50.0, "Hz", "flight PTIs span 0.1-10 Hz; the multisine has 4 lines an octave, "
                          "so 1e-3 Hz bounds it to 63 lines"),
    "pti.high_frequency": (1e-3, 50.0, "Hz", "as low_frequency, and above it"),
}


def check_pti_bounds(p, src: str, sec: str) -> None:
    """One ``[[pti]]`` (:class:`~taos.flight.ascent.Pti`, named ``sec``) within :data:`ASCENT_BOUNDS`."""
    for key, v in (("start", p.start_s), ("duration", p.duration_s), ("amplitude", p.amplitude_rad),
                   ("low_frequency", p.low_frequency_hz), ("high_frequency", p.high_frequency_hz)):
        _check_in(ASCENT_BOUNDS, f"pti.{key}", v, src, f"{sec}.{key}")


def check_ascent_bounds(a) -> None:
    """A loaded :class:`~taos.flight.ascent.Ascent` within :data:`ASCENT_BOUNDS`, and the gust
    and every PTI inside the trajectory (else they are silently never flown)."""
    src, T = a.source, ASCENT_BOUNDS
    _check_in(T, "update_interval", a.update_interval_s, src)
    tr = a.trajectory
    for col in ("time", "mass", "inertia", "gimbal_arm", "core_thrust_per_engine", "booster_thrust",
                "dynamic_pressure", "velocity", "wind_speed"):
        arr = next(getattr(tr, f.name) for f in dataclasses.fields(tr) if f.name.startswith(col + "_"))
        lo, hi = T[f"trajectory.{col}"][:2]
        bad = np.flatnonzero(~((arr >= lo) & (arr <= hi)))
        if bad.size:
            _check_in(T, f"trajectory.{col}", float(arr[bad[0]]), src, f"trajectory.{col}.values")
    b, ae, w = a.boosters, a.aero, a.wind
    for key, v in (("boosters.separation_time", b.separation_time_s), ("boosters.gimbal_arm", b.gimbal_arm_m),
                   ("boosters.actuator_time_constant", b.actuator_time_constant_s),
                   ("boosters.separation_rate_kick", b.separation_rate_kick_rad_s),
                   ("aero.reference_area", ae.reference_area_m2), ("aero.normal_force_slope", ae.normal_force_slope_per_rad),
                   ("aero.center_of_pressure_ahead", ae.center_of_pressure_ahead_m), ("wind.azimuth", w.azimuth_rad),
                   ("wind.gust_time", w.gust_time_s), ("wind.gust_amplitude", w.gust_amplitude_m_s),
                   ("wind.gust_duration", w.gust_duration_s), ("wind.turbulence_intensity", w.turbulence_intensity_m_s),
                   ("wind.turbulence_time_constant", w.turbulence_time_constant_s)):
        _check_in(T, key, v, src)
    end = a.end_time_s
    if w.gust_time_s > end:
        raise InputError(src, "wind.gust_time", f"a time within the trajectory (to {end:g} s)", got=f"{w.gust_time_s:g} s")
    for p in a.ptis:
        if p.end_s > end + 1e-9:
            raise InputError(src, "pti", f"every PTI within the trajectory (to {end:g} s)",
                             got=f"a PTI from {p.start_s:g} s to {p.end_s:g} s")


#: profile-file values (``models/profiles/*.toml``, :mod:`taos.profiles`), by key in any
#: profile table. Angles against the RS-25 gimbal range; frequencies, durations and cycles as
#: the run limits above (:data:`COMMAND_FREQ_HZ`, :data:`MAX_DURATION_S`, :data:`MAX_CYCLES`).
PROFILE_BOUNDS: dict[str, tuple[float, float, str, str]] = {
    "amplitude": (1e-6 * DEG, GIMBAL_RANGE_RAD, "rad", "a sine, sweep, multisine or circle must move (a millionth "
                  "of a degree) and stay within the gimbal range +-10.5 deg"),
    "step amplitude": (-GIMBAL_RANGE_RAD, GIMBAL_RANGE_RAD, "rad", "within the gimbal range"),
    "levels": (-GIMBAL_RANGE_RAD, GIMBAL_RANGE_RAD, "rad", "within the gimbal range"),
    "rate": (1e-3 * DEG, 1000.0 * DEG, "rad/s", "TVC slew rates are 5-30 deg/s: a faster ramp is a step, a slower "
             "one crosses the range in more than 1e4 s"),
    "frequency": (*COMMAND_FREQ_HZ, "Hz", "test and flight content is 0.1-30 Hz"),
    "cycles": (1.0, float(MAX_CYCLES), "", "a whole number of cycles"),
    "start": (0.0, MAX_DURATION_S, "s", "the run length limit"),
    "hold": (0.0, MAX_DURATION_S, "s", "the run length limit"),
    "duration": (0.0, MAX_DURATION_S, "s", "above zero, and the run length limit"),
    "number of levels": (1.0, 1000.0, "", "a multi-ramp has a handful of levels"),
    "number of frequencies": (1.0, 200.0, "", "the multisine is summed line by line at every sample"),
    "number of segments": (1.0, 1000.0, "", "a test sequence has tens of segments"),
}


def check_profile_value(key: str, value: float, src: str, field: str) -> float:
    """``value`` (SI, or a count) within :data:`PROFILE_BOUNDS` ``[key]``."""
    return _check_in(PROFILE_BOUNDS, key, float(value), src, field)
