"""The wind turbulence's recursion as a compiled kernel (:func:`taos.flight.ascent.wind_speed`).

The exact discretisation of the first-order (Ornstein-Uhlenbeck) turbulence
w' = (-w + sigma sqrt(2 tau) xi) / tau on a grid of step h is

    w_k = phi w_(k-1) + s xi_k,   phi = exp(-h / tau),   s = sigma sqrt(1 - phi^2)

(stationary RMS sigma [m/s]; xi_k standard normal). A loop in numba, without fast-math, so each
step is the same two roundings as the Python loop it replaces, bit for bit (and as
``scipy.signal.lfilter([s, 0], [1, -phi])``, which a Monte Carlo worker would otherwise import
scipy.signal for: about 0.55 CPU-s a process).
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def ou_recursion(turb, phi, s, xi):
    """turb[k] = phi turb[k-1] + s xi[k] for k >= 1, in place; ``turb[0]`` given [m/s].

    Parameters
    ----------
    turb : (n,) float64
        Turbulence [m/s]: its first entry the initial value, the rest written.
    phi : float
        exp(-h / tau), the step's decay [-].
    s : float
        sigma sqrt(1 - phi^2), the step's noise gain [m/s].
    xi : (n,) float64
        Standard normal samples [-] (``xi[0]`` unused).
    """
    for k in range(1, turb.shape[0]):
        turb[k] = phi * turb[k - 1] + s * xi[k]
