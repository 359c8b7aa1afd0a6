"""The built-in laws' registry entries: their kernels as cached C callbacks with the
registry's uniform signatures (planar: :mod:`._kernels`; spherical bearing: :mod:`._vector`),
their fit describing functions and the parameters a fit may free.

Law ids are a contract of the model files and ``--friction``: ``none``,
``coulomb-switching``, ``coulomb-smooth``, ``dahl``, ``lugre``, ``modified-lugre``.
"""

from __future__ import annotations

from numba import cfunc

from ..errors import InputError
from . import _kernels as K
from . import _vector as V
from ._laws import (
    CoulombSmooth,
    CoulombSwitching,
    Dahl,
    LuGre,
    ModifiedLuGre,
    NoFriction,
    coulomb_relay_level,
    dahl_angle_df,
)
from .registry import (
    BEARING_SIG,
    RATES_SIG,
    TORQUE3_SIG,
    ZDOT3_SIG,
    FrictionLawEntry,
    register,
)


#: the planar integrator's floating-point flags (reassociation and FMA contraction only;
#: no-NaN/no-Inf flags would remove its stability checks), which the scalar kernels were
#: compiled with when inlined there; the vector kernels keep strict IEEE arithmetic
_FM = {"reassoc", "contract", "arcp", "nsz"}


def _kernel(sig):
    return cfunc(sig, cache=True, fastmath=_FM if sig is RATES_SIG else False)


# -- memoryless laws: no state ------------------------------------------------------------------
@_kernel(ZDOT3_SIG)
def zero_zdot3(w0, w1, z0, z1, p):
    return 0.0, 0.0


# -- none ------------------------------------------------------------------------------------------
@_kernel(RATES_SIG)
def none_rates(v, z, t_app, p):
    return 0.0, 0.0


@_kernel(TORQUE3_SIG)
def none_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return 0.0, 0.0


@_kernel(BEARING_SIG)
def none_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return d0 / dt, d1 / dt, 0.0, 0.0, 0.0, 0.0


# -- Coulomb, stick-slip switching -----------------------------------------------------------------
@_kernel(RATES_SIG)
def switching_rates(v, z, t_app, p):
    return 0.0, K.coulomb_switching_torque(v, t_app, p)


@_kernel(TORQUE3_SIG)
def switching_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.switching_torque3(w0, w1, t0, t1, p)


@_kernel(BEARING_SIG)
def switching_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.switching_bearing_step(p, Kc, d0, d1, z0, z1, dt, s0)


# -- Coulomb, smooth ---------------------------------------------------------------------------------
@_kernel(RATES_SIG)
def smooth_rates(v, z, t_app, p):
    return 0.0, K.coulomb_smooth_torque(v, p)


@_kernel(TORQUE3_SIG)
def smooth_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.smooth_torque3(w0, w1, p)


@_kernel(BEARING_SIG)
def smooth_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.coeff_bearing_step(V.smooth_coeffs, V.lugre_rho, False, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


# -- Dahl -------------------------------------------------------------------------------------------
@_kernel(RATES_SIG)
def dahl_rates(v, z, t_app, p):
    return K.dahl_zdot(v, z, p), K.dahl_torque(z, p)


@_kernel(ZDOT3_SIG)
def dahl_zdot3(w0, w1, z0, z1, p):
    return V.dahl_zdot3(w0, w1, z0, z1, p)


@_kernel(TORQUE3_SIG)
def dahl_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    s0 = p[K.SLOT_SIGMA0]
    return s0 * z0, s0 * z1


@_kernel(BEARING_SIG)
def dahl_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    kappa = V.dahl_kappa(d0, d1, z0, z1, p)
    return V.coeff_bearing_step(V.dahl_coeffs, V.dahl_rho, True, kappa, p, Kc, d0, d1, z0, z1, dt, s0)


# -- LuGre and modified LuGre (one kernel set: the vibration factor is 1 at V_d = 0) --------------
@_kernel(RATES_SIG)
def lugre_rates(v, z, t_app, p):
    dz = K.lugre_zdot(v, z, p)
    return dz, K.lugre_torque(v, z, dz, p)


@_kernel(ZDOT3_SIG)
def lugre_zdot3(w0, w1, z0, z1, p):
    return V.lugre_zdot3(w0, w1, z0, z1, p)


@_kernel(TORQUE3_SIG)
def lugre_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.lugre_torque3(w0, w1, z0, z1, dz0, dz1, p)


@_kernel(BEARING_SIG)
def lugre_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.coeff_bearing_step(V.lugre_coeffs, V.lugre_rho, True, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


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


_COULOMB_FIT = dict(fit_describing_function=_coulomb_fit_df, fit_relay_level=_coulomb_relay,
                    fit_parameters=("coulomb_torque",))
_LUGRE_FIT = dict(fit_describing_function=_dahl_fit_df,
                  fit_parameters=("coulomb_torque", "bristle_stiffness", "viscous_damping"))

for _e in (
    FrictionLawEntry("none", NoFriction, none_rates, zero_zdot3, none_torque3, none_bearing,
                     fit_describing_function=lambda law, X, w: (0.0, 0.0)),
    FrictionLawEntry("coulomb-switching", CoulombSwitching, switching_rates, zero_zdot3,
                     switching_torque3, switching_bearing, **_COULOMB_FIT),
    FrictionLawEntry("coulomb-smooth", CoulombSmooth, smooth_rates, zero_zdot3, smooth_torque3,
                     smooth_bearing, **_COULOMB_FIT),
    FrictionLawEntry("dahl", Dahl, dahl_rates, dahl_zdot3, dahl_torque3, dahl_bearing,
                     fit_describing_function=_dahl_fit_df, fit_check=_dahl_fit_check,
                     fit_parameters=("coulomb_torque", "bristle_stiffness")),
    FrictionLawEntry("lugre", LuGre, lugre_rates, lugre_zdot3, lugre_torque3, lugre_bearing,
                     **_LUGRE_FIT),
    FrictionLawEntry("modified-lugre", ModifiedLuGre, lugre_rates, lugre_zdot3, lugre_torque3,
                     lugre_bearing, **_LUGRE_FIT),
):
    register(_e, builtin=True)
