"""FE verification against beam theory: a cantilevered hollow cylinder condensed like a gimbal half.

A tube (inner radius a, outer radius b, length L) is meshed and condensed exactly as the
gimbal halves are (RBE2 on both end faces, Guyan), the root held; its 6x6 tip compliance
C = K^-1 is compared with Timoshenko beam theory (Timoshenko & Goodier; Cowper 1966 shear
coefficient for a hollow circular section, m = a / b)::

    axial      C_zz   = L / (E A)
    torsion    C_rzrz = L / (G J),             J = pi (b^4 - a^4) / 2
    lateral    C_xx   = L^3 / (3 E I) + L / (k G A),   I = pi (b^4 - a^4) / 4
    rotation   C_ryry = L / (E I)
    k = 6 (1 + nu)(1 + m^2)^2 / ((7 + 6 nu)(1 + m^2)^2 + (20 + 12 nu) m^2)

The rigid end faces also restrain Poisson contraction and warping locally, a small end
effect (about 1 % at L / (2 b) = 6.7) included in the comparison.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .elasticity import TI_6AL_4V, Interface, Material, assemble_elasticity, guyan_condense, rigid_body_modes
from .mesh import curved_mesh, tube_mesh


@dataclass(frozen=True)
class TubeCheck:
    """FE / theory ratios of the tip compliances, and the free-free null-space residual."""

    axial: float
    torsion: float
    lateral: float
    rotation: float
    null_residual: float
    n_dofs: int

    @property
    def max_error(self) -> float:
        return max(abs(r - 1.0) for r in (self.axial, self.torsion, self.lateral, self.rotation))


def cantilever_tube_check(h: float = 0.015, n_theta: int = 12, inner_radius: float = 0.03,
                          outer_radius: float = 0.06, length: float = 0.8,
                          material: Material = TI_6AL_4V) -> TubeCheck:
    """Condense a tube (sizes in m) and compare its tip compliance with beam theory."""
    a, b, L = inner_radius, outer_radius, length
    rm = tube_mesh(a, b, L, h, n_theta)
    model = assemble_elasticity(curved_mesh(rm, n_theta), material)
    tip = np.flatnonzero(rm.node_j == rm.z_lines[-1])
    root = np.flatnonzero(rm.node_j == 0)
    refs = np.array([[0.0, 0.0, L], [0.0, 0.0, 0.0]])
    K = guyan_condense(model, [Interface("tip", tip, tuple(refs[0])), Interface("root", root, tuple(refs[1]))])
    C = np.linalg.inv(K[:6, :6])
    E, nu = material.youngs_modulus_Pa, material.poisson_ratio
    G = material.shear_modulus_Pa
    A = np.pi * (b * b - a * a)
    I = np.pi * (b ** 4 - a ** 4) / 4
    m = a / b
    k = 6 * (1 + nu) * (1 + m * m) ** 2 / ((7 + 6 * nu) * (1 + m * m) ** 2 + (20 + 12 * nu) * m * m)
    null = float(np.abs(K @ rigid_body_modes(refs)).max() / np.abs(K).max())
    return TubeCheck(axial=C[2, 2] / (L / (E * A)), torsion=C[5, 5] / (L / (G * 2 * I)),
                     lateral=C[0, 0] / (L ** 3 / (3 * E * I) + L / (k * G * A)),
                     rotation=C[4, 4] / (L / (E * I)), null_residual=null, n_dofs=model.ndofs)
