"""Gimbal friction laws: Coulomb (switching and smooth), Dahl, LuGre, modified LuGre.

To add a law: write its scalar ``torque``/``zdot`` kernels in :mod:`._kernels` (give it an
id and dispatch it there), write a small frozen class in :mod:`._laws` with its
``steady_state`` (and ``describing_function`` if analytic), register it in ``LAWS``, and add
its steady-state and passivity tests in ``tests/test_friction.py``.
"""

from ._laws import (
    FRICTION_KEYS,
    LAWS,
    CoulombSmooth,
    CoulombSwitching,
    Dahl,
    FrictionLaw,
    LuGre,
    ModifiedLuGre,
    NoFriction,
    friction_from_table,
)

__all__ = [
    "FRICTION_KEYS", "LAWS", "CoulombSmooth", "CoulombSwitching", "Dahl", "FrictionLaw", "LuGre",
    "ModifiedLuGre", "NoFriction", "friction_from_table",
]
