"""The Dahl law's kernels (:func:`._kernels.dahl_zdot`, :func:`._kernels.dahl_torque`,
:func:`._vector.dahl_zdot3`, the coefficient bearing step with :func:`._vector.dahl_coeffs`) as
cached C callbacks (with the lane form of the scalar kernel, ``rates_lanes``), and its registry
entry (see :mod:`._builtin`)."""

from __future__ import annotations

from . import _kernels as K
from . import _vector as V
from ._builtin import DAHL_FIT, inlined, kernel
from ._laws import Dahl
from .registry import FrictionLawEntry


@kernel("RATES_SIG")
def dahl_rates(v, z, t_app, p):
    return K.dahl_zdot(v, z, p), K.dahl_torque(z, p)


_law = inlined(dahl_rates)


@kernel("LANES_SIG")
def dahl_rates_lanes(v, z, t_app, P, dz, tf):
    for q in range(v.shape[0]):
        dz[q], tf[q] = _law(v[q], z[q], t_app[q], P[q])


@kernel("ZDOT3_SIG")
def dahl_zdot3(w0, w1, z0, z1, p):
    return V.dahl_zdot3(w0, w1, z0, z1, p)


@kernel("TORQUE3_SIG")
def dahl_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    s0 = p[K.SLOT_SIGMA0]
    return s0 * z0, s0 * z1


@kernel("BEARING_SIG")
def dahl_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    kappa = V.dahl_kappa(d0, d1, z0, z1, p)
    return V.coeff_bearing_step(V.dahl_coeffs, V.dahl_rho, True, kappa, p, Kc, d0, d1, z0, z1, dt, s0)


ENTRIES = (FrictionLawEntry("dahl", Dahl, dahl_rates, dahl_zdot3, dahl_torque3, dahl_bearing,
                            rates_lanes=dahl_rates_lanes, **DAHL_FIT),)
