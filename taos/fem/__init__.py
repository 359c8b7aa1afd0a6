"""FEM-derived data for the TVC models: gimbal-half stiffness matrices and thrust-structure modes.

* :mod:`taos.fem.mesh` - structured hexahedral meshes of bodies of revolution.
* :mod:`taos.fem.elasticity` - scikit-fem linear elasticity, RBE2 couplings, Guyan condensation.
* :mod:`taos.fem.gimbal` - parametric ball-and-socket gimbal, hanging / thrust load paths.
* :mod:`taos.fem.load_path` - gimbal compliance along the actuator line, implied K_L.
* :mod:`taos.fem.shift` - the share of the Green Run K_L shift the gimbal FEM explains, with its range.
* :mod:`taos.fem.verification` - FE check against beam theory (cantilevered tube).
* :mod:`taos.fem.frame`, :mod:`taos.fem.thrust_structure` - 3-D frame model and its modes.
* :mod:`taos.fem.io` - load and validate user matrices, provenance files.
* :mod:`taos.fem.build` - rebuild fem_data/ (scripts/build_fem_data.py).
"""

from .elasticity import TI_6AL_4V, Interface, Material, assemble_elasticity, guyan_condense, rigid_body_modes
from .gimbal import CONDITIONS, HALVES, CondensedHalf, GimbalGeometry, MeshSpec, condense_half, retainer_stress
from .io import (GimbalStiffness, load_gimbal_stiffness, load_stiffness_matrix, load_thrust_structure_modes,
                 validate_stiffness_matrix)
from .load_path import (LBF_PER_IN, ActuatorLine, LoadStiffnessShift, actuator_line_compliance,
                        implied_load_stiffness, stuck_gimbal_stiffness)
from .shift import ShiftShareRange, explained_share, fem_shift_share
from .thrust_structure import InterfaceModes, ThrustStructureSpec, node_names, thrust_structure_modes
from .verification import TubeCheck, cantilever_tube_check

__all__ = [
    "TI_6AL_4V", "Interface", "Material", "assemble_elasticity", "guyan_condense", "rigid_body_modes",
    "CONDITIONS", "HALVES", "CondensedHalf", "GimbalGeometry", "MeshSpec", "condense_half", "retainer_stress",
    "GimbalStiffness", "load_gimbal_stiffness", "load_stiffness_matrix", "load_thrust_structure_modes",
    "validate_stiffness_matrix", "LBF_PER_IN", "ActuatorLine", "LoadStiffnessShift", "actuator_line_compliance",
    "implied_load_stiffness", "stuck_gimbal_stiffness", "InterfaceModes", "ThrustStructureSpec", "node_names",
    "thrust_structure_modes", "TubeCheck", "cantilever_tube_check",
    "ShiftShareRange", "explained_share", "fem_shift_share",
]
