"""Friction-law parameter classes: fields, model-file keys, analytic properties.

Every law acts at the gimbal bearing between the two gimbal halves (planar: between the
engine and the thrust structure) and returns a torque opposing the relative rotation rate.
All fields are SI and made by :func:`param`, which records the ``[friction]`` model-file key
(the field name without the unit suffix; the value carries its unit, e.g.
``coulomb_torque = "144000 in*lbf"``), the unit kind, the packed kernel slot and whether the
parameter scales with the bearing normal load. A class is one part of its law's registry
entry (:mod:`.registry`), which also holds the compiled kernels.

Interface (a :class:`taos.descfcn.Nonlinearity`): ``law(v, z, t_app)`` gives the torque,
``law.derivative(v, z)`` the state derivative, ``law.steady_state(v)`` the analytic
steady-sliding curve, ``law.describing_function(V, w)`` the analytic describing function
where one exists (else ``None``), ``law.numeric_describing_function(V, f)`` the numeric one
by simulation, ``law.rate_describing_function(V, w)`` whichever of the two the law has, and
``law.check_step(J, dt, source)`` the explicit-step limit.

Describing functions, one convention for every law and every form: the relative rate is a sine
v = V sin(w t) (rate amplitude V [rad/s], frequency w [rad/s]; relative-angle amplitude
X = V / w), and N is the torque's fundamental over the rate's, a complex [N m s/rad]
(real part: dissipation, Re N >= 0 for a passive law; imaginary part: stiffness, negative for a
spring, -k / w). The three forms of it:

* analytic, :meth:`FrictionLaw.describing_function` ``(V, w)`` (``None`` where the law has
  none);
* numeric, :meth:`FrictionLaw.numeric_describing_function` ``(V, f)``, by simulation of the
  law's own kernel (frequency in Hz, f = w / 2 pi), for every law;
* fit, the registry entry's ``fit_describing_function(law, X, w) -> (Re N, Im N)``, in
  arithmetic that also takes CasADi symbols (optional: the fit refuses a law without it).

:meth:`FrictionLaw.rate_describing_function` is what a caller outside this package asks: the
analytic form where there is one, else the numeric one. Where a law has the analytic and the
fit form, they agree (``tests/test_friction.py`` checks it over the registry).

References
----------
* D. Karnopp, "Computer simulation of stick-slip friction in mechanical dynamic systems",
  J. Dyn. Sys., Meas., Control 107 (1985) 100-103.
* P. R. Dahl, "A solid friction model", Aerospace Corp. TOR-0158(3107-18)-1, 1968.
* C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, "A new model for control of
  systems with friction", IEEE Trans. Automatic Control 40(3) (1995) 419-425.
* N. Barabanov, R. Ortega, "Necessary and sufficient conditions for passivity of the LuGre
  friction model", IEEE TAC 45(4) (2000) 830-832.
"""

from __future__ import annotations

import abc
import dataclasses
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..descfcn import Nonlinearity, coulomb_describing_function, dahl_angle_df, simulated_describing_function
from ..descfcn import coulomb_relay_level  # noqa: F401  (._builtin imports it from here)
from ..errors import InputError
from ..units import to_si
from . import _slots as K
from . import registry


def param(default: float, key: str, kind: str, slot: int | None, *, torque_like: bool = False, meaning: str = ""):
    """A law parameter field: its model-file ``key`` (in the ``[friction]`` table), pint unit
    ``kind`` (:func:`taos.units.to_si`), ``slot`` in the packed kernel vector (``None``: not
    packed), ``torque_like`` (a torque or torque per angle/rate: scaled with the bearing
    normal load by :meth:`FrictionLaw.scaled`) and ``meaning``, the key's one-line description
    in the model-file key reference (``docs/reference/model_files.md`` is generated from it; a
    key several laws share is described once, by the first law declaring it with a meaning)."""
    return field(default=default, metadata={"key": key, "kind": kind, "slot": slot, "torque_like": torque_like,
                                            "meaning": meaning})


def _info(f: dataclasses.Field) -> dict:
    return f.metadata


def friction_keys() -> frozenset[str]:
    """Every key a ``[friction]`` table may hold (besides ``model``): the keys of every
    registered law."""
    return frozenset(_info(f)["key"] for cls in registry.param_classes().values() for f in dataclasses.fields(cls))


@dataclass(frozen=True)
class FrictionLaw(Nonlinearity):
    """Base class: a gimbal friction law's parameters (fields made with :func:`param`, SI)
    and its analytic properties. Subclasses set ``name`` (the registry id) and
    ``has_state``; the compiled kernels live in the law's registry entry (:attr:`entry`)."""

    name: ClassVar[str] = ""
    has_state: ClassVar[bool] = False
    has_friction: ClassVar[bool] = True
    #: built-in laws only: the module of :mod:`taos.friction` declaring this law's kernels and
    #: registry entry (its ``ENTRIES``), e.g. ``"_law_dahl"``; a class with it, defined in
    #: ``_laws.py`` or a ``_params_*.py`` module of the package, is a built-in law
    #: (:func:`taos.friction._builtin.discover`). Empty for laws registered at run time or by plug-ins.
    kernels: ClassVar[str] = ""

    coulomb_torque_Nm: float = param(0.0, "coulomb_torque", "torque", K.SLOT_TC, torque_like=True,
                                     meaning="Coulomb (sliding) friction torque T_c")

    @property
    def entry(self) -> registry.FrictionLawEntry:
        """This law's registry entry (kernels, vector form, fit describing function)."""
        return registry.entry_of(self)

    # -- packing for the compiled kernels -------------------------------------------------
    def pack(self) -> np.ndarray:
        """Packed float64 parameter vector for the kernels (:mod:`taos.friction._kernels`
        slots; the switching law's breakaway slot holds max(T_s, T_c))."""
        p = np.zeros(K.NPARAM)
        p[K.SLOT_TS] = self.coulomb_torque_Nm
        p[K.SLOT_VS] = 1.0
        p[K.SLOT_DELTA] = 2.0
        p[K.SLOT_ALPHA] = 1.0
        for f in dataclasses.fields(self):
            if _info(f)["slot"] is not None:
                p[_info(f)["slot"]] = getattr(self, f.name)
        return p

    def scaled(self, factor: float) -> "FrictionLaw":
        """The law with every torque-like parameter (torque levels, bristle stiffness and
        damping, viscous and stick damping) times ``factor``: friction proportional to a
        normal load, pre-sliding angle T_c / sigma_0 unchanged (every law is homogeneous of
        degree one in these, so the torque scales and nothing else)."""
        return dataclasses.replace(self, **{f.name: getattr(self, f.name) * factor
                                            for f in dataclasses.fields(self) if _info(f)["torque_like"]})

    # -- the interface ----------------------------------------------------------------------
    def __call__(self, v: float, z: float = 0.0, t_app: float = 0.0) -> float:
        """Friction torque [N m] at relative rate ``v`` [rad/s], state ``z`` [rad] and applied
        torque ``t_app`` [N m]."""
        return float(self.entry.rates(float(v), float(z), float(t_app), self.pack())[1])

    def derivative(self, v: float, z: float) -> float:
        """dz/dt [rad/s] (0 for memoryless laws)."""
        return float(self.entry.rates(float(v), float(z), 0.0, self.pack())[0])

    @abc.abstractmethod
    def steady_state(self, v: np.ndarray) -> np.ndarray:
        """Torque [N m] under steady sliding at constant rate ``v`` [rad/s] (analytic)."""

    def describing_function(self, rate_amplitude: float, omega_rad_s: float | None = None) -> complex | None:
        """Analytic describing function from a rate sinusoid V sin(w t) of amplitude
        ``rate_amplitude`` V [rad/s] and frequency ``omega_rad_s`` w [rad/s] (needed only by
        laws with memory) to the torque fundamental [N m s/rad], or ``None`` if there is none."""
        return None

    def check_step(self, inertia_kgm2: float, dt_s: float, source: str, section: str = "friction") -> None:
        """Refuse an explicit integration step ``dt_s`` [s] this law cannot be integrated with
        on a joint of inertia ``inertia_kgm2`` [kg m^2] (raise :class:`InputError`)."""

    def response(self, v: np.ndarray, dt: float, z0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Torque [N m] and state [rad] for a prescribed rate history ``v`` [rad/s] every ``dt`` [s]."""
        from ._kernels import prescribed_rate_response

        return prescribed_rate_response(self.entry.rates, self.pack(), np.ascontiguousarray(v, float),
                                          float(dt), float(z0))

    def numeric_describing_function(self, rate_amplitude: float, freq_hz: float,
                                    cycles: int = 6, steps_per_cycle: int = 4000) -> complex:
        """Describing function by simulation: v = V sin(w t), fundamental of the torque over
        the last whole cycle, divided by V (:func:`taos.descfcn.simulated_describing_function`).
        [N m s/rad]"""
        return simulated_describing_function(lambda v, dt: self.response(v, dt)[0], rate_amplitude, freq_hz,
                                             cycles, steps_per_cycle)

    def rate_describing_function(self, rate_amplitude: float, omega_rad_s: float) -> complex:
        """The law's describing function in the one convention (module docstring): rate
        amplitude V [rad/s], frequency w [rad/s] -> torque fundamental over rate fundamental
        [N m s/rad]; the analytic one (:meth:`describing_function`) where the law has one, else
        by simulation (:meth:`numeric_describing_function`)."""
        exact = self.describing_function(rate_amplitude, omega_rad_s)
        if exact is not None:
            return complex(exact)
        return self.numeric_describing_function(rate_amplitude, omega_rad_s / (2.0 * math.pi))

    # -- construction -----------------------------------------------------------------------
    @classmethod
    def from_table(cls, table: dict, source: str, section: str = "friction") -> "FrictionLaw":
        """Build from a ``[friction]`` table; keys this law does not use are ignored."""
        kwargs = {}
        for f in dataclasses.fields(cls):
            key, kind = _info(f)["key"], _info(f)["kind"]
            if key in table:
                nonneg = kind != "dimensionless"
                kwargs[f.name] = to_si(table[key], kind, source=source, field=f"{section}.{key}",
                                       nonnegative=nonneg)
            elif key == "coulomb_torque":
                raise InputError(source, f"{section}.{key}", "a torque with its unit, like '144000 in*lbf'",
                                 got="nothing (key missing)")
        if "static_torque_Nm" in {f.name for f in dataclasses.fields(cls)} and "static_torque" not in table:
            kwargs["static_torque_Nm"] = kwargs["coulomb_torque_Nm"]
        law = cls(**kwargs)
        law.validate(source, section)
        return law

    def validate(self, source: str, section: str = "friction") -> None:
        """Range checks beyond the unit parse; raise :class:`InputError`."""


@dataclass(frozen=True)
class NoFriction(FrictionLaw):
    """No gimbal friction: T_f = 0."""

    name: ClassVar[str] = "none"
    kernels: ClassVar[str] = "_law_none"
    has_friction: ClassVar[bool] = False

    def steady_state(self, v):
        return np.zeros_like(np.asarray(v, float))


@dataclass(frozen=True)
class CoulombSwitching(FrictionLaw):
    """Coulomb friction, stick-slip switching form (Karnopp 1985).

    Equations (rate v [rad/s], applied torque T_a [N m])::

        |v| <  v_stick :  T_f = sat(T_a + c_stick v, max(T_s, T_c))   (stuck)
        |v| >= v_stick :  T_f = T_c sign(v)                        (sliding)

    While stuck the friction balances the applied torque, so the joint neither chatters nor
    drifts (``c_stick`` bleeds off the residual rate with time constant J / c_stick). The stick
    band must exceed the rate change of one integration step, dt (T_c + T_s) / J; the
    simulator checks it. Passivity: T_f v >= 0 while sliding; inside the band the power is at
    most T_s v_stick.
    """

    name: ClassVar[str] = "coulomb-switching"
    kernels: ClassVar[str] = "_law_switching"

    static_torque_Nm: float = param(0.0, "static_torque", "torque", K.SLOT_TS, torque_like=True,
                                    meaning="static (breakaway) torque T_s of the Stribeck curve")
    stick_velocity_rad_s: float = param(1e-3, "stick_velocity", "angular_velocity", K.SLOT_VEPS,
                                        meaning="stick band of the switching Coulomb law")
    stick_damping_Nms_per_rad: float = param(0.0, "stick_damping", "rotational_damping", K.SLOT_CSTICK,
                                             torque_like=True,
                                             meaning="damping that bleeds the residual rate while stuck")

    def steady_state(self, v):
        return self.coulomb_torque_Nm * np.sign(np.asarray(v, float))

    def describing_function(self, rate_amplitude, omega_rad_s=None):
        return coulomb_describing_function(self.coulomb_torque_Nm, rate_amplitude)

    def check_step(self, inertia_kgm2, dt_s, source, section="friction"):
        """The stick band must exceed one step's rate change dt (max(T_s, T_c) + T_c) / J, and
        the stick damping must not overshoot: c_stick dt / J <= 1."""
        dv = dt_s * (max(self.static_torque_Nm, self.coulomb_torque_Nm) + self.coulomb_torque_Nm) / inertia_kgm2
        if dv >= self.stick_velocity_rad_s:
            raise InputError(source, f"{section}.stick_velocity",
                             f"a stick band above one step's rate change {dv:.3g} rad/s (or a smaller step)")
        if self.stick_damping_Nms_per_rad * dt_s / inertia_kgm2 > 1.0:
            raise InputError(source, f"{section}.stick_damping", "c_stick dt / J below 1 (or a smaller step)")

    def validate(self, source, section="friction"):
        if not self.stick_velocity_rad_s > 0:
            raise InputError(source, f"{section}.stick_velocity", "a positive angular velocity")


@dataclass(frozen=True)
class CoulombSmooth(FrictionLaw):
    """Coulomb friction, smooth regularised form.

    T_f = T_c v / sqrt(v^2 + v_eps^2): C-infinity, odd, monotone, |T_f| < T_c, slope T_c/v_eps
    at v = 0 (a viscous damper below v_eps). Explicit steps are stable while
    dt T_c / (v_eps J) < 2 (the simulator checks it). Passive: T_f v >= 0 for all v.
    """

    name: ClassVar[str] = "coulomb-smooth"
    kernels: ClassVar[str] = "_law_smooth"

    regularization_velocity_rad_s: float = param(1e-3, "regularization_velocity", "angular_velocity", K.SLOT_VEPS,
                                                 meaning="regularisation rate of the smooth Coulomb law")

    def steady_state(self, v):
        v = np.asarray(v, float)
        e = self.regularization_velocity_rad_s
        return self.coulomb_torque_Nm * v / np.sqrt(v * v + e * e)

    def describing_function(self, rate_amplitude, omega_rad_s=None):
        # exact for v_eps -> 0; the regularisation changes it by O((v_eps/V)^2)
        return coulomb_describing_function(self.coulomb_torque_Nm, rate_amplitude)

    def check_step(self, inertia_kgm2, dt_s, source, section="friction"):
        """Explicit steps on the regularised slope T_c / v_eps are stable while
        dt T_c / (v_eps J) <= 2."""
        if dt_s * self.coulomb_torque_Nm / (self.regularization_velocity_rad_s * inertia_kgm2) > 2.0:
            raise InputError(source, f"{section}.regularization_velocity",
                             "dt T_c / (v_eps J) below 2 (or a smaller step)")

    def validate(self, source, section="friction"):
        if not self.regularization_velocity_rad_s > 0:
            raise InputError(source, f"{section}.regularization_velocity", "a positive angular velocity")


@dataclass(frozen=True)
class Dahl(FrictionLaw):
    """Dahl (1968) friction: a spring in pre-sliding, Coulomb in sliding.

    dz/dt = v |1 - sigma_0 z sgn(v)/T_c|^alpha sgn(1 - sigma_0 z sgn(v)/T_c),  T_f = sigma_0 z.

    Pre-sliding stiffness sigma_0 [N m/rad], exponent alpha >= 1 (alpha = 1 is the usual
    choice). Steady state T_c sgn(v). Passive: with |z| <= T_c/sigma_0 (the invariant set),
    T_f v >= d/dt(sigma_0 z^2 / 2).
    """

    name: ClassVar[str] = "dahl"
    kernels: ClassVar[str] = "_law_dahl"
    has_state: ClassVar[bool] = True

    bristle_stiffness_Nm_per_rad: float = param(0.0, "bristle_stiffness", "rotational_stiffness", K.SLOT_SIGMA0,
                                                torque_like=True, meaning="bristle (pre-sliding) stiffness sigma_0")
    dahl_exponent: float = param(1.0, "dahl_exponent", "dimensionless", K.SLOT_ALPHA,
                                 meaning="Dahl shape exponent alpha")

    def steady_state(self, v):
        return self.coulomb_torque_Nm * np.sign(np.asarray(v, float))

    def describing_function(self, rate_amplitude, omega_rad_s=None):
        """Exact for exponent 1 (the closed-form hysteresis loop, :func:`dahl_angle_df`):
        N = N_x(V / w) / (j w); ``None`` for other exponents or without ``omega_rad_s``."""
        if self.dahl_exponent != 1.0 or omega_rad_s is None:
            return None
        nr, ni = dahl_angle_df(self.coulomb_torque_Nm, self.bristle_stiffness_Nm_per_rad,
                               rate_amplitude / omega_rad_s)
        return complex(float(nr), float(ni)) / (1j * omega_rad_s)

    def validate(self, source, section="friction"):
        if not self.bristle_stiffness_Nm_per_rad > 0:
            raise InputError(source, f"{section}.bristle_stiffness",
                             "a positive rotational stiffness for the Dahl law")
        if self.dahl_exponent < 1.0:
            raise InputError(source, f"{section}.dahl_exponent", "a number >= 1")


@dataclass(frozen=True)
class LuGre(FrictionLaw):
    """LuGre friction (Canudas de Wit et al. 1995), with a rational bristle-damping decay.

    dz/dt = v - sigma_0 |v| z / g(v),  g(v) = T_c + (T_s - T_c) exp(-|v/v_s|^delta),
    T_f = sigma_0 z + sigma_1(v) dz/dt + sigma_2 v,  sigma_1(v) = sigma_1 v_1 / (v_1 + |v|)
    (constant if v_1 = 0).

    Steady state g(v) sgn(v) + sigma_2 v. Passivity (Barabanov & Ortega 2000; from the
    storage sigma_0 z^2/2): the power balance is a quadratic form in (z, v) that is
    non-negative when |v| sigma_1(v)^2 <= 4 g(v) (sigma_1(v) + sigma_2); :meth:`passive_at`
    evaluates it. With the rational decay |v| sigma_1(v) < sigma_1 v_1, so it holds at every
    rate while sigma_1 v_1 <= 4 min g (and, for the modified law, where h(v) >= (2/pi) |v| / V_d
    below V_d, while sigma_1 <= 8 min G / (pi V_d)); :meth:`passivity_ratios` gives both
    ratios (at most 1: passive). Constant sigma_1 (v_1 = 0) is not passive above
    4 g / sigma_1 unless sigma_2 covers it.

    Incremental condition: in series with a compliance and a (nearly) massless part (the
    3-D model's gimbal bearing, :mod:`taos.friction._vector`) the torque at a frozen bristle
    state must not fall with the rate, dT_f/dv >= 0; above V_d that is
    (1 - sigma_0 z sgn(v) / g) d(|v| sigma_1(v))/d|v| + sigma_2 >= 0, so |v| sigma_1(v) must
    not decrease. The decay exp(-(v/v_1)^2) of Canudas de Wit et al. (1995, eq. 9) fails it
    above v_1 / sqrt 2 (|v| sigma_1(v) peaks there and falls to 0): the bearing's equations
    then have impasse points (the slip jumps, with no step-converged solution over a Green
    Run; docs/theory/taos3d.md). The rational decay keeps the purpose of the exponential
    (sigma_1(v) -> 0 in sliding, so the law is passive at every rate) while
    d(|v| sigma_1(v))/d|v| = sigma_1 v_1^2 / (v_1 + |v|)^2 > 0: it replaces it in this
    project, for ``lugre`` and ``modified-lugre`` alike (one definition,
    :func:`taos.friction._kernels._sigma1`; the parameters sigma_1 and v_1 keep their names
    and meaning: sigma_1(0) = sigma_1, and v_1 the rate where the damping has decayed to
    sigma_1 / 2, 1/e with the exponential).
    """

    name: ClassVar[str] = "lugre"
    kernels: ClassVar[str] = "_law_lugre"
    has_state: ClassVar[bool] = True

    static_torque_Nm: float = param(0.0, "static_torque", "torque", K.SLOT_TS, torque_like=True)
    stribeck_velocity_rad_s: float = param(1e-3, "stribeck_velocity", "angular_velocity", K.SLOT_VS,
                                           meaning="Stribeck velocity v_s")
    stribeck_exponent: float = param(2.0, "stribeck_exponent", "dimensionless", K.SLOT_DELTA,
                                     meaning="Stribeck shape exponent delta")
    bristle_stiffness_Nm_per_rad: float = param(0.0, "bristle_stiffness", "rotational_stiffness", K.SLOT_SIGMA0,
                                                torque_like=True)
    bristle_damping_Nms_per_rad: float = param(0.0, "bristle_damping", "rotational_damping", K.SLOT_SIGMA1,
                                               torque_like=True, meaning="bristle damping sigma_1")
    viscous_damping_Nms_per_rad: float = param(0.0, "viscous_damping", "rotational_damping", K.SLOT_SIGMA2,
                                               torque_like=True, meaning="viscous friction sigma_2")
    damping_decay_velocity_rad_s: float = param(0.0, "damping_decay_velocity", "angular_velocity", K.SLOT_V1,
                                                meaning="bristle-damping decay rate v_1: sigma_1(v) = "
                                                "sigma_1 v_1/(v_1 + |v|), half at v_1")

    def _g(self, v):
        v = np.abs(np.asarray(v, float))
        tc, ts = self.coulomb_torque_Nm, self.static_torque_Nm
        return tc + (ts - tc) * np.exp(-(v / self.stribeck_velocity_rad_s) ** self.stribeck_exponent)

    def _h(self, v):
        return np.ones_like(np.asarray(v, float))

    def _sigma1(self, v):
        """sigma_1(v) = sigma_1 v_1 / (v_1 + |v|) [N m s/rad] (the kernels' ``_sigma1``)."""
        v = np.abs(np.asarray(v, float))
        v1 = self.damping_decay_velocity_rad_s
        s1 = self.bristle_damping_Nms_per_rad
        return s1 * v1 / (v1 + v) if v1 > 0 else s1 + 0 * v

    def steady_state(self, v):
        v = np.asarray(v, float)
        return self._g(v) * self._h(v) * np.sign(v) + self.viscous_damping_Nms_per_rad * v

    def passive_at(self, v) -> np.ndarray:
        """True where the passivity condition |v| sigma_1(v)^2 <= 4 g(v) (sigma_1(v) + sigma_2)
        holds, at rates ``v`` [rad/s]."""
        v = np.asarray(v, float)
        s1 = self._sigma1(v)
        g = self._g(v) * self._h(v)
        return np.abs(v) * s1 ** 2 <= 4.0 * g * (s1 + self.viscous_damping_Nms_per_rad) + 1e-300

    def passivity_ratios(self) -> tuple[float, float]:
        """(sigma_1 v_1 / (4 g_min), sigma_1 pi V_d / (8 g_min)), g_min = min(T_s, T_c) the
        Stribeck curve's lowest level: both at most 1 make the law passive at every rate
        (sufficient, sigma_2 ignored; class docstring). The first is infinite for a constant
        sigma_1 > 0 (v_1 = 0); the second is 0 without vibration (V_d = 0, plain LuGre)."""
        gmin = min(self.static_torque_Nm, self.coulomb_torque_Nm)
        s1, v1 = self.bristle_damping_Nms_per_rad, self.damping_decay_velocity_rad_s
        vd = getattr(self, "vibration_velocity_rad_s", 0.0)
        first = s1 * v1 / (4.0 * gmin) if v1 > 0 else (math.inf if s1 > 0 else 0.0)
        return first, s1 * math.pi * vd / (8.0 * gmin)

    def validate(self, source, section="friction"):
        if not self.bristle_stiffness_Nm_per_rad > 0:
            raise InputError(source, f"{section}.bristle_stiffness",
                             f"a positive rotational stiffness for the {self.name} law")
        if not self.stribeck_velocity_rad_s > 0:
            raise InputError(source, f"{section}.stribeck_velocity", "a positive angular velocity")
        if not self.static_torque_Nm > 0:  # g(0) = T_s: the bristle relaxation divides by it
            raise InputError(source, f"{section}.static_torque", "a positive torque")


@dataclass(frozen=True)
class ModifiedLuGre(LuGre):
    """Modified LuGre for a vibration environment (this project's documented form).

    The LuGre equations with g(v) = G(v) h(v), where G is the Stribeck curve above (the
    bearing's own, with a tunable shape exponent delta; a model file holds T_s >= T_c as for
    every law, :func:`taos.bounds.check_model_bounds`: the vibration lowers the friction felt at
    small rates through h, not through a Stribeck curve rising with the rate) and

        h(v) = (2/pi) asin(min(1, |v| / V_d))

    is the average of a Coulomb law over a superposed vibration of rate amplitude V_d
    [rad/s]: friction becomes viscous-like below V_d, with slope (2/pi) T_s / V_d at v = 0
    (bristle relaxation rate sigma_0 pi V_d / (2 T_s) there, finite). With V_d = 0 the law is
    exactly LuGre (h = 1); the packed kernels are identical. Basis: the averaging argument of
    DESIGN.md and the paper's companion work on vibration-reduced stiction (ref. 2 of the
    seed paper). Passivity as for LuGre with g including h (below V_d the bound
    sigma_1 <= 8 min G / (pi V_d) of :meth:`LuGre.passivity_ratios`).
    """

    name: ClassVar[str] = "modified-lugre"
    kernels: ClassVar[str] = "_law_lugre"

    vibration_velocity_rad_s: float = param(0.0, "vibration_velocity", "angular_velocity", K.SLOT_VD,
                                            meaning="vibration rate amplitude V_d of the modified LuGre law")

    def _h(self, v):
        v = np.abs(np.asarray(v, float))
        vd = self.vibration_velocity_rad_s
        if vd <= 0:
            return np.ones_like(v)
        return (2.0 / math.pi) * np.arcsin(np.minimum(1.0, v / vd))


def friction_from_table(table: dict, source: str, model: str | None = None,
                        section: str = "friction") -> FrictionLaw:
    """Build the law named by ``table['model']`` (or ``model``, the ``--friction`` override,
    which keeps the table's torque levels and parameters) from its registry entry."""
    name = model if model is not None else table.get("model")
    params = registry.params_of(name, source if model is None else "command line",
                                f"{section}.model" if model is None else "--friction")
    from ..errors import check_keys

    from .bounds import check_friction_law, check_friction_values

    check_keys(table, set(friction_keys()) | {"model"}, source, section)
    check_friction_values(table, source, section)   # issue 40: every key within its physical bound
    law = params.from_table(table, source, section)
    check_friction_law(law, source, section)
    return law
