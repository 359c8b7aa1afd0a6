"""The friction-law registry: one entry per law, reachable by its id.

An entry (:class:`FrictionLawEntry`) holds everything about a law:

* ``params``: its parameter class (a frozen :class:`~taos.friction._laws.FrictionLaw`
  subclass; the fields carry their model-file key and unit kind, see
  :func:`~taos.friction._laws.param`), which also holds the law's analytic steady-state
  curve, its analytic describing function (if one exists) and its stable-step rule;
* ``rates``: the scalar kernel (planar model), a compiled C callback with the signature
  :data:`RATES_SIG` giving the bristle-state rate and the torque together (the torque of the
  bristle laws needs the rate; one call per integrator stage);
* ``rates_lanes``: the same law over n lanes in one call (the lockstep kernels: Monte Carlo
  batches, the MASV actuators), signature :data:`LANES_SIG`, ``rates_lanes(v, z, t_app, P,
  dz, tf)`` with ``v``, ``z``, ``t_app`` (n,) and ``P`` (n, NPARAM) (a pack per lane) in,
  ``dz``, ``tf`` (n,) out: lane q gets exactly ``rates(v[q], z[q], t_app[q], P[q])``, the
  scalar law inlined into a loop and compiled with the scalar kernel's floating-point flags
  (bit-identical, ``tests/test_friction_lanes.py``). Never a second copy of the law: a
  built-in law's module declares it as that loop over its scalar kernel (:func:`inlined` in
  :mod:`._builtin`, cached), and an entry without one (a law registered at run time, a
  plug-in) gets it generated here from its ``rates`` (:func:`lanes_of`);
* ``zdot3``, ``torque3``, ``bearing_step``: the vector spherical-bearing form (3-D model),
  signatures :data:`ZDOT3_SIG`, :data:`TORQUE3_SIG`, :data:`BEARING_SIG`;
* ``fit_describing_function`` (and ``fit_relay_level``, ``fit_check``): the describing
  function the fit surrogate uses (CasADi or float arithmetic), and ``fit_parameters``, the
  friction parameters a fit may free.

The compiled integrators (:mod:`taos.planar.dynamics`, :mod:`taos.taos3d.dynamics`) take the
kernels as first-class function arguments (numba ``FunctionType``): one compiled (and
cached) integrator serves every law, including a law registered at run time. Kernel
arguments (SI): relative rate ``v``/``w`` [rad/s], bristle state ``z`` [rad], its
derivative ``dz`` [rad/s] (vector form: from ``zdot3``), applied (non-friction) torque ``t_app`` [N m], packed parameter
vector ``p`` (float64, C-contiguous, the law's :meth:`pack`), chain compliance ``Kc`` (2, 2)
[rad/(N m)], trial bearing increment ``d`` [rad], step ``dt`` [s].

An unknown id stops with :class:`~taos.errors.InputError` naming it and the known ids.

Plug-ins: an installed package registers a law through the entry-point group
:data:`ENTRY_POINT_GROUP` (``taos.friction_laws``), the entry point's name being the law id and
its object a :class:`FrictionLawEntry` or a function of no argument returning one, e.g. in the
plug-in's ``pyproject.toml``::

    [project.entry-points."taos.friction_laws"]
    my-law = "my_package.friction:ENTRY"

The entry points are read (not imported) the first time the list of ids is needed or an id is
not known otherwise; a plug-in is imported when its law is first asked for (its parameter class
by :func:`params_of`, its kernels, compiled then, by :func:`get`), so ``--friction my-law``
works in every command and installed plug-ins cost nothing until used. A plug-in that fails to
import, or whose object is not an entry with its entry point's id, stops with
:class:`~taos.errors.InputError` naming the plug-in; it never shadows a built-in law.

Nothing here imports numba until a kernel is needed: the built-in laws' parameter classes are
known without their kernels (:func:`params_of`, :func:`param_classes`; model loading and
``taos info`` use these), and each built-in law's entry, whose kernels are compiled C callbacks
loaded from numba's cache, is registered on the first :func:`get` (or ``LAWS`` lookup) of that
law: a command loads the kernels of the law it runs only (:func:`load_all` loads every one).
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Callable

from ..errors import InputError

#: the kernel fields of an entry and their signature names (:func:`signatures`):
#: rates: (dz/dt [rad/s], T_f [N m]) = rates(v, z, t_app, p);
#: zdot3: (dz0, dz1) [rad/s] = zdot3(w0, w1, z0, z1, p);
#: torque3: (T0, T1) [N m] = torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p);
#: bearing_step: (w0, w1, z0, z1, T0, T1) = bearing_step(p, Kc, d0, d1, z0, z1, dt, s0)
KERNELS = {"rates": "RATES_SIG", "zdot3": "ZDOT3_SIG", "torque3": "TORQUE3_SIG", "bearing_step": "BEARING_SIG"}
#: the lane form of ``rates``: rates_lanes(v, z, t_app, P, dz, tf) -> None (``dz``, ``tf`` written)
LANE_KERNELS = {"rates_lanes": "LANES_SIG"}


@functools.cache
def signatures() -> dict:
    """The numba signatures of the kernels, by signature name (numba imported here)."""
    import warnings

    from numba import types as nt
    from numba.core.errors import NumbaExperimentalFeatureWarning

    # first-class function arguments are marked experimental in numba; they are this design
    warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)
    f8 = nt.float64
    p = nt.float64[::1]
    return {"RATES_SIG": nt.UniTuple(f8, 2)(f8, f8, f8, p),
            "ZDOT3_SIG": nt.UniTuple(f8, 2)(f8, f8, f8, f8, p),
            "TORQUE3_SIG": nt.UniTuple(f8, 2)(f8, f8, f8, f8, f8, f8, f8, f8, p),
            "BEARING_SIG": nt.UniTuple(f8, 6)(p, nt.float64[:, ::1], f8, f8, f8, f8, f8, f8),
            "LANES_SIG": nt.void(p, p, p, nt.float64[:, ::1], p, p)}


def __getattr__(name: str):
    """``RATES_SIG``, ``ZDOT3_SIG``, ``TORQUE3_SIG``, ``BEARING_SIG``, ``LANES_SIG``: the kernel
    signatures."""
    if name in KERNELS.values() or name in LANE_KERNELS.values():
        return signatures()[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True, eq=False)
class FrictionLawEntry:
    """Everything about one friction law (see the module docstring).

    ``fit_describing_function(law, X, w) -> (re, im)``: torque fundamental over relative-rate
    fundamental [N m s/rad] at relative-angle amplitude ``X`` [rad] and frequency ``w``
    [rad/s] (rate amplitude w X), in arithmetic that also takes CasADi SX (``law``'s fields
    may be symbolic in a fit); ``None`` when the fit does not support the law.
    ``fit_relay_level(law) -> a`` [N m] marks a pure relay N = a / (w X): the fit then solves
    the loop in closed form, including the held engine. ``fit_check(law, source)`` raises
    :class:`InputError` for parameter values the fit's describing function does not cover.
    ``fit_parameters``: the ``[friction]`` keys a fit may free (names of
    :data:`taos.identify.surrogate.PARAMETERS`). ``rates_lanes``: the lane form of ``rates``
    (module docstring); None: generated from ``rates`` on :func:`register`.
    """

    id: str
    params: type
    rates: object
    zdot3: object
    torque3: object
    bearing_step: object
    fit_describing_function: Callable | None = None
    fit_relay_level: Callable | None = None
    fit_check: Callable | None = None
    fit_parameters: tuple[str, ...] = ()
    builtin: bool = False
    rates_lanes: object = None


_REGISTRY: dict[str, FrictionLawEntry] = {}
_BUILTINS: dict = {"params": {}, "loader": None}
_BUILTIN_LOCK = threading.RLock()

#: the entry-point group through which installed packages add friction laws
ENTRY_POINT_GROUP = "taos.friction_laws"
#: plug-ins: entry points by id (read once, on first need) and their loaded, not yet compiled, entries
_PLUGINS: dict = {"points": None, "loaded": {}}


def _plugin_points() -> dict:
    """id -> entry point of every installed plug-in law (read once per process; a plug-in
    naming a built-in id is ignored: built-ins are never shadowed)."""
    if _PLUGINS["points"] is None:
        from importlib.metadata import entry_points

        _PLUGINS["points"] = {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)
                              if ep.name not in _builtin_params()}
    return _PLUGINS["points"]


def refresh_plugins() -> None:
    """Read the installed plug-ins again (after installing one into a running process); laws
    already registered stay."""
    import importlib

    _PLUGINS["points"] = None
    importlib.invalidate_caches()


def _plugin_entry(law_id: str) -> FrictionLawEntry | None:
    """The (uncompiled) entry of plug-in ``law_id``, importing the plug-in on first use; None
    when no installed plug-in has that id."""
    if law_id in _PLUGINS["loaded"]:
        return _PLUGINS["loaded"][law_id]
    ep = _plugin_points().get(law_id) if isinstance(law_id, str) else None
    if ep is None:
        return None
    where = f"friction plug-in {ep.value!r} ({ENTRY_POINT_GROUP})"
    try:
        obj = ep.load()
        entry = obj if isinstance(obj, FrictionLawEntry) else (obj() if callable(obj) else obj)
    except Exception as e:  # a broken plug-in is the user's input: one line naming it
        raise InputError(where, law_id, "an importable plug-in", got=f"{type(e).__name__}: {e}") from None
    if not isinstance(entry, FrictionLawEntry) or entry.id != law_id:
        raise InputError(where, law_id, f"a FrictionLawEntry with id {law_id!r} (or a function returning one)",
                         got=repr(getattr(entry, "id", type(entry).__name__)))
    _PLUGINS["loaded"][law_id] = entry
    return entry


def declare_builtins(params: dict, loader: Callable[[str], object]) -> None:
    """The built-in laws: their parameter classes by id, and the function returning the entries
    declared with a built-in law id (called on the first lookup of that law's entry, it may
    return the entries of other laws sharing its kernels; :mod:`taos.friction` declares them)."""
    _BUILTINS["params"] = dict(params)
    _BUILTINS["loader"] = loader


def _load_builtin(law_id: str) -> None:
    """Register built-in law ``law_id``'s entry (loads or compiles its C callbacks) and those
    declared with it, unless registered already."""
    with _BUILTIN_LOCK:   # threads asking for the same law at once register it once
        if law_id not in _REGISTRY and _BUILTINS["loader"] is not None:
            for e in _BUILTINS["loader"](law_id):
                if e.id not in _REGISTRY:
                    register(e, builtin=True)


def load_all() -> None:
    """Register every built-in law's entry (all their kernels: the warm-up compiles them)."""
    for law_id in _builtin_params():
        _load_builtin(law_id)


def _builtin_params() -> dict:
    return _BUILTINS["params"]


class _Laws(Mapping):
    """id -> entry, read-only; the built-in entries are registered on first lookup."""

    def __getitem__(self, law_id: str) -> FrictionLawEntry:
        if law_id not in _REGISTRY and isinstance(law_id, str) and law_id in _builtin_params():
            _load_builtin(law_id)
        if law_id not in _REGISTRY:
            plugin = _plugin_entry(law_id)
            if plugin is not None:   # compiled and stored on first use
                return register(plugin)
        return _REGISTRY[law_id]

    def __iter__(self):
        return iter(ids())

    def __len__(self) -> int:
        return len(ids())


#: id -> entry (read-only view of the registry)
LAWS = _Laws()


def _compiled(fn, sig, law_id: str, name: str):
    """A numba C callback with signature ``sig`` for ``fn`` (a CFunc, a numba dispatcher or a
    plain function that numba can compile)."""
    from numba import cfunc
    from numba.core.ccallback import CFunc

    if isinstance(fn, CFunc):
        if fn._sig != sig:
            raise InputError("friction registry", f"{law_id}.{name}", f"a kernel with signature {sig}",
                             got=str(fn._sig))
        return fn
    py = getattr(fn, "py_func", fn)
    if not callable(py):
        raise InputError("friction registry", f"{law_id}.{name}", "a numba-compilable function", got=repr(fn))
    return cfunc(sig)(py)


def lanes_of(rates):
    """The lane form (:data:`LANES_SIG`, module docstring) of the scalar C callback ``rates``
    (:data:`RATES_SIG`): its Python function inlined into a loop over the lanes, compiled with
    the same floating-point flags, so lane q's numbers are those of ``rates`` at lane q's
    arguments. Not cached on disk (a closure: a law registered at run time or a plug-in, whose
    scalar kernel is compiled at run time too; the built-in laws declare theirs, cached)."""
    from numba import cfunc, njit

    flags = {k: v for k, v in rates._compiler.targetoptions.items() if k != "cache"}
    law = njit(inline="always", **flags)(rates._pyfunc)

    def rates_lanes(v, z, t_app, P, dz, tf):
        for q in range(v.shape[0]):
            dz[q], tf[q] = law(v[q], z[q], t_app[q], P[q])

    return cfunc(signatures()["LANES_SIG"], **flags)(rates_lanes)


def register(entry: FrictionLawEntry, *, replace_existing: bool = False, builtin: bool = False) -> FrictionLawEntry:
    """Add ``entry`` under ``entry.id`` (kernels compiled to C callbacks here); returns the
    stored entry. Its parameter class must name the same id (``params.name``)."""
    if not entry.id or not isinstance(entry.id, str):
        raise InputError("friction registry", "id", "a non-empty law id", got=repr(entry.id))
    if entry.id in _REGISTRY and (not replace_existing or _REGISTRY[entry.id].builtin) or (
            not builtin and entry.id in _builtin_params()):   # built-in laws are never replaced
        raise InputError("friction registry", entry.id, "an id not yet registered", got="a duplicate")
    if getattr(entry.params, "name", None) != entry.id:
        raise InputError("friction registry", f"{entry.id}.params", f"a parameter class with name = {entry.id!r}",
                         got=repr(getattr(entry.params, "name", None)))
    compiled = {k: _compiled(getattr(entry, k), signatures()[s], entry.id, k) for k, s in KERNELS.items()}
    lanes = entry.rates_lanes
    compiled["rates_lanes"] = (lanes_of(compiled["rates"]) if lanes is None else
                               _compiled(lanes, signatures()["LANES_SIG"], entry.id, "rates_lanes"))
    stored = replace(entry, builtin=builtin, **compiled)
    _REGISTRY[entry.id] = stored
    return stored


def unregister(law_id: str) -> None:
    """Remove a law registered at run time (built-in laws stay)."""
    e = get(law_id)
    if e.builtin:
        raise InputError("friction registry", law_id, "a law registered at run time", got="a built-in law")
    del _REGISTRY[law_id]


def get(law_id: str, source: str = "friction registry", field: str = "friction.model") -> FrictionLawEntry:
    """The entry of ``law_id``; an unknown id raises :class:`InputError` naming the known ids."""
    try:
        return LAWS[law_id]
    except (KeyError, TypeError):
        raise InputError(source, field, "a friction law id, one of " + ", ".join(ids()),
                         got=repr(law_id)) from None


def ids() -> tuple[str, ...]:
    """The law ids: the built-in ones, then those registered at run time, then the installed
    plug-ins' (:data:`ENTRY_POINT_GROUP`), in order."""
    return tuple(dict.fromkeys((*_builtin_params(), *_REGISTRY, *_plugin_points())))


def param_classes() -> dict[str, type]:
    """id -> parameter class of every law known so far (built-in, registered, plug-ins already
    imported), without loading any kernel or importing any plug-in."""
    known = dict.fromkeys((*_builtin_params(), *_REGISTRY, *_PLUGINS["loaded"]))
    return {i: (_REGISTRY[i].params if i in _REGISTRY else
                _builtin_params()[i] if i in _builtin_params() else _PLUGINS["loaded"][i].params) for i in known}


def params_of(law_id: str, source: str = "friction registry", field: str = "friction.model") -> type:
    """The parameter class of ``law_id`` (no kernel is loaded; a plug-in law's package is
    imported); an unknown id raises :class:`InputError` naming the known ids."""
    if not isinstance(law_id, str):   # a TOML table or number where a name belongs
        raise InputError(source, field, "a friction law id (a string), one of " + ", ".join(ids()),
                         got=repr(law_id)[:60])
    classes = param_classes()
    if law_id in classes:
        return classes[law_id]
    plugin = _plugin_entry(law_id)
    if plugin is not None:
        return plugin.params
    raise InputError(source, field, "a friction law id, one of " + ", ".join(ids()), got=repr(law_id))


def entry_of(law) -> FrictionLawEntry:
    """The entry of a law instance (a :class:`~taos.friction._laws.FrictionLaw`, by its class's
    ``name``; the registry imports no law class: the laws import it)."""
    return get(type(law).name)
