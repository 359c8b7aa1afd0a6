"""The ``none`` law's kernels (no friction torque: T_f = 0; the bearing follows the applied
increment, w = d / dt) as cached C callbacks (with the lane form of the scalar kernel,
``rates_lanes``), and its registry entry (see :mod:`._builtin`)."""

from __future__ import annotations

from ._builtin import NONE_FIT, inlined, kernel
from ._law_zero import zero_zdot3
from ._laws import NoFriction
from .registry import FrictionLawEntry


@kernel("RATES_SIG")
def none_rates(v, z, t_app, p):
    return 0.0, 0.0


_law = inlined(none_rates)


@kernel("LANES_SIG")
def none_rates_lanes(v, z, t_app, P, dz, tf):
    for q in range(v.shape[0]):
        dz[q], tf[q] = _law(v[q], z[q], t_app[q], P[q])


@kernel("TORQUE3_SIG")
def none_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return 0.0, 0.0


@kernel("BEARING_SIG")
def none_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return d0 / dt, d1 / dt, 0.0, 0.0, 0.0, 0.0


ENTRIES = (FrictionLawEntry("none", NoFriction, none_rates, zero_zdot3, none_torque3, none_bearing,
                            rates_lanes=none_rates_lanes, **NONE_FIT),)
