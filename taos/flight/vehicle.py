"""Notional launch-vehicle flight-control loop around the TVC (seed paper sections 3.1-3.2).

Rigid-body attitude (pitch or yaw) of the core-stage vehicle after booster separation, a
notional flight-control system (FCS), and the TVC in its forward path.

Vehicle (one plane, small angles, exo-atmospheric; Greensite, *Analysis and Design of Space
Vehicle Flight Control Systems*, 1970, ch. 1)::

    I_v theta'' = n_e [T l_c delta + K_twd delta''] + I_v M_a theta
    K_twd = J_n + m_e l_e l_c                       "tail wags dog" inertial coupling

theta vehicle attitude [rad], delta engine deflection [rad] (all n_e engines alike, each the
simplex TVC of :mod:`taos.planar.simplex`), T thrust per engine [N], l_c c.g. -> gimbal-plane arm [m],
m_e engine mass [kg], l_e gimbal -> engine c.g. offset [m], J_n engine inertia about the gimbal
[kg m^2], M_a aerodynamic instability [1/s^2] (0 exo-atmospheric). The TWD zeros sit at
w_twd = sqrt(T l_c / K_twd). The engine equation does not feel the vehicle's own angular
acceleration ("dog wags tail"): at the 0.1-0.2 Hz limit cycle J_n theta'' is ~1e-3 of the
friction torque. Written with xi = theta - b delta (b = n_e K_twd / I_v), the vehicle is
proper: xi'' = a delta + M_a theta, a = n_e T l_c / I_v; outputs theta = xi + b delta,
theta' = xi' + b delta'.

FCS (attitude reference zero)::

    u       = K_p theta + K_i int(theta) dt + K_d theta'         PID on attitude and rate
    delta_c = -P_n(s) F(s) u,   F(s) = 1/(tau s + 1) x notch(s)   lag / notch filter
    P_n(s)  = (n, n) Pade approximant of exp(-s t_d)              sensor + compute delay

The loop broken at the TVC command (the TVC replaced by unity) is
L0(jw) = -d delta_c / d delta (jw); with the TVC's describing function N(A, w) the
characteristic equation is 1 + L0 N = 0 (negative feedback convention: the critical point is
-1, i.e. 0 dB and -180 deg on a Nichols chart). :func:`vehicle_fcs_state_space` is the single
definition of vehicle + FCS; :func:`loop_freqresp` and the closed loop
:func:`flight_plant` (a :class:`~taos.planar.simplex.LurePlant` for the compiled integrator) both
use it.
"""

from __future__ import annotations

import hashlib
import os
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from taos.errors import InputError
from taos.linear import StateSpace
from taos.stability import LoopMargins, loop_margins
from taos.model import TvcModel, read_toml
from taos.shipped import resolve, resolve_reference
from taos.planar.simplex import LurePlant, simplex_limits, simplex_state_space

#: vehicle + FCS block signals
VF_INPUTS = ("delta_rad", "delta_rate_rad_s")
VF_OUTPUTS = ("delta_cmd_rad", "attitude_rad", "rate_rad_s")


@dataclass(frozen=True)
class Vehicle:
    """Rigid-body vehicle in one plane (SI). See the module docstring for the equations.

    mass_kg : vehicle mass [kg] (reported; the attitude dynamics need only the inertia);
    pitch/yaw_inertia_kgm2 : I_v about the c.g. [kg m^2]; engine_count : n_e;
    thrust_per_engine_N : T [N]; gimbal_arm_m : l_c, c.g. to gimbal plane [m];
    engine_mass_kg : m_e [kg]; engine_cg_offset_m : l_e, gimbal to engine c.g. [m];
    engine_inertia_kgm2 : J_n about the gimbal [kg m^2]; aero_instability_per_s2 : M_a [1/s^2];
    optional first bending mode (0 Hz: none): bending_frequency_hz w_b / 2 pi [Hz],
    bending_damping_ratio zeta_b [-], bending_gain g_b [-] with
    eta'' + 2 zeta_b w_b eta' + w_b^2 eta = g_b a delta, the sensors reading theta + eta and
    theta' + eta' (g_b: the mode's generalised TVC force times the sensor's modal slope, relative to
    the rigid body's a; Greensite 1970, ch. 5).
    """

    mass_kg: float
    pitch_inertia_kgm2: float
    yaw_inertia_kgm2: float
    engine_count: int
    thrust_per_engine_N: float
    gimbal_arm_m: float
    engine_mass_kg: float
    engine_cg_offset_m: float
    engine_inertia_kgm2: float
    aero_instability_per_s2: float = 0.0
    bending_frequency_hz: float = 0.0
    bending_damping_ratio: float = 0.005
    bending_gain: float = 0.0

    def inertia(self, axis: str) -> float:
        return self.pitch_inertia_kgm2 if axis == "pitch" else self.yaw_inertia_kgm2

    def control_acceleration_per_s2(self, axis: str) -> float:
        """a = n_e T l_c / I_v [1/s^2]: attitude acceleration per radian of engine deflection."""
        return self.engine_count * self.thrust_per_engine_N * self.gimbal_arm_m / self.inertia(axis)

    def twd_coefficient(self, axis: str) -> float:
        """b = n_e (J_n + m_e l_e l_c) / I_v [-]: tail-wags-dog attitude per engine angle."""
        k = self.engine_inertia_kgm2 + self.engine_mass_kg * self.engine_cg_offset_m * self.gimbal_arm_m
        return self.engine_count * k / self.inertia(axis)

    def twd_frequency_hz(self, axis: str = "pitch") -> float:
        """w_twd / 2 pi = sqrt(a / b) / 2 pi [Hz]: the tail-wags-dog zero."""
        return math.sqrt(self.control_acceleration_per_s2(axis) / self.twd_coefficient(axis)) / (2 * math.pi)


@dataclass(frozen=True)
class FlightControl:
    """Notional FCS (SI): K_p [rad/rad], K_i [1/s], K_d [s]; lag time constant [s] (0: none);
    notch centre [Hz] (0: none) with numerator / denominator damping ratios; delay t_d [s]
    and its Pade order (0: none)."""

    attitude_gain: float
    integral_gain_per_s: float
    rate_gain_s: float
    lag_time_constant_s: float = 0.0
    notch_frequency_hz: float = 0.0
    notch_zeta_num: float = 0.0
    notch_zeta_den: float = 0.7
    delay_s: float = 0.0
    pade_order: int = 2


@dataclass(frozen=True)
class FlightModel:
    """A flight file: vehicle, FCS, the axis analysed and the TVC model file it pairs with."""

    name: str
    vehicle: Vehicle
    fcs: FlightControl
    axis: str = "yaw"
    tvc_model: str = ""
    source: str = "<code>"
    sha256: str = ""


# -- loading ------------------------------------------------------------------------------
_VEHICLE_KEYS = {  # key -> (field, reference unit, check)
    "mass": ("mass_kg", "kg", "positive"),
    "pitch_inertia": ("pitch_inertia_kgm2", "kg*m**2", "positive"),
    "yaw_inertia": ("yaw_inertia_kgm2", "kg*m**2", "positive"),
    "thrust_per_engine": ("thrust_per_engine_N", "N", "positive"),
    "gimbal_arm": ("gimbal_arm_m", "m", "positive"),
    "engine_mass": ("engine_mass_kg", "kg", "nonnegative"),
    "engine_cg_offset": ("engine_cg_offset_m", "m", "nonnegative"),
    "engine_inertia": ("engine_inertia_kgm2", "kg*m**2", "nonnegative"),
    "aero_instability": ("aero_instability_per_s2", "1/s**2", "nonnegative"),
    "bending_frequency": ("bending_frequency_hz", "Hz", "nonnegative"),
    "bending_damping_ratio": ("bending_damping_ratio", "dimensionless", "positive"),
    "bending_gain": ("bending_gain", "dimensionless", "nonnegative"),
}
_FCS_KEYS = {
    "attitude_gain": ("attitude_gain", "rad/rad", "positive"),
    "integral_gain": ("integral_gain_per_s", "1/s", "nonnegative"),
    "rate_gain": ("rate_gain_s", "s", "nonnegative"),
    "lag_time_constant": ("lag_time_constant_s", "s", "nonnegative"),
    "notch_frequency": ("notch_frequency_hz", "Hz", "nonnegative"),
    "notch_zeta_num": ("notch_zeta_num", "dimensionless", "nonnegative"),
    "notch_zeta_den": ("notch_zeta_den", "dimensionless", "positive"),
    "delay": ("delay_s", "s", "nonnegative"),
}
_OPTIONAL = {"aero_instability", "lag_time_constant", "notch_frequency", "notch_zeta_num",
             "notch_zeta_den", "delay", "bending_frequency", "bending_damping_ratio", "bending_gain"}


def _value(table: Mapping, key: str, unit: str, check: str, src: str, section: str) -> float:
    """Parse ``table[key]`` (a string with a unit; plain numbers for dimensionless) to SI."""
    from taos.units import Q_

    fld = f"{section}.{key}"
    expected = f"a value with a unit convertible to {unit}"
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise InputError(src, fld, expected, got=repr(v))
    if isinstance(v, (int, float)):
        if unit != "dimensionless":
            raise InputError(src, fld, expected, got=f"{v!r} (no unit)")
        q = Q_(float(v), "dimensionless")
    else:
        from taos.units import check_value_text

        check_value_text(v, src, fld, expected)
        try:
            q = Q_(v)
        except Exception:
            raise InputError(src, fld, expected, got=repr(v)) from None
        if not hasattr(q, "dimensionality"):
            q = Q_(float(q), "dimensionless")
    ref = Q_(1.0, unit)
    if q.dimensionality != ref.dimensionality:
        raise InputError(src, fld, expected, got=repr(v))
    out = float(q.to(ref.units).magnitude)
    if not math.isfinite(out) or (check == "positive" and not out > 0) or (check == "nonnegative" and out < 0):
        raise InputError(src, fld, f"a {check} finite value in {unit}", got=repr(v))
    return out


def _parse(table: Mapping, keys: dict, src: str, section: str) -> dict:
    if not isinstance(table, Mapping):
        raise InputError(src, f"[{section}]", f"a [{section}] table", got="nothing (section missing)")
    from taos.errors import check_keys

    check_keys(table, set(keys) | ({"engine_count"} if section == "vehicle" else {"pade_order"}), src, section)
    out = {}
    for k, (fld, unit, check) in keys.items():
        if k not in table:
            if k in _OPTIONAL:
                continue
            raise InputError(src, f"{section}.{k}", f"a value in {unit}", got="nothing (key missing)")
        out[fld] = _value(table, k, unit, check, src, section)
        from taos.bounds import FLIGHT_BOUNDS, check_bound
        if f"{section}.{k}" in FLIGHT_BOUNDS:   # the documented physical bounds (docs/reference/bounds.md)
            check_bound(out[fld], f"{section}.{k}", src)
    return out


def load_flight(path: str | Path) -> FlightModel:
    """Load a flight file (``models/flight/core_stage.toml``); :class:`InputError` on bad input."""
    p = resolve(path, "flight")
    src = str(p)
    raw, doc = read_toml(p, "a readable flight file")
    from taos.errors import check_keys

    check_keys(doc, {"name", "description", "axis", "tvc_model", "vehicle", "fcs"}, src)
    vt = doc.get("vehicle")
    vkw = _parse(vt, _VEHICLE_KEYS, src, "vehicle")
    n = vt.get("engine_count")
    from taos.bounds import MAX_ENGINES
    if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_ENGINES:
        raise InputError(src, "vehicle.engine_count", f"a whole number of engines from 1 to {MAX_ENGINES}",
                         got=repr(n))
    ft = doc.get("fcs")
    fkw = _parse(ft, _FCS_KEYS, src, "fcs")
    order = ft.get("pade_order", 2)
    if not isinstance(order, int) or isinstance(order, bool) or not 0 <= order <= 6:
        raise InputError(src, "fcs.pade_order", "a whole number from 0 to 6", got=repr(order))
    axis = doc.get("axis", "yaw")
    if axis not in ("pitch", "yaw"):
        raise InputError(src, "axis", "'pitch' or 'yaw'", got=repr(axis))
    tvc = doc.get("tvc_model", "")
    if tvc:
        tvc = str(resolve_reference(tvc, p, field="tvc_model", kind="flight", what="a TVC model file"))
        if os.path.realpath(tvc) == os.path.realpath(p):
            raise InputError(src, "tvc_model", "a TVC model file, not this flight file itself", got=repr(doc["tvc_model"]))
    return FlightModel(name=str(doc.get("name", p.stem)), vehicle=Vehicle(engine_count=n, **vkw),
                       fcs=FlightControl(pade_order=order, **fkw), axis=axis, tvc_model=tvc,
                       source=src, sha256=hashlib.sha256(raw).hexdigest())


# -- linear blocks ------------------------------------------------------------------------
def pade(delay_s: float, order: int) -> tuple[np.ndarray, np.ndarray]:
    """(num, den) of the (n, n) Pade approximant of exp(-s t_d), highest power first:
    c_k = (2n - k)! n! / ((2n)! k! (n - k)!), num = sum c_k (-s t_d)^k, den = sum c_k (s t_d)^k."""
    if order == 0 or delay_s == 0.0:
        return np.array([1.0]), np.array([1.0])
    n = order
    c = [math.factorial(2 * n - k) * math.factorial(n) / (math.factorial(2 * n) * math.factorial(k)
         * math.factorial(n - k)) for k in range(n + 1)]
    num = np.array([c[k] * (-delay_s) ** k for k in range(n, -1, -1)])
    den = np.array([c[k] * delay_s ** k for k in range(n, -1, -1)])
    return num, den


def fcs_filter_tf(fcs: FlightControl) -> tuple[np.ndarray, np.ndarray]:
    """(num, den) of the FCS command filter F(s) P_n(s): lag, notch and Pade delay in series."""
    num, den = np.array([1.0]), np.array([1.0])
    if fcs.lag_time_constant_s > 0:
        den = np.polymul(den, [fcs.lag_time_constant_s, 1.0])
    if fcs.notch_frequency_hz > 0:
        w = 2 * math.pi * fcs.notch_frequency_hz
        num = np.polymul(num, [1.0, 2 * fcs.notch_zeta_num * w, w * w])
        den = np.polymul(den, [1.0, 2 * fcs.notch_zeta_den * w, w * w])
    pn, pd = pade(fcs.delay_s, fcs.pade_order)
    return np.polymul(num, pn), np.polymul(den, pd)


def fcs_filter_ss(fcs: FlightControl) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C, D) of :func:`fcs_filter_tf` in controller canonical form (time in s; the
    filter's input and output are the FCS command in rad).

    With num (padded with leading zeros to den's length) and den both divided by den[0]: A's
    first row is -den[1:] with ones on its subdiagonal, B = e_1, C = num[1:] - num[0] den[1:],
    D = num[0]; a static filter (no lag, notch or delay) keeps one idle state. This is
    ``scipy.signal.tf2ss`` bit for bit (``tests/test_flight.py``), written out so that a flight
    run does not import scipy.signal (about half a second of every Monte Carlo worker's start-up).
    scipy's trim of numerator coefficients below 1e-14 never applies: num[0] / den[0] is
    +-1 or +-1 / lag time constant (the Pade and notch leading coefficients cancel)."""
    num, den = fcs_filter_tf(fcs)
    num, den = num / den[0], den / den[0]
    num = np.concatenate([np.zeros(len(den) - len(num)), num])
    n = len(den) - 1
    if n == 0:
        return np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), num.reshape(1, 1)
    A = np.vstack([-den[None, 1:], np.eye(n - 1, n)])
    return A, np.eye(n, 1), (num[1:] - num[0] * den[1:])[None, :], num[:1].reshape(1, 1)


def vehicle_fcs_state_space(flight: FlightModel, axis: str | None = None, *,
                            filter_ss: tuple | None = None) -> StateSpace:
    """Vehicle + FCS as one linear block (equations in the module docstring).

    Inputs :data:`VF_INPUTS` (engine deflection [rad] and rate [rad/s]); outputs
    :data:`VF_OUTPUTS` (FCS engine command [rad], attitude [rad], attitude rate [rad/s]).
    States: ``xi_rad``, ``xi_rate_rad_s`` (attitude minus the TWD part), ``int_attitude_rad_s``,
    then the filter / delay states. ``filter_ss``: :func:`fcs_filter_ss` of ``flight.fcs`` when
    already computed (it does not depend on the gains or the vehicle)."""
    axis = axis or flight.axis
    v, f = flight.vehicle, flight.fcs
    a = v.control_acceleration_per_s2(axis)
    b = v.twd_coefficient(axis)
    Ma = v.aero_instability_per_s2
    # vehicle + integrator: states (xi, xi', int theta); inputs (delta, delta')
    A = np.array([[0.0, 1.0, 0.0], [Ma, 0.0, 0.0], [1.0, 0.0, 0.0]])
    B = np.array([[0.0, 0.0], [a + Ma * b, 0.0], [b, 0.0]])
    c_th, d_th = np.array([1.0, 0.0, 0.0]), np.array([b, 0.0])
    c_q, d_q = np.array([0.0, 1.0, 0.0]), np.array([0.0, b])
    c_u = f.attitude_gain * c_th + f.rate_gain_s * c_q + np.array([0.0, 0.0, f.integral_gain_per_s])
    d_u = f.attitude_gain * d_th + f.rate_gain_s * d_q
    # filter chain driven by u, output -F P u
    Af, Bf, Cf, Df = fcs_filter_ss(f) if filter_ss is None else filter_ss
    nf = Af.shape[0]
    nb = 2 if v.bending_frequency_hz > 0 else 0  # optional first bending mode (eta, eta')
    n = 3 + nf + nb
    Aa = np.zeros((n, n))
    Aa[:3, :3] = A
    Ba = np.zeros((n, 2))
    Ba[:3] = B
    c_u = np.concatenate([c_u, np.zeros(nf + nb)])
    if nb:  # sensed attitude theta + eta, rate theta' + eta'; the integrator integrates the sensed attitude
        ib = 3 + nf
        wb = 2 * math.pi * v.bending_frequency_hz
        Aa[ib, ib + 1] = 1.0
        Aa[ib + 1, ib] = -wb * wb
        Aa[ib + 1, ib + 1] = -2 * v.bending_damping_ratio * wb
        Ba[ib + 1, 0] = v.bending_gain * a
        Aa[2, ib] = 1.0
        c_u[ib] = f.attitude_gain
        c_u[ib + 1] = f.rate_gain_s
    if nf:
        Aa[3:3 + nf, 3:3 + nf] = Af
        Aa[3:3 + nf, :] += np.outer(Bf[:, 0], c_u)
        Ba[3:3 + nf] = np.outer(Bf[:, 0], d_u)
    C = np.zeros((3, n))
    D = np.zeros((3, 2))
    C[0, :] = -Df[0, 0] * c_u
    if nf:
        C[0, 3:3 + nf] += -Cf[0]
    D[0] = -Df[0, 0] * d_u
    C[1, :3], D[1] = c_th, d_th
    C[2, :3], D[2] = c_q, d_q
    states = (("xi_rad", "xi_rate_rad_s", "int_attitude_rad_s") + tuple(f"filter_{i}" for i in range(nf))
              + (("bending_eta", "bending_eta_rate") if nb else ()))
    return StateSpace(Aa, Ba, C, D, states, VF_INPUTS, VF_OUTPUTS)


def loop_freqresp(flight: FlightModel, freq_hz, axis: str | None = None) -> np.ndarray:
    """L0(j w): the FCS loop broken at the TVC command with the TVC replaced by unity
    (delta = delta_c), negative feedback convention (1 + L0 = 0 at instability). [-]"""
    f = np.atleast_1d(np.asarray(freq_hz, float))
    h = vehicle_fcs_state_space(flight, axis).freqresp(f, list(VF_INPUTS), "delta_cmd_rad")
    return -(h[:, 0] + 2j * np.pi * f * h[:, 1])


@dataclass(frozen=True, eq=False)
class PlantParts:
    """The parts of :func:`flight_plant` that do not change with the vehicle's properties or
    the FCS gains: the simplex block and its packed limits for one model and axis, the FCS
    filter's state space. Built once for the many plants of one flown ascent."""

    tvc: StateSpace
    limits: np.ndarray
    filter_ss: tuple

    @classmethod
    def of(cls, flight: FlightModel, model: TvcModel, axis: str | None = None) -> "PlantParts":
        axis = axis or flight.axis
        return cls(simplex_state_space(model, axis), simplex_limits(model, axis), fcs_filter_ss(flight.fcs))


def flight_plant(flight: FlightModel, model: TvcModel, axis: str | None = None, *,
                 parts: PlantParts | None = None) -> LurePlant:
    """Closed flight loop: vehicle + FCS + the linear simplex TVC block as a Lur'e plant.

    The avionics sit on the FCS command channel (``cmd_c`` = the FCS command row over the
    joint state); the friction element acts at the gimbal as in :func:`simplex_plant`.
    External input ``pti_rad``: a programmed test input added to the FCS command [rad].
    Outputs: the simplex outputs, then :data:`VF_OUTPUTS`. States: the simplex states, then
    the vehicle + FCS states. ``parts``: :meth:`PlantParts.of` of the same ``model``, ``axis``
    and FCS filter when already built (the same plant, without rebuilding them)."""
    from taos.planar.saturation import embed_limits   # a numba module: imported by a run, not a file load

    axis = axis or flight.axis
    parts = parts or PlantParts.of(flight, model, axis)
    tv = parts.tvc
    vf = vehicle_fcs_state_space(flight, axis, filter_ss=parts.filter_ss)
    nt, nv = tv.A.shape[0], vf.A.shape[0]
    n = nt + nv
    # TVC outputs feeding the vehicle: delta = theta, delta' = omega (rows over the TVC state)
    sel = np.zeros((2, nt))
    sel[0, tv.state_index("theta_rad")] = 1.0
    sel[1, tv.state_index("omega_rad_s")] = 1.0
    A = np.zeros((n, n))
    A[:nt, :nt] = tv.A
    A[nt:, nt:] = vf.A
    A[nt:, :nt] = vf.B @ sel
    B = np.zeros((n, 3))
    B[:nt, 1:] = tv.B
    C = np.zeros((tv.C.shape[0] + vf.C.shape[0], n))
    C[: tv.C.shape[0], :nt] = tv.C
    C[tv.C.shape[0]:, nt:] = vf.C
    C[tv.C.shape[0]:, :nt] = vf.D @ sel
    ss = StateSpace(A, B, C, np.zeros((C.shape[0], 3)), tv.states + vf.states,
                    ("pti_rad",) + tv.inputs, tv.outputs + vf.outputs)
    return LurePlant(ss=ss, n_ext=1, cmd_c=C[ss.output_index("delta_cmd_rad")].copy(), cmd_d=np.ones(1),
                     rate_c=C[ss.output_index("omega_rad_s")].copy(),
                     applied_c=C[ss.output_index("applied_torque_Nm")].copy(),
                     inertia_kgm2=model.engine.inertia(axis),
                     limits=embed_limits(parts.limits, n, 0))


# -- margins ------------------------------------------------------------------------------
def open_loop_state_space(flight: FlightModel, axis: str | None = None) -> StateSpace:
    """L0(s) as a SISO state space: input ``delta_rad`` (the TVC replaced by unity, delta =
    delta_c), output ``loop_L0`` = -delta_c, so that L0 = 1 + ... is in the negative feedback
    convention of :func:`loop_freqresp` (the same response, exactly).

    The vehicle + FCS block takes delta and its rate; with delta' = s delta,
    C (sI - A)^-1 (B_0 + s B_1) = C (sI - A)^-1 (B_0 + A B_1) + C B_1, so the rate input folds
    into B and D without a derivative."""
    vf = vehicle_fcs_state_space(flight, axis)
    o = vf.output_index("delta_cmd_rad")
    A = vf.A
    B0, B1 = vf.B[:, [0]], vf.B[:, [1]]
    C, D = vf.C[[o]], vf.D[[o]]
    if D[0, 1] != 0.0:  # an improper loop (rate feed-through to the command) has no state space
        raise ValueError("open_loop_state_space: the FCS command feeds the engine rate straight through")
    return StateSpace(A, B0 + A @ B1, -C, -(D[:, [0]] + C @ B1), vf.states, ("delta_rad",), ("loop_L0",))


@dataclass(frozen=True)
class Margins:
    """Stability margins of an open loop L (negative feedback), from :func:`taos.stability.loop_margins`.

    Gain margins in dB, each positive: ``high_gain_margin_db`` the gain may rise by that much
    (the smallest -20 log|L| over the -180 deg crossings where |L| < 1), ``low_gain_margin_db``
    it may fall by that much (the smallest 20 log|L| over the crossings where |L| > 1, the
    low-frequency crossing of a conditionally stable loop), each with its phase crossover
    [Hz]. Phase margin [deg] the smallest over the gain crossovers (0 dB), at
    ``gain_crossover_hz``. ``crossings`` lists every crossing."""

    gain_crossover_hz: float | None
    phase_margin_deg: float | None
    low_gain_margin_db: float | None
    low_phase_crossover_hz: float | None
    high_gain_margin_db: float | None
    high_phase_crossover_hz: float | None
    crossings: LoopMargins | None = None

    def to_dict(self) -> dict:
        d = {k: v for k, v in self.__dict__.items() if k != "crossings"}
        if self.crossings is not None:
            d.update(self.crossings.to_dict())
        return d


def _margins(lm: LoopMargins) -> Margins:
    pm, fc = lm.min_phase_margin
    lo, flo = lm.downward
    hi, fhi = lm.upward
    return Margins(gain_crossover_hz=fc, phase_margin_deg=None if fc is None else pm,
                   low_gain_margin_db=lo, low_phase_crossover_hz=flo,
                   high_gain_margin_db=hi, high_phase_crossover_hz=fhi, crossings=lm)


def margins(freq_hz: np.typing.ArrayLike, L: np.typing.ArrayLike) -> Margins:
    """Margins of the sampled open loop ``L`` (complex, on an increasing frequency grid [Hz]);
    every crossing located between samples by :func:`taos.stability.loop_margins`."""
    from taos.stability import check_sampled_loop
    return _margins(loop_margins(*check_sampled_loop(freq_hz, L, "freq_hz")))


def flight_loop_margins(flight: FlightModel, axis: str | None = None) -> Margins:
    """Exact margins of L0 (the TVC replaced by unity) from :func:`open_loop_state_space`,
    every crossing found by python-control."""
    return _margins(loop_margins(open_loop_state_space(flight, axis)))
