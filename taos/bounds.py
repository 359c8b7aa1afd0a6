"""Documented limits of the inputs and of the physical envelope, checked before work starts.

Every check raises :class:`~taos.errors.InputError` (exit 2: one line naming the value and the
limit) or, for a model that is unstable or a run that leaves its envelope,
:class:`~taos.errors.UnstableModel` / :class:`~taos.errors.EnvelopeExceeded` (exit 3).

Limits (SI inside; shown here in the units of the messages):

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

import math

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
