"""LuGre and the modified LuGre: one kernel set (:func:`._kernels.lugre_zdot`,
:func:`._kernels.lugre_torque`, :func:`._vector.lugre_zdot3`, :func:`._vector.lugre_torque3`,
the coefficient bearing step with :func:`._vector.lugre_coeffs`; the vibration factor is 1 at
V_d = 0) as cached C callbacks (with the lane form of the scalar kernel, ``rates_lanes``), and
the two laws' registry entries (see :mod:`._builtin`)."""

from __future__ import annotations

from . import _kernels as K
from . import _vector as V
from ._builtin import LUGRE_FIT, inlined, kernel
from ._laws import LuGre, ModifiedLuGre
from .registry import FrictionLawEntry


@kernel("RATES_SIG")
def lugre_rates(v, z, t_app, p):
    dz = K.lugre_zdot(v, z, p)
    return dz, K.lugre_torque(v, z, dz, p)


_law = inlined(lugre_rates)


@kernel("LANES_SIG")
def lugre_rates_lanes(v, z, t_app, P, dz, tf):
    for q in range(v.shape[0]):
        dz[q], tf[q] = _law(v[q], z[q], t_app[q], P[q])


@kernel("ZDOT3_SIG")
def lugre_zdot3(w0, w1, z0, z1, p):
    return V.lugre_zdot3(w0, w1, z0, z1, p)


@kernel("TORQUE3_SIG")
def lugre_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.lugre_torque3(w0, w1, z0, z1, dz0, dz1, p)


@kernel("BEARING_SIG")
def lugre_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.coeff_bearing_step(V.lugre_coeffs, V.lugre_rho, True, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


ENTRIES = (FrictionLawEntry("lugre", LuGre, lugre_rates, lugre_zdot3, lugre_torque3, lugre_bearing,
                            rates_lanes=lugre_rates_lanes, **LUGRE_FIT),
           FrictionLawEntry("modified-lugre", ModifiedLuGre, lugre_rates, lugre_zdot3, lugre_torque3,
                            lugre_bearing, rates_lanes=lugre_rates_lanes, **LUGRE_FIT))
