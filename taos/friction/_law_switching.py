"""The stick-slip switching Coulomb law's kernels (:func:`._kernels.coulomb_switching_torque`,
:func:`._vector.switching_torque3`, :func:`._vector.switching_bearing_step`) as cached C
callbacks (with the lane form of the scalar kernel, ``rates_lanes``), and its registry entry
(see :mod:`._builtin`)."""

from __future__ import annotations

from . import _kernels as K
from . import _vector as V
from ._builtin import COULOMB_FIT, inlined, kernel
from ._law_zero import zero_zdot3
from ._laws import CoulombSwitching
from .registry import FrictionLawEntry


@kernel("RATES_SIG")
def switching_rates(v, z, t_app, p):
    return 0.0, K.coulomb_switching_torque(v, t_app, p)


_law = inlined(switching_rates)


@kernel("LANES_SIG")
def switching_rates_lanes(v, z, t_app, P, dz, tf):
    for q in range(v.shape[0]):
        dz[q], tf[q] = _law(v[q], z[q], t_app[q], P[q])


@kernel("TORQUE3_SIG")
def switching_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.switching_torque3(w0, w1, t0, t1, p)


@kernel("BEARING_SIG")
def switching_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.switching_bearing_step(p, Kc, d0, d1, z0, z1, dt, s0)


ENTRIES = (FrictionLawEntry("coulomb-switching", CoulombSwitching, switching_rates, zero_zdot3,
                            switching_torque3, switching_bearing, rates_lanes=switching_rates_lanes,
                            **COULOMB_FIT),)
