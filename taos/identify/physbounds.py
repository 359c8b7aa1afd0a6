"""Bounds of fitted parameters from physics and the measured band, not from the start value.

A fit must be able to reach the right answer from any credible start model (the ambient
model's 2,185 in-lbf friction and the hot-fire model's 117,525 in-lbf describe the same
bearing at two normal loads), so the range a parameter may take is set by what the hardware
and the record allow, never as a multiple of where the fit began. :func:`physical_bounds`
gives, for the names that have one:

* ``load_stiffness`` K_L [N/m]: the load resonance w_L = sqrt((K_L R^2 + K_n) / J_n)
  (docs/theory/simplex.md) within the measured band widened by ``band_margin`` (an octave by
  default) on each side: lower K_L puts the notch below f_min / 2, higher above 2 f_max, where
  the record cannot tell K_L from zero or from a rigid load path. With J_n of each axis in
  the record, the lower bound is the smallest and the upper the largest over the axes, and
  the lower at least 1e-3 of the upper (the feedline stiffness K_n alone may already hold
  w_L above f_min / 2). For the shipped RS-25 set and a 0.5-14 Hz Green Run record: 3,400 to
  3.4e6 lbf/in (K_n alone puts w_L at 1.0 Hz), which holds both Green Run fits (115,000 and
  205,000 lbf/in) and the actuator's own oil column 4 beta A^2 / V_t (1.35e6 lbf/in).
* ``coulomb_torque`` T_c [N m]: between ``torque_floor`` (1e-4) times and once the torque the
  actuator can apply at stall, A P_s R (stall force at supply pressure times the moment arm;
  1.42e6 in-lbf for the RS-25 set). A larger friction would hold the engine against every
  command the actuator can make, and a record with engine motion rules it out. The floor is
  above zero because the describing functions divide by T_c (relay level, Dahl loop
  sigma_0 X / T_c); 1e-4 of the stall torque is below any friction a TVC record resolves
  (the shipped ambient level is 1.5e-3 of it).
* ``load_damping_ratio``: 1e-4 to 1 (above critical the load mode is no resonance and the
  record would show no notch).
* ``avionics_gain``: 0.5 to 1.5 (a servo-amplifier gain error beyond +-50 % is a wiring fault,
  not a parameter).

Every other fittable parameter keeps a range relative to its start
(:data:`taos.identify.surrogate.PARAMETERS` ``lo``/``hi``): servo gains and engine properties
come from the hardware's own data sheets, so the start is that data and the range its
uncertainty. ``basis`` says which rule made each bound (reported with the fit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.model import TvcModel

#: the notch may sit up to this factor outside the measured band
BAND_MARGIN = 2.0
#: lowest Coulomb torque as a fraction of the stall torque A P_s R
TORQUE_FLOOR = 1e-4


@dataclass(frozen=True)
class Bound:
    """A parameter's range [SI] and the rule that set it."""

    lower: float
    upper: float
    basis: str


def stall_torque_Nm(model: TvcModel) -> float:
    """A P_s R [N m]: the most torque the actuator applies about the gimbal."""
    return model.actuator.stall_force_N * model.actuator.moment_arm_m


def load_stiffness_for_resonance(model: TvcModel, axis: str, freq_hz: float) -> float:
    """K_L [N/m] that puts w_L = sqrt((K_L R^2 + K_n) / J_n) at ``freq_hz`` on ``axis``."""
    R = model.actuator.moment_arm_m
    w = 2 * math.pi * freq_hz
    return (w * w * model.engine.inertia(axis) - model.engine.rotational_stiffness_Nm_per_rad) / (R * R)


def physical_bounds(model: TvcModel, names, axes, freq_hz, *, band_margin: float = BAND_MARGIN,
                    torque_floor: float = TORQUE_FLOOR) -> dict[str, Bound]:
    """name -> :class:`Bound` for those of ``names`` that have a physical range (module
    docstring); ``axes`` and ``freq_hz`` [Hz] are the record's points."""
    f = np.asarray(freq_hz, float)
    f = f[f > 0]
    axs = sorted(set(map(str, axes))) or ["pitch"]
    out: dict[str, Bound] = {}
    for n in names:
        if n == "load_stiffness" and f.size:
            flo, fhi = float(f.min()) / band_margin, float(f.max()) * band_margin
            lo = min(load_stiffness_for_resonance(model, a, flo) for a in axs)
            hi = max(load_stiffness_for_resonance(model, a, fhi) for a in axs)
            lo = max(lo, 1e-3 * hi)   # K_n alone may hold w_L above f_min / margin
            out[n] = Bound(lo, hi, f"load resonance within [{flo:.3g}, {fhi:.3g}] Hz (measured band "
                                   f"x1/{band_margin:g}..x{band_margin:g})")
        elif n == "coulomb_torque":
            ts = stall_torque_Nm(model)
            out[n] = Bound(torque_floor * ts, ts, f"{torque_floor:g} x to 1 x the stall torque A P_s R")
        elif n == "load_damping_ratio":
            out[n] = Bound(1e-4, 1.0, "a damped resonance (zeta below critical)")
        elif n == "avionics_gain":
            out[n] = Bound(0.5, 1.5, "servo-amplifier gain within +-50 %")
    return out
