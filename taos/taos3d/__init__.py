"""TAOS: the 3-D two-actuator single-engine model (seed paper sec. 4).

One engine (Pinocchio rigid body, 3-D mass properties) on a two-half compliant gimbal (FEM
6x6 stiffness per half), two hydraulic actuators along their exact 3-D lines of action, and
spherical-bearing friction (vector forms of every planar law) between the halves. See
:mod:`.dynamics` for the formulation (massless halves condensed, implicit bearing step).

The names below load their module on first use (PEP 562), so the input checks of
:mod:`.model` (geometry, stiffness file, derived keys) run without importing the compiled
dynamics or SciPy: a bad model file is refused in a blink, before any simulation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from taos import lazy_api

if TYPE_CHECKING:
    from .calibrate import load_taos_model, taos_model, with_values
    from .model import ActuatorGeometry, GimbalParams, TaosModel, beam_half_stiffness, engine_pin_model
    from .simulate import (TaosTimeHistory, linear_state_space, simulate_taos, taos_freqresp, taos_freqresp_family,
                           two_axis_dwell)

_WHERE = {
    "ActuatorGeometry": "model", "GimbalParams": "model", "TaosModel": "model", "beam_half_stiffness": "model",
    "engine_pin_model": "model", "load_taos_model": "calibrate", "taos_model": "calibrate", "with_values": "calibrate",
    "TaosTimeHistory": "simulate", "linear_state_space": "simulate", "simulate_taos": "simulate",
    "taos_freqresp": "simulate", "taos_freqresp_family": "simulate", "two_axis_dwell": "simulate",
}

__all__ = [
    "ActuatorGeometry", "GimbalParams", "TaosModel", "TaosTimeHistory", "beam_half_stiffness",
    "engine_pin_model", "linear_state_space", "load_taos_model", "simulate_taos", "taos_freqresp", "taos_freqresp_family",
    "taos_model", "two_axis_dwell", "with_values",
]


__getattr__, __dir__ = lazy_api(__name__, {k: f".{m}" for k, m in _WHERE.items()}, globals())
