"""FE verification: the condensation used for the gimbal halves against beam theory."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from taos.fem import TI_6AL_4V, Interface, assemble_elasticity, cantilever_tube_check, guyan_condense, rigid_body_modes
from taos.fem.mesh import curved_mesh, tube_mesh


@pytest.fixture(scope="module")
def tube():
    return cantilever_tube_check(h=0.02, n_theta=8)


def test_cantilever_tube_tip_compliance_matches_timoshenko_beam_within_3_percent(tube):
    for name in ("axial", "torsion", "lateral", "rotation"):
        assert abs(getattr(tube, name) - 1.0) < 0.03, (name, getattr(tube, name))


def test_torsion_of_tube_is_exact_with_rigid_ends(tube):
    # Saint-Venant torsion of a circular tube has no warping: rigid ends change nothing
    assert abs(tube.torsion - 1.0) < 0.005


def test_condensed_free_free_matrix_has_the_six_rigid_body_motions_as_null_space(tube):
    assert tube.null_residual < 1e-11  # achieved 2e-13


def test_condensed_matrix_is_symmetric_positive_semidefinite_with_six_zero_modes():
    rm = tube_mesh(0.03, 0.06, 0.4, 0.03, 8)
    model = assemble_elasticity(curved_mesh(rm, 8), TI_6AL_4V)
    refs = np.array([[0, 0, 0.4], [0, 0, 0.0]])
    K = guyan_condense(model, [Interface("tip", np.flatnonzero(rm.node_j == rm.z_lines[-1]), tuple(refs[0])),
                               Interface("root", np.flatnonzero(rm.node_j == 0), tuple(refs[1]))])
    assert np.allclose(K, K.T)
    d = 1 / np.sqrt(np.diag(K))
    ev = np.linalg.eigvalsh(K * np.outer(d, d))
    assert np.sum(ev < 1e-8 * ev.max()) == 6
    assert ev.min() > -1e-8 * ev.max()
    R = rigid_body_modes(refs)
    assert np.abs(K @ R).max() < 1e-8 * np.abs(K).max()


def test_curved_geometry_gives_exact_tube_volume():
    from taos.fem.elasticity import volume
    rm = tube_mesh(0.03, 0.06, 0.4, 0.03, 8)
    model = assemble_elasticity(curved_mesh(rm, 8), TI_6AL_4V)
    exact = np.pi * (0.06 ** 2 - 0.03 ** 2) * 0.4
    assert abs(volume(model) / exact - 1) < 2e-3


@pytest.mark.parametrize("solver, supernodal", [("superlu", None), ("cholmod", 0), ("cholmod", 2)],
                         ids=["superlu", "cholmod-simplicial", "cholmod-auto"])
def test_sparse_inverse_form_matches_a_dense_solve(solver, supernodal):
    """B^T A^-1 B of both sparse solvers (SuperLU, the default without the optional cvxopt;
    CHOLMOD's simplicial L D L^T and its automatic choice) against a dense solve."""
    from cvxopt import cholmod

    from taos.fem.elasticity import spd_inverse_form
    rng = np.random.default_rng(7)
    n = 300
    R = sp.random(n, n, density=0.02, random_state=rng)
    A = (R @ R.T + sp.diags(rng.uniform(1.0, 2.0, n))).tocsr()  # sparse, symmetric positive definite
    B = rng.standard_normal((n, 5))
    want = B.T @ np.linalg.solve(A.toarray(), B)
    saved = dict(cholmod.options)
    try:
        if supernodal is not None:
            cholmod.options["supernodal"] = supernodal
        got = spd_inverse_form(A, B, solver)
    finally:
        cholmod.options.clear()
        cholmod.options.update(saved)
    assert np.abs(got - want).max() < 1e-12 * np.abs(want).max()
    if solver == "cholmod":
        with pytest.raises(ArithmeticError, match="not positive definite"):
            spd_inverse_form(A - 10.0 * sp.eye(n), B, solver)


def test_both_sparse_solvers_condense_a_gimbal_half_alike():
    """The two solvers on a real interior block (the upper gimbal half, thrust condition, on a
    coarse mesh): the same condensed matrix to round-off; the default is CHOLMOD where cvxopt is
    installed (the test extra installs it)."""
    from taos.fem import elasticity as el
    from taos.fem.gimbal import GimbalGeometry, MeshSpec, half_interfaces, half_model

    g = GimbalGeometry()
    rm, em = half_model(g, "upper", MeshSpec(0.02, 8))
    itf = half_interfaces(g, "upper", "thrust", rm)
    got = {solver: el.guyan_condense(em, itf, solver) for solver in el.SPD_SOLVERS}
    scale = np.abs(got["superlu"]).max()
    assert np.abs(got["cholmod"] - got["superlu"]).max() < 1e-10 * scale
    assert el.spd_solver() == "cholmod"
