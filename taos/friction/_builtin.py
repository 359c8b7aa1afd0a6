"""The built-in laws' registry entries, one law (or one kernel set) at a time.

Each built-in law's kernels are cached C callbacks declared in their own small module
(:mod:`._law_none`, :mod:`._law_switching`, :mod:`._law_smooth`, :mod:`._law_dahl`,
:mod:`._law_lugre`; the memoryless laws share :mod:`._law_zero`): :func:`load` imports the
module of the law asked for, so a command loads (from numba's cache) only the kernels of the
law it runs, not all eighteen. The planar kernels are in :mod:`._kernels`, the spherical-bearing
ones in :mod:`._vector`; this module also holds the fit describing functions and the
parameters a fit may free (plain Python: it imports no numba).

Law ids are a contract of the model files and ``--friction``: ``none``,
``coulomb-switching``, ``coulomb-smooth``, ``dahl``, ``lugre``, ``modified-lugre``.
"""

from __future__ import annotations

import importlib

from ..errors import InputError
from ._laws import coulomb_relay_level, dahl_angle_df

#: law id -> the module declaring its kernels and entries (``ENTRIES``); LuGre and the modified
#: LuGre share one kernel set (the vibration factor is 1 at V_d = 0)
MODULES = {"none": "._law_none", "coulomb-switching": "._law_switching", "coulomb-smooth": "._law_smooth",
           "dahl": "._law_dahl", "lugre": "._law_lugre", "modified-lugre": "._law_lugre"}

#: the planar integrator's floating-point flags (reassociation and FMA contraction only;
#: no-NaN/no-Inf flags would remove its stability checks), which the scalar kernels were
#: compiled with when inlined there; the vector kernels keep strict IEEE arithmetic
_FM = {"reassoc", "contract", "arcp", "nsz"}


def kernel(sig_name: str):
    """The decorator declaring a built-in kernel: a numba C callback with the registry's
    signature ``sig_name`` (:data:`taos.friction.registry.KERNELS`), cached on disk."""
    from numba import cfunc

    from .registry import signatures

    return cfunc(signatures()[sig_name], cache=True, fastmath=_FM if sig_name == "RATES_SIG" else False)


def load(law_id: str) -> tuple:
    """The entries declared with built-in law ``law_id`` (importing its kernels' module, which
    loads its C callbacks from numba's cache or compiles them)."""
    return importlib.import_module(MODULES[law_id], __package__).ENTRIES


# -- fit describing functions (rate form, at engine angle amplitude X and frequency w) ----------
def _coulomb_fit_df(law, X, w):
    return coulomb_relay_level(law.coulomb_torque_Nm) / (w * X), 0.0


def _dahl_fit_df(law, X, w):
    """Exact for Dahl (exponent 1); for LuGre its Dahl core (T_s = T_c, sigma_1 = 0, h = 1,
    where LuGre is Dahl) plus sigma_2: N = N_x / (j w) + sigma_2. The fit's defect correction
    against the full time-domain model removes the difference."""
    nx = dahl_angle_df(law.coulomb_torque_Nm, law.bristle_stiffness_Nm_per_rad, X)
    s2 = getattr(law, "viscous_damping_Nms_per_rad", 0.0)
    return nx[1] / w + s2, -nx[0] / w


def _dahl_fit_check(law, source):
    if law.dahl_exponent != 1.0:
        raise InputError(source, "friction.dahl_exponent", "1 for fits (closed-form Dahl loop)",
                         got=repr(law.dahl_exponent))


def _coulomb_relay(law):
    return coulomb_relay_level(law.coulomb_torque_Nm)


def _no_friction_df(law, X, w):
    return 0.0, 0.0


#: the fit fields of each family's entries
NONE_FIT = dict(fit_describing_function=_no_friction_df)
COULOMB_FIT = dict(fit_describing_function=_coulomb_fit_df, fit_relay_level=_coulomb_relay,
                   fit_parameters=("coulomb_torque",))
DAHL_FIT = dict(fit_describing_function=_dahl_fit_df, fit_check=_dahl_fit_check,
                fit_parameters=("coulomb_torque", "bristle_stiffness"))
LUGRE_FIT = dict(fit_describing_function=_dahl_fit_df,
                 fit_parameters=("coulomb_torque", "bristle_stiffness", "viscous_damping"))
