"""The avionics command path over one integration step of the 3-D model: the post-avionics
commands [rad] its RK4 stages take (:func:`stage_inputs`), and the exact mean of a quantised command
path over a linear ramp (:func:`command_mean`), which places the quantiser's jumps in time to first
order instead of at the stage points."""

from __future__ import annotations

import math

from numba import njit

from ..planar import _avionics_kernels as _av
from ..planar._avionics_slots import AV_LSB, AV_ROUND
from ._so3 import _FM


@njit(cache=True, error_model="numpy")
def command_mean(c0, c1, p):
    """Mean of the avionics command path (:func:`taos.planar.avionics.apply`, packed parameters ``p``)
    over a command ramping linearly from ``c0`` to ``c1`` [rad] (one integration step) [rad].
    With quantisation the command path is piecewise constant in the command (bins of one LSB,
    edges at k LSB for truncation, (k + 1/2) LSB for rounding; the crossover gain is a
    function of the quantised value), so the mean is the bin values weighted by the fraction
    of the ramp in each bin: an integrator that uses it for a step places the output's jumps
    in time to first order instead of at its stage points. ``p``: slots ``AV_*``."""
    lo = min(c0, c1)
    hi = max(c0, c1)
    lsb = p[AV_LSB]
    if lsb <= 0.0 or hi - lo <= 0.0:
        return _av.apply(0.5 * (lo + hi), p)
    off = 0.5 if p[AV_ROUND] > 0.5 else 0.0
    k = math.floor(lo / lsb - off) + 1.0
    b = (k + off) * lsb  # first bin edge above lo
    a = lo
    s = 0.0
    while b < hi:
        s += (b - a) * _av.apply(0.5 * (a + b), p)
        a = b
        k += 1.0
        b = (k + off) * lsb
    s += (hi - a) * _av.apply(0.5 * (a + hi), p)
    return s / (hi - lo)


@njit(cache=True, fastmath=_FM, error_model="numpy")
def stage_inputs(c0, cm, c1, avp):
    """Post-avionics commands [rad] for the RK4 stages (start, middle, end; pitch and yaw) of a
    step with pre-avionics commands c0/cm/c1 (2,) at its start, middle and end. A quantised
    command path is piecewise constant in time: every stage then takes its mean over the step
    (:func:`command_mean`), which places its jumps in time to first order
    (sampled at the stages, a jump would move to a stage point: an O(dt) error). ``avp`` the
    packed avionics (``AV_*``). Returns (u0, u1) at the start, the middle and the end."""
    if avp[AV_LSB] > 0.0:
        a0 = command_mean(c0[0], c1[0], avp)
        a1 = command_mean(c0[1], c1[1], avp)
        return a0, a1, a0, a1, a0, a1
    return (_av.apply(c0[0], avp), _av.apply(c0[1], avp), _av.apply(cm[0], avp), _av.apply(cm[1], avp),
            _av.apply(c1[0], avp), _av.apply(c1[1], avp))

