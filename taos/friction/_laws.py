"""Friction laws as small frozen classes over the scalar kernels in :mod:`._kernels`.

Every law acts at the gimbal bearing between the two gimbal halves (planar: between the
engine and the thrust structure) and returns a torque opposing the relative rotation rate.
All fields are SI; the TOML keys (``[friction]`` table) are the field names without the
unit suffix and carry their unit in the value, e.g. ``coulomb_torque = "144000 in*lbf"``.

Interface (python-control ``descfcn`` style): ``law(v, z, t_app)`` gives the torque,
``law.derivative(v, z)`` the state derivative, ``law.steady_state(v)`` the analytic
steady-sliding curve, ``law.describing_function(V)`` the analytic describing function
where one exists (else ``None``) and ``law.numeric_describing_function(V, f)`` the
numeric one by simulation.

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
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import InputError
from ..units import to_si
from . import _kernels as K

# field name -> (TOML key, unit kind, packed slot)
_FIELD_INFO: dict[str, tuple[str, str, int]] = {
    "coulomb_torque_Nm": ("coulomb_torque", "torque", K.SLOT_TC),
    "static_torque_Nm": ("static_torque", "torque", K.SLOT_TS),
    "stribeck_velocity_rad_s": ("stribeck_velocity", "angular_velocity", K.SLOT_VS),
    "stribeck_exponent": ("stribeck_exponent", "dimensionless", K.SLOT_DELTA),
    "bristle_stiffness_Nm_per_rad": ("bristle_stiffness", "rotational_stiffness", K.SLOT_SIGMA0),
    "bristle_damping_Nms_per_rad": ("bristle_damping", "rotational_damping", K.SLOT_SIGMA1),
    "viscous_damping_Nms_per_rad": ("viscous_damping", "rotational_damping", K.SLOT_SIGMA2),
    "vibration_velocity_rad_s": ("vibration_velocity", "angular_velocity", K.SLOT_VD),
    "damping_decay_velocity_rad_s": ("damping_decay_velocity", "angular_velocity", K.SLOT_V1),
    "stick_velocity_rad_s": ("stick_velocity", "angular_velocity", K.SLOT_VEPS),
    "stick_damping_Nms_per_rad": ("stick_damping", "rotational_damping", K.SLOT_CSTICK),
    "regularization_velocity_rad_s": ("regularization_velocity", "angular_velocity", K.SLOT_VEPS),
    "dahl_exponent": ("dahl_exponent", "dimensionless", K.SLOT_ALPHA),
}
#: Every key a ``[friction]`` table may hold (besides ``model``).
FRICTION_KEYS = frozenset(info[0] for info in _FIELD_INFO.values())


@dataclass(frozen=True)
class FrictionLaw(abc.ABC):
    """Base class: a gimbal friction law. Subclasses set ``name`` and ``fid``."""

    name: ClassVar[str] = ""
    fid: ClassVar[int] = -1
    has_state: ClassVar[bool] = False

    coulomb_torque_Nm: float = 0.0

    # -- packing for the compiled kernels -------------------------------------------------
    def pack(self) -> np.ndarray:
        """Packed float64 parameter vector for :mod:`taos.friction._kernels` (the switching
        law's breakaway slot holds max(T_s, T_c))."""
        p = np.zeros(K.NPARAM)
        p[K.SLOT_TS] = self.coulomb_torque_Nm
        p[K.SLOT_VS] = 1.0
        p[K.SLOT_DELTA] = 2.0
        p[K.SLOT_ALPHA] = 1.0
        for f in dataclasses.fields(self):
            p[_FIELD_INFO[f.name][2]] = getattr(self, f.name)
        return p

    # -- the interface ----------------------------------------------------------------------
    def __call__(self, v: float, z: float = 0.0, t_app: float = 0.0) -> float:
        """Friction torque [N m] at relative rate ``v`` [rad/s], state ``z`` [rad] and applied
        torque ``t_app`` [N m]."""
        p = self.pack()
        dz = K.zdot(self.fid, float(v), float(z), p)
        return float(K.torque(self.fid, float(v), float(z), dz, float(t_app), p))

    def derivative(self, v: float, z: float) -> float:
        """dz/dt [rad/s] (0 for memoryless laws)."""
        return float(K.zdot(self.fid, float(v), float(z), self.pack()))

    @abc.abstractmethod
    def steady_state(self, v: np.ndarray) -> np.ndarray:
        """Torque [N m] under steady sliding at constant rate ``v`` [rad/s] (analytic)."""

    def describing_function(self, rate_amplitude: float) -> complex | None:
        """Analytic describing function from a rate sinusoid of amplitude ``rate_amplitude``
        [rad/s] to the torque fundamental [N m s/rad], or ``None`` if there is none."""
        return None

    def response(self, v: np.ndarray, dt: float, z0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Torque [N m] and state [rad] for a prescribed rate history ``v`` [rad/s] every ``dt`` [s]."""
        return K.prescribed_rate_response(self.fid, self.pack(), np.ascontiguousarray(v, float),
                                          float(dt), float(z0))

    def numeric_describing_function(self, rate_amplitude: float, freq_hz: float,
                                    cycles: int = 6, steps_per_cycle: int = 4000) -> complex:
        """Describing function by simulation: v = V sin(w t), fundamental of the torque over
        the last whole cycle, divided by V. [N m s/rad]"""
        n = cycles * steps_per_cycle + 1
        dt = 1.0 / (freq_hz * steps_per_cycle)
        t = np.arange(n) * dt
        w = 2 * math.pi * freq_hz
        tq, _ = self.response(rate_amplitude * np.sin(w * t), dt)
        last = slice(n - 1 - steps_per_cycle, n - 1)
        s = np.sin(w * t[last])
        c = np.cos(w * t[last])
        a = 2.0 * np.mean(tq[last] * s)
        b = 2.0 * np.mean(tq[last] * c)
        return complex(a, b) / rate_amplitude

    # -- construction -----------------------------------------------------------------------
    @classmethod
    def from_table(cls, table: dict, source: str, section: str = "friction") -> "FrictionLaw":
        """Build from a ``[friction]`` table; keys this law does not use are ignored."""
        kwargs = {}
        for f in dataclasses.fields(cls):
            key, kind, _ = _FIELD_INFO[f.name]
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


def coulomb_describing_function(coulomb_torque_Nm: float, rate_amplitude: float) -> complex:
    """4 T_c / (pi V): fundamental of T_c sign(V sin wt) over V [N m s/rad] (relay describing
    function, Gelb & Vander Velde, Multiple-Input Describing Functions, 1968)."""
    return complex(4.0 * coulomb_torque_Nm / (math.pi * rate_amplitude), 0.0)


@dataclass(frozen=True)
class NoFriction(FrictionLaw):
    """No gimbal friction: T_f = 0."""

    name: ClassVar[str] = "none"
    fid: ClassVar[int] = K.ID_NONE

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
    fid: ClassVar[int] = K.ID_COULOMB_SWITCHING

    static_torque_Nm: float = 0.0
    stick_velocity_rad_s: float = 1e-3
    stick_damping_Nms_per_rad: float = 0.0

    def steady_state(self, v):
        return self.coulomb_torque_Nm * np.sign(np.asarray(v, float))

    def describing_function(self, rate_amplitude):
        return coulomb_describing_function(self.coulomb_torque_Nm, rate_amplitude)

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
    fid: ClassVar[int] = K.ID_COULOMB_SMOOTH

    regularization_velocity_rad_s: float = 1e-3

    def steady_state(self, v):
        v = np.asarray(v, float)
        e = self.regularization_velocity_rad_s
        return self.coulomb_torque_Nm * v / np.sqrt(v * v + e * e)

    def describing_function(self, rate_amplitude):
        # exact for v_eps -> 0; the regularisation changes it by O((v_eps/V)^2)
        return coulomb_describing_function(self.coulomb_torque_Nm, rate_amplitude)

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
    fid: ClassVar[int] = K.ID_DAHL
    has_state: ClassVar[bool] = True

    bristle_stiffness_Nm_per_rad: float = 0.0
    dahl_exponent: float = 1.0

    def steady_state(self, v):
        return self.coulomb_torque_Nm * np.sign(np.asarray(v, float))

    def validate(self, source, section="friction"):
        if not self.bristle_stiffness_Nm_per_rad > 0:
            raise InputError(source, f"{section}.bristle_stiffness",
                             "a positive rotational stiffness for the Dahl law")
        if self.dahl_exponent < 1.0:
            raise InputError(source, f"{section}.dahl_exponent", "a number >= 1")


@dataclass(frozen=True)
class LuGre(FrictionLaw):
    """LuGre friction (Canudas de Wit et al. 1995).

    dz/dt = v - sigma_0 |v| z / g(v),  g(v) = T_c + (T_s - T_c) exp(-|v/v_s|^delta),
    T_f = sigma_0 z + sigma_1(v) dz/dt + sigma_2 v,  sigma_1(v) = sigma_1 exp(-(v/v_1)^2)
    (constant if v_1 = 0).

    Steady state g(v) sgn(v) + sigma_2 v. Passivity (Barabanov & Ortega 2000; from the
    storage sigma_0 z^2/2): the power balance is a quadratic form in (z, v) that is
    non-negative when |v| sigma_1(v)^2 <= 4 g(v) (sigma_1(v) + sigma_2); a decaying sigma_1
    (v_1 > 0) keeps it for all v. :meth:`passive_at` evaluates the condition.
    """

    name: ClassVar[str] = "lugre"
    fid: ClassVar[int] = K.ID_LUGRE
    has_state: ClassVar[bool] = True

    static_torque_Nm: float = 0.0
    stribeck_velocity_rad_s: float = 1e-3
    stribeck_exponent: float = 2.0
    bristle_stiffness_Nm_per_rad: float = 0.0
    bristle_damping_Nms_per_rad: float = 0.0
    viscous_damping_Nms_per_rad: float = 0.0
    damping_decay_velocity_rad_s: float = 0.0

    def _g(self, v):
        v = np.abs(np.asarray(v, float))
        tc, ts = self.coulomb_torque_Nm, self.static_torque_Nm
        return tc + (ts - tc) * np.exp(-(v / self.stribeck_velocity_rad_s) ** self.stribeck_exponent)

    def _h(self, v):
        return np.ones_like(np.asarray(v, float))

    def _sigma1(self, v):
        v1 = self.damping_decay_velocity_rad_s
        s1 = self.bristle_damping_Nms_per_rad
        return s1 * np.exp(-(np.asarray(v, float) / v1) ** 2) if v1 > 0 else s1 + 0 * np.asarray(v, float)

    def steady_state(self, v):
        v = np.asarray(v, float)
        return self._g(v) * self._h(v) * np.sign(v) + self.viscous_damping_Nms_per_rad * v

    def passive_at(self, v) -> np.ndarray:
        """True where the passivity condition |v| sigma_1^2 <= 4 g (sigma_1 + sigma_2) holds."""
        v = np.asarray(v, float)
        s1 = self._sigma1(v)
        g = self._g(v) * self._h(v)
        return np.abs(v) * s1 ** 2 <= 4.0 * g * (s1 + self.viscous_damping_Nms_per_rad) + 1e-300

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

    The LuGre equations with g(v) = G(v) h(v), where G is the Stribeck curve above (the static
    level T_s may be set *below* T_c, with a tunable shape exponent delta) and

        h(v) = (2/pi) asin(min(1, |v| / V_d))

    is the average of a Coulomb law over a superposed vibration of rate amplitude V_d
    [rad/s]: friction becomes viscous-like below V_d, with slope (2/pi) T_s / V_d at v = 0
    (bristle relaxation rate sigma_0 pi V_d / (2 T_s) there, finite). With V_d = 0 the law is
    exactly LuGre (h = 1); the packed kernels are identical. Basis: the averaging argument of
    DESIGN.md and the paper's companion work on vibration-reduced stiction (ref. 2 of the
    seed paper). Passivity as for LuGre with g including h.
    """

    name: ClassVar[str] = "modified-lugre"
    fid: ClassVar[int] = K.ID_MODIFIED_LUGRE

    vibration_velocity_rad_s: float = 0.0

    def _h(self, v):
        v = np.abs(np.asarray(v, float))
        vd = self.vibration_velocity_rad_s
        if vd <= 0:
            return np.ones_like(v)
        return (2.0 / math.pi) * np.arcsin(np.minimum(1.0, v / vd))



#: Registry: model name -> class (the names are a contract, DESIGN.md).
LAWS: dict[str, type[FrictionLaw]] = {
    cls.name: cls for cls in (NoFriction, CoulombSwitching, CoulombSmooth, Dahl, LuGre, ModifiedLuGre)
}


def friction_from_table(table: dict, source: str, model: str | None = None,
                        section: str = "friction") -> FrictionLaw:
    """Build the law named by ``table['model']`` (or ``model``, the ``--friction`` override,
    which keeps the table's torque levels and parameters)."""
    name = model if model is not None else table.get("model")
    if name not in LAWS:
        raise InputError(source if model is None else "command line",
                         f"{section}.model" if model is None else "--friction",
                         "one of " + ", ".join(LAWS), got=repr(name))
    from ..errors import check_keys

    check_keys(table, set(FRICTION_KEYS) | {"model"}, source, section)
    return LAWS[name].from_table(table, source, section)
