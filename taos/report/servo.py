"""The servoactuator's own figures: position-loop margins, laboratory flatness, load-mode damping.

A flight TVC actuator is specified in the *laboratory* condition (rigid load, no gimbal
friction, unity avionics) as nearly flat to its bandwidth with at least 45 deg and 6 dB of
position-loop margin; on the real load path its load mode should stay damped. These are the
figures a TVC engineer reads first, so ``taos info`` shows them for every model
(:func:`servo_figures`, JSON key ``servo``). All come from the linear simplex block
(:func:`taos.planar.simplex.simplex_state_space`), which takes the command after the avionics
and the friction torque as a separate input, so "no friction, unity avionics" is the block itself:

* position loop, broken at the command summing junction (as ``masv coupling`` breaks it):
  T(jw) = x_p / (R theta_c), L = T / (1 - T); gain and phase margins of L sampled on
  0.01-300 Hz (:func:`taos.stability.loop_margins`), with the model's own load path and in the
  laboratory condition (load stiffness K_L -> 1e12 N/m);
* laboratory command -> engine response: peaking above its low-frequency gain [dB] and the
  -3 dB bandwidth [Hz] (:func:`taos.report.merit.frequency_merit`);
* load mode: the least-damped oscillatory pole of A below 40 Hz, s = -zeta w_n + j w_n
  sqrt(1 - zeta^2): w_n / 2 pi [Hz] and zeta [-], with the model's load path.

Linear analysis only (numpy): no compiled kernels, scipy or python-control, so ``taos info``
stays quick (``tests/test_startup.py``). ``tests/test_servo_calibration.py`` checks the same
figures independently with python-control.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from taos.model import TvcModel

#: load stiffness standing for a rigid load in the laboratory condition [N/m]
LAB_LOAD_STIFFNESS_N_PER_M = 1e12
#: load-mode search band: oscillatory poles below this frequency [Hz]
LOAD_MODE_MAX_HZ = 40.0


@dataclass(frozen=True)
class LoopFigures:
    """Position-loop margins: ``gain_margin_db`` [dB] (smallest over the phase crossovers, inf
    when there is none), ``phase_margin_deg`` [deg] at ``crossover_hz`` [Hz]."""

    gain_margin_db: float
    phase_margin_deg: float
    crossover_hz: float | None

    def to_dict(self) -> dict:
        inf = lambda x: None if x is None or not math.isfinite(x) else float(x)  # noqa: E731
        return {"gain_margin_db": inf(self.gain_margin_db), "phase_margin_deg": inf(self.phase_margin_deg),
                "crossover_hz": inf(self.crossover_hz)}


@dataclass(frozen=True)
class ServoFigures:
    """The servo's figures on one axis (see the module docstring for definitions)."""

    axis: str
    loop: LoopFigures            # with the model's load path
    lab_loop: LoopFigures        # laboratory condition (rigid load)
    lab_peaking_db: float        # laboratory command -> engine peaking above low frequency [dB]
    lab_bandwidth_hz: float | None   # laboratory command -> engine -3 dB [Hz]
    load_mode_hz: float | None   # least-damped oscillatory pole below 40 Hz, model's load [Hz]
    load_mode_damping: float | None  # its damping ratio [-]

    def to_dict(self) -> dict:
        return {"axis": self.axis, "position_loop": self.loop.to_dict(),
                "laboratory": {**self.lab_loop.to_dict(), "engine_peaking_db": self.lab_peaking_db,
                               "engine_bandwidth_3db_hz": self.lab_bandwidth_hz,
                               "load_stiffness_N_per_m": LAB_LOAD_STIFFNESS_N_PER_M},
                "load_mode": {"freq_hz": self.load_mode_hz, "damping_ratio": self.load_mode_damping},
                "definition": "position loop L = T/(1-T), T = x_p/(R theta_c), broken at the command "
                              "summing junction; laboratory: rigid load, no friction, unity avionics"}


def laboratory(model: TvcModel) -> TvcModel:
    """The model with a rigid load path (K_L = :data:`LAB_LOAD_STIFFNESS_N_PER_M`)."""
    return model.replace(structure=dataclasses.replace(model.structure,
                                                       load_stiffness_N_per_m=LAB_LOAD_STIFFNESS_N_PER_M))


def position_loop(model: TvcModel, axis: str = "pitch") -> LoopFigures:
    """Margins of L = T / (1 - T), T = x_p / (R theta_c), sampled on 0.01-300 Hz."""
    import numpy as np

    from taos.planar.simplex import simplex_state_space
    from taos.stability import loop_margins

    f = np.logspace(-2, np.log10(300.0), 6000)
    T = simplex_state_space(model, axis).freqresp(f, "command_rad", "x_p_m") / model.actuator.moment_arm_m
    lm = loop_margins(f, T / (1.0 - T))
    pm, fc = lm.min_phase_margin
    return LoopFigures(lm.min_gain_margin_db, pm, fc)


def load_mode(model: TvcModel, axis: str = "pitch") -> tuple[float | None, float | None]:
    """(w_n / 2 pi [Hz], zeta [-]) of the least-damped oscillatory pole below 40 Hz, or (None, None)."""
    import numpy as np

    from taos.planar.simplex import simplex_state_space

    ev = np.linalg.eigvals(simplex_state_space(model, axis).A)
    osc = [e for e in ev if e.imag > 1.0 and abs(e) / (2 * math.pi) < LOAD_MODE_MAX_HZ]
    if not osc:
        return None, None
    e = min(osc, key=lambda e: -e.real / abs(e))
    return float(abs(e) / (2 * math.pi)), float(-e.real / abs(e))


def servo_figures(model: TvcModel, axis: str = "pitch") -> ServoFigures:
    """The servo's figures of ``model`` on ``axis`` (module docstring)."""
    from .merit import frequency_merit

    lab = laboratory(model)
    fm = frequency_merit(lab, axis).engine
    f_lm, z_lm = load_mode(model, axis)
    return ServoFigures(axis, position_loop(model, axis), position_loop(lab, axis), float(fm.peak_gain_db),
                        None if fm.bandwidth_3db_hz is None else float(fm.bandwidth_3db_hz), f_lm, z_lm)
