"""Describing functions (:mod:`taos.descfcn`): the numeric ones against the closed forms of
Gelb & Vander Velde (1968) - the ideal relay 4 D / (pi A) and the unit-slope saturation
(2/pi)(asin r + r sqrt(1 - r^2)), r = L / A - and the project's nonlinearities share the
interface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.descfcn import (Nonlinearity, Relay, Saturation, simulated_describing_function,
                          static_describing_function)


@pytest.mark.parametrize("A", [0.01, 0.3, 1.0, 7.0])
def test_relay_numeric_equals_4D_over_pi_A(A):
    """The midpoint rule puts no node on the relay's switching instants, so the numeric DF
    converges as 1/n^2 (about 1e-7 relative at n = 4096)."""
    F = Relay(2.5)
    exact = 4 * 2.5 / (math.pi * A)
    assert F.describing_function(A) == pytest.approx(exact, rel=1e-15)
    num = static_describing_function(F, A)
    assert abs(num - exact) / exact < 1e-6, (num, exact)


@pytest.mark.parametrize("A", [0.5, 1.0, 1.02, 1.5, 3.0, 20.0])
def test_saturation_numeric_equals_the_closed_form(A):
    """Limit L = 1: N = 1 up to A = L, then the closed form; the numeric DF (a kink, no jump)
    agrees within 1e-6."""
    F = Saturation(1.0)
    exact = F.describing_function(A)
    r = min(1.0, 1.0 / A)
    assert exact.real == pytest.approx(2 / math.pi * (math.asin(r) + r * math.sqrt(1 - r * r)), rel=1e-15)
    assert exact.imag == 0.0
    num = static_describing_function(F, A)
    assert abs(num - exact) < 1e-6, (A, num, exact)
    assert abs(num.imag) < 1e-12


def test_simulated_describing_function_of_a_static_relay():
    """The simulation entry point (for nonlinearities with memory) on a memoryless relay: the
    fundamental of its last whole cycle equals the relay's closed form within the rectangle
    rule's error: its nodes fall on the switching instants (sign 0 there), an O(1/n) error
    (pi / n relative, 8e-4 at n = 4000 steps per cycle)."""
    F = Relay(1.0)
    for A, f in ((0.2, 0.5), (1.0, 3.0)):
        num = simulated_describing_function(lambda u, dt: F(u), A, f)
        exact = F.describing_function(A)
        assert abs(num - exact) / abs(exact) < 2e-3, (A, f, num, exact)


def test_project_nonlinearities_share_the_interface(tmp_path):
    """Friction laws and the command avionics are :class:`Nonlinearity`; a law's simulated DF
    equals the relay's for Coulomb friction (T_c sign v is the relay of level T_c)."""
    from taos.friction import CoulombSmooth
    from taos.planar.avionics import Avionics

    law = CoulombSmooth(coulomb_torque_Nm=1000.0, regularization_velocity_rad_s=1e-6)
    assert isinstance(law, Nonlinearity) and isinstance(Avionics(), Nonlinearity)
    assert law.describing_function(0.1) == Relay(1000.0).describing_function(0.1)
    num = law.numeric_describing_function(0.1, 1.0)
    assert abs(num - Relay(1000.0).describing_function(0.1)) / abs(law.describing_function(0.1)) < 1e-3
    assert Avionics().describing_function(0.01) is None
    assert static_describing_function(Avionics(), 0.01) == pytest.approx(1.0, abs=1e-12)
    assert np.isclose(static_describing_function(lambda x: 2.0 * x, 0.3), 2.0)
