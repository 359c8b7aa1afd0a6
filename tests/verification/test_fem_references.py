"""FE elasticity (quadratic hexahedra, Guyan condensation) against beam theory and exact
geometry (Timoshenko & Goodier; Cowper's shear coefficient for a tube)."""

from __future__ import annotations

import numpy as np
import pytest

from taos.fem import TI_6AL_4V, assemble_elasticity, cantilever_tube_check
from taos.fem.mesh import curved_mesh, tube_mesh


@pytest.fixture(scope="module")
def tube():
    return cantilever_tube_check(h=0.02, n_theta=8)


REFS = {"axial": "bar L/(EA)", "torsion": "Saint-Venant torsion L/(G J)",
        "lateral": "Timoshenko beam L^3/(3EI) + L/(k G A) (Cowper k)", "rotation": "Euler-Bernoulli L/(EI)"}


@pytest.mark.parametrize("name", ["axial", "torsion", "lateral", "rotation"])
def test_cantilever_tube_tip_compliance_beam_theory(tube, name, verify):
    tol = 0.005 if name == "torsion" else 0.03
    verify(REFS[name], tol, abs(getattr(tube, name) - 1.0), case=f"tube tip compliance, {name}")


def test_condensed_matrix_null_space_is_the_rigid_body_motions(tube, verify):
    verify("rigid-body motions carry no force (K R = 0)", 1e-9, tube.null_residual, unit="relative to max|K|")


def test_curved_mesh_gives_exact_tube_volume(verify):
    from taos.fem.elasticity import volume

    rm = tube_mesh(0.03, 0.06, 0.4, 0.03, 8)
    model = assemble_elasticity(curved_mesh(rm, 8), TI_6AL_4V)
    exact = np.pi * (0.06 ** 2 - 0.03 ** 2) * 0.4
    verify("exact volume pi (b^2 - a^2) L", 2e-3, abs(volume(model) / exact - 1))
