"""TAOS: the 3-D two-actuator single-engine model (seed paper sec. 4).

One engine (Pinocchio rigid body, 3-D mass properties) on a two-half compliant gimbal (FEM
6x6 stiffness per half), two hydraulic actuators along their exact 3-D lines of action, and
spherical-bearing friction (vector forms of every planar law) between the halves. See
:mod:`.dynamics` for the formulation (massless halves condensed, implicit bearing step).
"""

from .calibrate import load_taos_model, taos_model
from .model import (
    ActuatorGeometry,
    GimbalParams,
    TaosModel,
    beam_half_stiffness,
    engine_pin_model,
)
from .simulate import (
    TaosTimeHistory,
    linear_state_space,
    simulate_taos,
    taos_freqresp,
    taos_freqresp_family,
    two_axis_dwell,
)

__all__ = [
    "ActuatorGeometry", "GimbalParams", "TaosModel", "TaosTimeHistory", "beam_half_stiffness",
    "engine_pin_model", "linear_state_space", "load_taos_model", "simulate_taos", "taos_freqresp", "taos_freqresp_family",
    "taos_model", "two_axis_dwell",
]
