"""The smooth Coulomb law's kernels (:func:`._kernels.coulomb_smooth_torque`,
:func:`._vector.smooth_torque3`, the coefficient bearing step with
:func:`._vector.smooth_coeffs`) as cached C callbacks (with the lane form of the scalar kernel,
``rates_lanes``), and its registry entry (see :mod:`._builtin`)."""

from __future__ import annotations

from . import _kernels as K
from . import _vector as V
from ._builtin import COULOMB_FIT, inlined, kernel
from ._law_zero import zero_zdot3
from ._laws import CoulombSmooth
from .registry import FrictionLawEntry


@kernel("RATES_SIG")
def smooth_rates(v, z, t_app, p):
    return 0.0, K.coulomb_smooth_torque(v, p)


_law = inlined(smooth_rates)


@kernel("LANES_SIG")
def smooth_rates_lanes(v, z, t_app, P, dz, tf):
    for q in range(v.shape[0]):
        dz[q], tf[q] = _law(v[q], z[q], t_app[q], P[q])


@kernel("TORQUE3_SIG")
def smooth_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.smooth_torque3(w0, w1, p)


@kernel("BEARING_SIG")
def smooth_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.coeff_bearing_step(V.smooth_coeffs, V.lugre_rho, False, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


ENTRIES = (FrictionLawEntry("coulomb-smooth", CoulombSmooth, smooth_rates, zero_zdot3, smooth_torque3,
                            smooth_bearing, rates_lanes=smooth_rates_lanes, **COULOMB_FIT),)
