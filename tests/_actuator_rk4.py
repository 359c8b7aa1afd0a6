"""Classical RK4 of the actuator alone against a constant load force, compiled (numba) for
tests/test_pressure_limit.py: the linear state space plus the packed valve/pressure limits of
:func:`taos.planar.saturation.apply_valve_pressure`, the command ``x_c = gain x_p + offset`` [m]
held over each step. The same arithmetic as the plain-Python loop it replaces, without the
Python call overhead of its 120,000 derivative evaluations per run. Not cached on disk: a
cached test kernel would not notice a change of the library kernel it calls."""

from __future__ import annotations

import numpy as np
from numba import njit

from taos.planar.saturation import apply_valve_pressure


@njit(cache=False)
def _derivative(A, bx, bf, lim, x, xc, force_N, R):
    dx = A @ x + bx * xc + bf * force_N
    apply_valve_pressure(lim, x, int(0), xc / R, dx)   # int(0): not a literal (its own specialisation in the library cache)
    return dx


@njit(cache=False)
def rk4_actuator(A, bx, bf, lim, R, force_N, ixp, xc_gain, xc_offset, dt, n_steps):
    """Final state after ``n_steps`` RK4 steps of ``dt`` [s] from rest (SI state of
    :func:`taos.planar.actuator.actuator_state_space`)."""
    x = np.zeros(A.shape[0])
    for _ in range(n_steps):
        xc = xc_gain * x[ixp] + xc_offset
        k1 = _derivative(A, bx, bf, lim, x, xc, force_N, R)
        k2 = _derivative(A, bx, bf, lim, x + 0.5 * dt * k1, xc, force_N, R)
        k3 = _derivative(A, bx, bf, lim, x + 0.5 * dt * k2, xc, force_N, R)
        k4 = _derivative(A, bx, bf, lim, x + dt * k3, xc, force_N, R)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x
