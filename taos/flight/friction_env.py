"""Gimbal friction against its environment (seed paper sec. 5: why flight friction exceeded the
Green Run's): the bearing's Coulomb level follows the thrust, and the modified-LuGre vibration
level follows the vibration environment.

Thrust. The gimbal bearing carries the thrust N [N] (the engine weight m g0 when hanging), so its
Coulomb level is

    T_c = mu N r_b                                                  [N m]

with the model file's ``[gimbal] friction_coefficient`` mu [-] and ``bearing_radius`` r_b [m]
(the 3-D model's :attr:`taos.taos3d.model.TaosModel.coulomb_torque_Nm`; a file without them:
mu r_b = T_c,file / N_file, the file's own anchor). :func:`at_thrust` is the model variant at
thrust N (``engine.thrust`` and ``friction.coulomb_torque`` together; the law's torque-like
parameters follow the level, :mod:`taos.variants`). Along an ascent the core thrust per engine
N(t) comes from the ascent file's trajectory; :func:`friction_scale` is N(t) / N_model, the
factor on the law's torque-like slots (:meth:`taos.friction.FrictionLaw.scaled`) that
:func:`taos.flight.ascent_sim.simulate_ascent` applies per update interval with
``friction_follows_thrust=True`` (exactly 1, hence bit-identical runs, when the trajectory's
thrust is the model's).

Vibration. The modified LuGre law (:class:`taos.friction._laws.ModifiedLuGre`) averages Coulomb
friction over a sinusoidal relative rate of amplitude V_d [rad/s]: h(v) = (2/pi) asin(|v| / V_d),
slope (2/pi) / V_d at v = 0. The mappings (:func:`vibration_velocity`):

* a sine vibration of relative angular-rate amplitude W [rad/s]: V_d = W (the law's own case);
* a random (Gaussian) relative angular rate of RMS sigma_w [rad/s]: Coulomb friction averaged over
  it is T_c erf(v / (sqrt(2) sigma_w)), slope sqrt(2/pi) / sigma_w at v = 0; equal slopes (the
  small-amplitude gain the LCO sees) give V_d = (2 / pi) sigma_w / sqrt(2 / pi) = sqrt(2 / pi) sigma_w;
* a lateral acceleration at the nozzle, a distance L [m] from the gimbal, relative to the thrust
  structure: angular acceleration a / L. A flat PSD of level W_a [g^2/Hz] over [f1, f2] [Hz] gives
  the rate RMS sigma_w^2 = g0^2 W_a / (4 pi^2 L^2) (1 / f1 - 1 / f2) (the rate PSD is W_a g0^2 /
  (L^2 (2 pi f)^2)); a sine of amplitude A [m/s^2] at f [Hz] the rate amplitude A / (2 pi f L).

The result is the model variant ``{"friction.vibration_velocity": V_d}`` (:func:`with_vibration`).
The vibration is that of the engine relative to the thrust structure across the bearing: a level
measured on the stand or in flight must be referred to it (here: the nozzle's lateral motion
over its lever arm, the rigid-engine approximation).
"""

from __future__ import annotations

import math

import numpy as np

from taos.errors import InputError

G0 = 9.80665


def _gimbal(model) -> tuple[float, float]:
    """mu [-] and r_b [m] of the model's ``[gimbal]`` table; without them mu = T_c / (N r_b) with
    r_b = 1 m (only the product mu r_b = T_c,file / N_file matters)."""
    from taos.taos3d.model import normal_load_N
    from taos.units import to_si

    g = dict(model.extra.get("gimbal", {}) or {})
    n0 = normal_load_N(model)
    rb = to_si(g["bearing_radius"], "length", source=model.source, field="gimbal.bearing_radius") \
        if "bearing_radius" in g else 1.0
    if "friction_coefficient" in g:
        mu = to_si(g["friction_coefficient"], "dimensionless", source=model.source,
                   field="gimbal.friction_coefficient")
    else:
        mu = model.friction.coulomb_torque_Nm / (n0 * rb)
    return float(mu), float(rb)


def bearing_level_Nm(model, thrust_N: float) -> float:
    """T_c = mu N r_b [N m] at thrust ``thrust_N`` (0: hanging, N = m g0; module docstring)."""
    _check_thrust(thrust_N)
    mu, rb = _gimbal(model)
    n = thrust_N if thrust_N > 0 else model.engine.mass_kg * G0
    return mu * n * rb


def _check_thrust(thrust_N) -> None:
    if isinstance(thrust_N, bool) or not isinstance(thrust_N, (int, float, np.floating)) \
            or not math.isfinite(thrust_N) or not 0 <= thrust_N <= 1e8:
        raise InputError("friction environment", "thrust_N", "a thrust from 0 to 1e8 N", got=repr(thrust_N))


def at_thrust(model, thrust_N: float):
    """The model variant at thrust ``thrust_N`` [N]: ``engine.thrust`` and ``friction.coulomb_torque``
    = mu N r_b together (the 3-D model's bearing level agrees), the law's torque-like parameters
    following the level."""
    return model.with_values({"engine.thrust": float(thrust_N),
                              "friction.coulomb_torque": bearing_level_Nm(model, thrust_N)})


def friction_scale(model, thrust_N) -> np.ndarray:
    """N / N_model: the factor on the law's torque-like parameters at thrust(s) ``thrust_N`` [N]
    (N_model the model's bearing normal load, :func:`taos.taos3d.model.normal_load_N`)."""
    from taos.taos3d.model import normal_load_N

    n = np.asarray(thrust_N, float)
    if not np.all(np.isfinite(n)) or np.any(n < 0):
        raise InputError("friction environment", "thrust_N", "finite thrusts >= 0 N", got=repr(thrust_N))
    return np.where(n > 0, n, model.engine.mass_kg * G0) / normal_load_N(model)


def vibration_velocity(*, rate_amplitude_rad_s: float | None = None, rate_rms_rad_s: float | None = None,
                       psd_g2_per_hz: float | None = None, band_hz: tuple[float, float] | None = None,
                       accel_amplitude_m_s2: float | None = None, freq_hz: float | None = None,
                       arm_m: float | None = None) -> float:
    """V_d [rad/s] of the modified LuGre law from one vibration environment (module docstring):
    a sine rate amplitude; a random rate RMS; a flat lateral acceleration PSD [g^2/Hz] over
    ``band_hz`` at ``arm_m`` [m] from the gimbal; or a sine acceleration amplitude [m/s^2] at
    ``freq_hz`` at ``arm_m``."""
    given = {k: v for k, v in (("rate_amplitude_rad_s", rate_amplitude_rad_s), ("rate_rms_rad_s", rate_rms_rad_s),
                               ("psd_g2_per_hz", psd_g2_per_hz), ("accel_amplitude_m_s2", accel_amplitude_m_s2))
             if v is not None}
    if len(given) != 1:
        raise InputError("vibration environment", "level", "exactly one of a rate amplitude, a rate RMS, an "
                         "acceleration PSD or an acceleration amplitude", got=", ".join(given) or "none")
    (key, val), = given.items()
    if isinstance(val, bool) or not isinstance(val, (int, float)) or not math.isfinite(val) or val < 0:
        raise InputError("vibration environment", key, "a finite value >= 0", got=repr(val))
    if key == "rate_amplitude_rad_s":
        return float(val)
    if key == "rate_rms_rad_s":
        return math.sqrt(2.0 / math.pi) * float(val)
    if arm_m is None or not (isinstance(arm_m, (int, float)) and math.isfinite(arm_m) and 0.1 <= arm_m <= 50):
        raise InputError("vibration environment", "arm_m", "the nozzle's distance from the gimbal, 0.1 to 50 m",
                         got=repr(arm_m))
    if key == "psd_g2_per_hz":
        if band_hz is None or len(band_hz) != 2 or not 0 < band_hz[0] < band_hz[1] <= 1e4:
            raise InputError("vibration environment", "band_hz", "(f1, f2) with 0 < f1 < f2 <= 1e4 Hz",
                             got=repr(band_hz))
        f1, f2 = map(float, band_hz)
        rms = math.sqrt(G0 ** 2 * val / (4 * math.pi ** 2 * arm_m ** 2) * (1 / f1 - 1 / f2))
        return math.sqrt(2.0 / math.pi) * rms
    if freq_hz is None or not (isinstance(freq_hz, (int, float)) and 0 < freq_hz <= 1e4):
        raise InputError("vibration environment", "freq_hz", "a frequency from 0 to 1e4 Hz", got=repr(freq_hz))
    return float(val) / (2 * math.pi * freq_hz * arm_m)


def with_vibration(model, v_d_rad_s: float):
    """The model variant with the modified-LuGre vibration level V_d [rad/s]
    (``friction.vibration_velocity``; the law switched to ``modified-lugre`` when it is not)."""
    values = {"friction.vibration_velocity": float(v_d_rad_s)}
    if model.friction.name != "modified-lugre":
        values = {"friction.model": "modified-lugre", **values}
    return model.with_values(values)
