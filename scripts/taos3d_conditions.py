"""The 3-D model's hot fire, ambient and flight conditions side by side (benchmarks/RESULTS.md,
"Hot fire vs ambient in the 3-D model"): the bearing friction level T_c = mu N r_b of each
condition's normal load N, the gimbal chain's pitch/yaw stiffness S^T K_s S of each FEM pair,
and the command -> piston notch of the 3-D linear model against the planar simplex model.

Usage: python scripts/taos3d_conditions.py
"""

from __future__ import annotations

import math

import numpy as np

from taos.model import load_model
from taos.planar.simplex import load_resonance_from_notch
from taos.taos3d import taos_model
from taos.taos3d.calibrate import taos_notch_hz
from taos.units import N_PER_M_PER_LBF_PER_IN, NM_PER_IN_LBF


def main() -> None:
    for name in ("rs25_hotfire", "rs25_ambient", "rs25_flight"):
        m = load_model(name)
        tm = taos_model(m)
        g = tm.gimbal
        S = tm.bearing_selection
        k = S.T @ tm.chain_stiffness @ S
        simplex = load_resonance_from_notch(m, "pitch")
        notch = taos_notch_hz(tm, simplex, "pitch")
        print(f"{name}: N = {tm.normal_load_N / 1e3:,.1f} kN, mu = {g.friction_coefficient:.4f}, "
              f"r_b = {g.bearing_radius_m:.3f} m -> T_c = mu N r_b = {tm.coulomb_torque_Nm:,.0f} N m "
              f"({tm.coulomb_torque_Nm / NM_PER_IN_LBF:,.0f} in-lbf; the law's coulomb_torque "
              f"{m.friction.coulomb_torque_Nm:,.0f} N m)")
        print(f"  chain pitch/yaw stiffness S^T K_s S: {np.diag(k)[0]:.3g}, {np.diag(k)[1]:.3g} N m/rad; "
              f"K_L R^2 = {m.structure.load_stiffness_N_per_m * m.actuator.moment_arm_m ** 2:.3g} N m/rad")
        print(f"  K_L = {m.structure.load_stiffness_N_per_m / N_PER_M_PER_LBF_PER_IN:,.0f} lbf/in, line stiffness "
              f"{tm.line_load_stiffness_N_per_m / N_PER_M_PER_LBF_PER_IN:,.0f} lbf/in; command -> piston notch "
              f"(pitch): 3-D {notch:.3f} Hz, simplex {simplex:.3f} Hz, load resonance eq. 1 "
              f"{m.load_resonance_hz('pitch'):.3f} Hz")
    assert math.isfinite(notch)


if __name__ == "__main__":
    main()
