"""Describing functions: the nonlinearity interface, the analytic ones and the numeric ones.

In the spirit of python-control's ``descfcn`` module. A nonlinearity is a small class
(:class:`Nonlinearity`) called on its input, ``F(x)``, with an optional analytic
``describing_function(A, w)`` (``None`` where there is none). For an input A sin(w t) the
describing function is the complex ratio of the output's fundamental to the input's
(Gelb & Vander Velde, *Multiple-Input Describing Functions and Nonlinear System Design*,
McGraw-Hill, 1968, ch. 2):

    N(A, w) = (1 / (pi A)) int_0^{2 pi} y(psi) (sin psi + j cos psi) dpsi,   psi = w t,

y the periodic output (for a static nonlinearity y = F(A sin psi) and N does not depend on w).

Numeric describing functions (the two entry points):

* :func:`static_describing_function` - a memoryless F, by the midpoint rule over one period;
* :func:`simulated_describing_function` - a nonlinearity with memory, from a simulated response
  to a sine, the fundamental of its last whole cycle (the friction laws'
  :meth:`taos.friction.FrictionLaw.numeric_describing_function`).

Analytic describing functions:

* :class:`Relay` (ideal relay D sign(x)): N = 4 D / (pi A); Coulomb friction T_c sign(v) is
  the relay of level T_c on the rate (:func:`coulomb_describing_function`,
  :func:`coulomb_relay_level`);
* :class:`Saturation` (unit slope, limit L): N = (2/pi) (asin r + r sqrt(1 - r^2)), r = L / A,
  and 1 for A <= L (Gelb & Vander Velde, table 2.3-1);
* :func:`dahl_angle_df` - the Dahl law (exponent 1), its exact hysteresis loop.

The TVC's describing function N(A, w) with friction and avionics in the path, measured by sine
dwells on the simplex model, is :mod:`taos.flight.describing`; the limit-cycle solution
L0 N = -1 of the flight loop is :mod:`taos.flight.lco`.
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np


class Nonlinearity(abc.ABC):
    """A nonlinearity ``F``: ``F(x)`` is its output; :meth:`describing_function` its analytic
    describing function where one exists (else ``None``)."""

    @abc.abstractmethod
    def __call__(self, x):
        """Output for input ``x`` (a value or an array)."""

    def describing_function(self, amplitude: float, omega_rad_s: float | None = None) -> complex | None:
        """Analytic describing function at input amplitude ``amplitude`` A (> 0, the input's
        unit) and frequency ``omega_rad_s`` w [rad/s] (needed only with memory): output
        fundamental over A [output unit / input unit], or ``None`` if there is none."""
        return None


# -- numeric --------------------------------------------------------------------------------
def static_describing_function(F: Callable, amplitude: float, n: int = 4096) -> complex:
    """Describing function of a memoryless ``F`` at input amplitude ``amplitude`` A (> 0):
    the fundamental of F(A sin psi) over A, by the midpoint rule on ``n`` points of one period
    (exact for the harmonics below n/2; a discontinuity costs O(1/n)). ``F`` takes an array."""
    psi = (np.arange(n) + 0.5) * 2 * np.pi / n
    y = F(amplitude * np.sin(psi))
    a = 2 * np.mean(y * np.sin(psi))
    b = 2 * np.mean(y * np.cos(psi))
    return complex(a, b) / amplitude


def simulated_describing_function(response: Callable, amplitude: float, freq_hz: float,
                                  cycles: int = 6, steps_per_cycle: int = 4000) -> complex:
    """Describing function of a nonlinearity with memory: ``response(u, dt)`` is its output
    history for the input samples ``u`` every ``dt`` [s] (from its rest state); the input is
    u = A sin(w t) (A = ``amplitude``, w = 2 pi ``freq_hz``) for ``cycles`` periods of
    ``steps_per_cycle`` steps, and the fundamental of the output over the last whole cycle,
    divided by A, is returned (earlier cycles let the state settle)."""
    n = cycles * steps_per_cycle + 1
    dt = 1.0 / (freq_hz * steps_per_cycle)
    t = np.arange(n) * dt
    w = 2 * math.pi * freq_hz
    y = response(amplitude * np.sin(w * t), dt)
    last = slice(n - 1 - steps_per_cycle, n - 1)
    s = np.sin(w * t[last])
    c = np.cos(w * t[last])
    a = 2.0 * np.mean(y[last] * s)
    b = 2.0 * np.mean(y[last] * c)
    return complex(a, b) / amplitude


# -- analytic -------------------------------------------------------------------------------
def coulomb_relay_level(coulomb_torque_Nm):
    """4 T_c / pi [N m]: the relay describing function times the rate amplitude (float or SX)."""
    return 4.0 * coulomb_torque_Nm / math.pi


def coulomb_describing_function(coulomb_torque_Nm: float, rate_amplitude: float) -> complex:
    """4 T_c / (pi V): fundamental of T_c sign(V sin wt) over V [N m s/rad] (relay describing
    function, Gelb & Vander Velde, Multiple-Input Describing Functions, 1968)."""
    return complex(coulomb_relay_level(coulomb_torque_Nm) / rate_amplitude, 0.0)


_GL_X, _GL_W = np.polynomial.legendre.leggauss(64)


def dahl_angle_df(tc, sigma0, X):
    """Dahl (exponent 1) describing function from relative angle to torque [N m/rad] at angle
    amplitude ``X`` [rad], as (re, im); float or CasADi SX arguments.

    The periodic hysteresis loop under theta = X sin(psi) is exact: on the upward branch
    T_up = T_c - (T_c + T_top) exp(-beta (1 + sin psi)), beta = sigma_0 X / T_c,
    T_top = T_c tanh(beta) (the downward branch is its odd mirror), so the fundamental is
    N_x = (2/pi) int_{-pi/2}^{pi/2} T_up (sin psi + j cos psi) dpsi / X, integrated by
    64-point Gauss-Legendre quadrature (Dahl 1968; rate form N = N_x / (j w))."""
    if isinstance(tc, (int, float, np.floating)) and isinstance(sigma0, (int, float, np.floating)) \
            and isinstance(X, (int, float, np.floating)):
        exp, tanh = math.exp, math.tanh
    else:
        import casadi as ca
        exp, tanh = ca.exp, ca.tanh
    psi = 0.5 * math.pi * _GL_X
    w = 0.5 * math.pi * _GL_W
    beta = sigma0 * X / tc
    ttop = tc * tanh(beta)
    a = 0
    b = 0
    for p, wi in zip(psi, w):
        tu = tc - (tc + ttop) * exp(-beta * (1 + math.sin(p)))
        a = a + wi * tu * math.sin(p)
        b = b + wi * tu * math.cos(p)
    return (2 / math.pi) * a / X, (2 / math.pi) * b / X


@dataclass(frozen=True)
class Relay(Nonlinearity):
    """Ideal relay y = D sign(x), level ``level`` D (the output's unit): N(A) = 4 D / (pi A)
    (:func:`coulomb_relay_level`; Coulomb friction is the relay of level T_c on the rate)."""

    level: float

    def __call__(self, x):
        return self.level * np.sign(x)

    def describing_function(self, amplitude, omega_rad_s=None):
        return coulomb_describing_function(self.level, amplitude)


@dataclass(frozen=True)
class Saturation(Nonlinearity):
    """Unit-slope saturation y = min(max(x, -L), L), limit ``limit`` L > 0 (the input's unit):
    N(A) = 1 for A <= L, else (2/pi) (asin r + r sqrt(1 - r^2)), r = L / A (Gelb & Vander
    Velde 1968, table 2.3-1)."""

    limit: float

    def __call__(self, x):
        return np.clip(x, -self.limit, self.limit)

    def describing_function(self, amplitude, omega_rad_s=None):
        r = self.limit / amplitude
        if r >= 1.0:
            return 1.0 + 0j
        return complex(2.0 / math.pi * (math.asin(r) + r * math.sqrt(1.0 - r * r)), 0.0)
