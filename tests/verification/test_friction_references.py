"""Friction laws against their published steady-state curves and describing functions."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from taos.friction import CoulombSmooth, CoulombSwitching, LuGre, ModifiedLuGre

from ..test_friction import TC, law_cases

REFS = {"coulomb-switching": "Karnopp 1985 (stick-slip switching), sliding torque T_c sign(v)",
        "coulomb-smooth": "algebraic regularisation T_c v / sqrt(v^2 + v_eps^2)",
        "dahl": "Dahl 1968 steady state T_c sign(v)",
        "lugre": "Canudas de Wit et al. 1995 Stribeck curve g(v) + sigma_2 v",
        "modified-lugre": "modified LuGre steady state (vibration-lowered Stribeck curve)"}


@pytest.mark.parametrize("law", [law_cases()[name] for name in REFS], ids=lambda law: law.name)
def test_steady_sliding_torque_on_the_published_curve(law, verify):
    """At constant rate 7e-3 rad/s the simulated torque settles on the law's steady-state curve."""
    v = 7e-3
    s0 = getattr(law, "bristle_stiffness_Nm_per_rad", 0.0) or TC / 1e-3
    n = 40000
    dt = 400 * TC / s0 / abs(v) / n
    tq, _ = law.response(np.full(n, v), dt)
    ref = float(law.steady_state(v))
    verify(REFS[law.name], 1e-6, abs(tq[-1] - ref) / TC, unit="relative to T_c",
           case=f"steady sliding torque, {law.name}")


@pytest.mark.parametrize("V", [0.005, 0.1])
def test_coulomb_describing_function_gelb_vander_velde(V, verify):
    """Numeric describing function of Coulomb friction under a sinusoidal rate of amplitude V
    equals 4 T_c / (pi V) (Gelb & Vander Velde 1968)."""
    law = CoulombSmooth(coulomb_torque_Nm=TC, regularization_velocity_rad_s=1e-7)
    n = law.numeric_describing_function(V, 1.0)
    exact = 4 * TC / (math.pi * V)
    verify("Gelb & Vander Velde 1968: N(V) = 4 T_c / (pi V)", 0.02, abs(n - exact) / exact,
           case=f"Coulomb describing function, V = {V} rad/s")


def test_modified_lugre_is_lugre_without_vibration(verify):
    """Modified LuGre with zero vibration level reproduces LuGre sample for sample (identity)."""
    lug = LuGre(coulomb_torque_Nm=TC, static_torque_Nm=1.3 * TC, stribeck_velocity_rad_s=3e-3,
                bristle_stiffness_Nm_per_rad=1e7, bristle_damping_Nms_per_rad=2e5)
    mod = ModifiedLuGre(**{f.name: getattr(lug, f.name) for f in dataclasses.fields(lug)}, vibration_velocity_rad_s=0.0)
    t = np.arange(50000) * 1e-5
    v = 0.02 * np.sin(2 * np.pi * 1.3 * t)
    a, _ = lug.response(v, 1e-5)
    b, _ = mod.response(v, 1e-5)
    verify("identity: LuGre (Canudas de Wit 1995)", 0.0, float(np.max(np.abs(a - b))) / TC, unit="relative to T_c")


def test_switching_coulomb_passivity_outside_stick_band(verify):
    """Karnopp's switching law dissipates power while sliding: min T_f v over |v| >= v_stick is
    not negative (passivity)."""
    law = CoulombSwitching(coulomb_torque_Nm=TC, static_torque_Nm=TC, stick_velocity_rad_s=1e-3)
    v = np.linspace(-0.1, 0.1, 2001)
    p = np.array([law(x, 0.0, 5e3) * x for x in v])[np.abs(v) >= 1e-3]
    verify("passivity (Karnopp 1985)", 0.0, max(0.0, -float(p.min())), unit="W")
