"""MASV: modal multi-engine layer (one to eight engines, their actuators, the structure's modes).

masv imports taos; taos never imports masv.

Modules: :mod:`masv.structure` (modal model, file contract, validation, static correction),
:mod:`masv.config` (TOML configuration: engines, actuators, structure, band of interest;
every key: docs/reference/masv_files.md), :mod:`masv.fe_import` (mode shapes from Universal
File 55, Nastran punch and Nastran OP2 files; the OP2 reader ``masv._op2``),
:mod:`masv.system` (assembly of taos.planar.simplex.simplex_state_space engine-axis blocks, the engines'
mass and c.g. offset, and the modes; one StateSpace of the whole, and a fast block-elimination
frequency response),
:mod:`masv.analysis` (8x8 responses, notches, coupling, closed-loop eigenvalues, loop margins,
the TVSE loop break, modes in the band of interest), :mod:`masv.plotting`, :mod:`masv.synthetic` (a
mirror-symmetric test structure), :mod:`masv.coupled` (the coupled state space with block
inputs left open), :mod:`masv.timedomain` (the nonlinear multi-engine time domain; compiled
kernel :mod:`masv._kernel`), :mod:`masv.cli` (``masv modes|freqresp|coupling|tvse|simulate``).
"""

from .analysis import (TvseLoop, actuator_loop_margins, closed_loop_eigenvalues, coupling, frequency_response,
                       modes_in_band, modes_near_bandwidth, notch_frequencies, structure_effect, tvse_loops)
from .config import ActuatorSpec, EngineSpec, MasvConfig, load_config, make_config
from .timedomain import MasvTimeHistory, simulate
from .structure import ModalStructure, load_modes, rigid_structure, validate_modes
from .system import MasvSystem, build_system, engine_axis_block

__all__ = ["ActuatorSpec", "EngineSpec", "MasvConfig", "MasvSystem", "ModalStructure", "build_system",
           "closed_loop_eigenvalues", "coupling", "engine_axis_block", "frequency_response", "load_config",
           "load_modes", "actuator_loop_margins", "make_config", "modes_near_bandwidth", "notch_frequencies",
           "rigid_structure", "structure_effect", "validate_modes", "TvseLoop", "tvse_loops", "modes_in_band",
           "MasvTimeHistory", "simulate"]
