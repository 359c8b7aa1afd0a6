"""Gimbal friction laws: Coulomb (switching and smooth), Dahl, LuGre, modified LuGre.

Every law has one entry in :mod:`taos.friction.registry`, reachable by its id
(``taos.friction.get("lugre")``, ``taos.friction.LAWS``): its parameter class (fields with
model-file keys and units, steady-state curve, analytic describing function, stable-step
rule), its scalar kernels (planar model), its vector spherical-bearing kernels (3-D model)
and its fit describing function. The planar and 3-D integrators, the describing-function
tools, the fit surrogate and the step check all ask the entry; an unknown id stops with
:class:`~taos.errors.InputError`.

To add a built-in law (files in this folder only; ``docs/developer/adding_a_friction_law.md``):
write a frozen parameter class deriving :class:`FrictionLaw` with fields made by :func:`param`,
its ``steady_state`` (and ``describing_function``, ``check_step`` where they apply), naming its
id (``name``) and its kernels' module (``kernels``), in ``_laws.py`` or a ``_params_<name>.py``
module (:func:`._builtin.discover` finds it); write its kernels with the registry's signatures
(``rates``, ``zdot3``, ``torque3``, ``bearing_step``; numba C callbacks) and its
:class:`FrictionLawEntry` in ``_law_<name>.py`` (``ENTRIES``; see the built-in ones and the
helpers in :mod:`._vector`). A law of your own code: the same class and kernels, and
:func:`register` with a :class:`FrictionLawEntry`. The ids (:func:`ids`) feed the command-line
help, the docs' key reference and the tests parametrised over the registry, which then cover it.
"""

from ._laws import (
    CoulombSmooth,
    CoulombSwitching,
    Dahl,
    FrictionLaw,
    LuGre,
    ModifiedLuGre,
    NoFriction,
    friction_from_table,
    friction_keys,
    param,
)
from ..descfcn import coulomb_describing_function, dahl_angle_df
from .registry import LAWS, FrictionLawEntry, declare_builtins, get, ids, param_classes, params_of, register, unregister


def _builtin_entries(law_id: str) -> tuple:
    from ._builtin import load  # the entries and kernels of one built-in law, on its first use

    return load(law_id)


def _builtin_params() -> dict:
    from ._builtin import discover  # the built-in laws' parameter classes, found in this package

    return discover()


declare_builtins(_builtin_params(), _builtin_entries)


def __getattr__(name: str):
    """``coeff_bearing_step`` (a numba kernel) is imported on first use: loading a model does not
    import numba."""
    if name == "coeff_bearing_step":
        from ._vector import coeff_bearing_step
        return coeff_bearing_step
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "LAWS", "CoulombSmooth", "CoulombSwitching", "Dahl", "FrictionLaw", "FrictionLawEntry", "LuGre", "coeff_bearing_step",
    "ModifiedLuGre", "NoFriction", "coulomb_describing_function", "dahl_angle_df", "friction_from_table",
    "friction_keys", "get", "ids", "param", "param_classes", "params_of", "register", "unregister",
]
