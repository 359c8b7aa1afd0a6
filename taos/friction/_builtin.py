"""The built-in laws: found in this package's files, their registry entries loaded one law (or
one kernel set) at a time.

A built-in law is a parameter class (a :class:`~taos.friction.FrictionLaw` subclass, numba-free)
that names its kernels' module in its ``kernels`` class attribute, defined in :mod:`._laws` or in
a ``_params_<name>.py`` module of this package; :func:`discover` finds them all (nothing lists
them by hand: the ids, the CLI help, the docs' key reference and the tests' parametrisations
come from it). Each law's kernels are cached C callbacks declared in their own small module,
``_law_<name>.py``, whose ``ENTRIES`` holds the law's :class:`~.registry.FrictionLawEntry`
(:mod:`._law_none`, :mod:`._law_switching`, :mod:`._law_smooth`, :mod:`._law_dahl`,
:mod:`._law_lugre`; the memoryless laws share :mod:`._law_zero`): :func:`load` imports the
module of the law asked for, so a command loads (from numba's cache) only the kernels of the
law it runs, not all eighteen. The planar kernels are in :mod:`._kernels`, the spherical-bearing
ones in :mod:`._vector`; this module also holds the fit describing functions and the
parameters a fit may free (plain Python: it imports no numba). Adding a built-in law:
``docs/developer/adding_a_friction_law.md``.

Law ids are a contract of the model files and ``--friction``; the built-in ones so far:
``none``, ``coulomb-switching``, ``coulomb-smooth``, ``dahl``, ``lugre``, ``modified-lugre``
(the list is :func:`taos.friction.ids`).
"""

from __future__ import annotations

import functools
import importlib

from ..errors import InputError
from ._laws import FrictionLaw, coulomb_relay_level, dahl_angle_df

#: the modules of this package that may define built-in laws' parameter classes, besides
#: :mod:`._laws`: ``_params_<name>.py`` (numba-free; their kernels go in ``_law_<name>.py``)
PARAMS_PREFIX = "_params_"


@functools.cache
def discover() -> dict[str, type]:
    """id -> parameter class of every built-in law, in order: those of :mod:`._laws` in the
    order they are defined, then those of the ``_params_*`` modules (by file name, each in
    definition order). A built-in law's class sets ``name`` and ``kernels`` itself (not
    inherited: a subclass of a built-in law names its own kernels' module, which may be its
    parent's). Imports no numba."""
    import pkgutil

    package = importlib.import_module(__package__)
    names = ["._laws"] + sorted("." + m.name for m in pkgutil.iter_modules(package.__path__)
                                if m.name.startswith(PARAMS_PREFIX))
    out: dict[str, type] = {}
    for n in names:
        mod = importlib.import_module(n, __package__)
        for obj in vars(mod).values():
            if (isinstance(obj, type) and issubclass(obj, FrictionLaw) and obj.__module__ == mod.__name__
                    and "kernels" in vars(obj) and obj.kernels):
                if "name" not in vars(obj) or not obj.name or obj.name in out:
                    raise InputError(f"taos.friction{n}", obj.__name__, "a built-in law with its own, unique name",
                                     got=repr(obj.name))
                out[obj.name] = obj
    return out


def modules() -> dict[str, str]:
    """Built-in law id -> the module declaring its kernels and entries (``ENTRIES``); LuGre and
    the modified LuGre share one kernel set (the vibration factor is 1 at V_d = 0)."""
    return {law_id: "." + cls.kernels for law_id, cls in discover().items()}


#: the planar integrator's floating-point flags (reassociation and FMA contraction only;
#: no-NaN/no-Inf flags would remove its stability checks), which the scalar kernels were
#: compiled with when inlined there; the vector kernels keep strict IEEE arithmetic
_FM = {"reassoc", "contract", "arcp", "nsz"}


def kernel(sig_name: str):
    """The decorator declaring a built-in kernel: a numba C callback with the registry's
    signature ``sig_name`` (:data:`taos.friction.registry.KERNELS`, ``LANE_KERNELS``), cached
    on disk."""
    from numba import cfunc

    from .registry import signatures

    return cfunc(signatures()[sig_name], cache=True,
                 fastmath=_FM if sig_name in ("RATES_SIG", "LANES_SIG") else False)


def inlined(rates):
    """The Python function of the scalar C callback ``rates`` as a numba function inlined where
    it is called, with the scalar kernel's floating-point flags: a law module's lane form
    (``rates_lanes``, :data:`taos.friction.registry.LANES_SIG`) is the loop over the lanes::

        _law = inlined(my_rates)

        @kernel("LANES_SIG")
        def my_rates_lanes(v, z, t_app, P, dz, tf):
            for q in range(v.shape[0]):
                dz[q], tf[q] = _law(v[q], z[q], t_app[q], P[q])

    (a module-level function, so that numba caches it; a law without one gets the same loop
    generated, uncached, by :func:`taos.friction.registry.lanes_of`)."""
    from numba import njit

    return njit(inline="always", fastmath=_FM)(rates._pyfunc)


def load(law_id: str) -> tuple:
    """The entries declared with built-in law ``law_id`` (importing its kernels' module, which
    loads its C callbacks from numba's cache or compiles them)."""
    return importlib.import_module(modules()[law_id], __package__).ENTRIES


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
