"""Linear elasticity with scikit-fem, rigid (RBE2-type) interface couplings, Guyan condensation.

Equations (small strain, isotropic, SI)::

    sigma = lambda tr(eps) I + 2 mu eps,   eps = (grad u + grad u^T) / 2
    lambda = E nu / ((1 + nu)(1 - 2 nu)),  mu = E / (2 (1 + nu))
    K = int_V eps(v) : sigma(u) dV                                   (stiffness, N/m)

Elements: 20-node serendipity hexahedra (:class:`~skfem.ElementHexS2`, quadratic
displacement, free of shear locking in bending for the regular meshes built here) on
27-node quadratic-geometry meshes (:func:`taos.fem.mesh.curved_mesh`).

Interface coupling (RBE2, rigid): every displacement DOF on an interface surface follows
the rigid motion of a reference point x_ref with 6 DOFs q = (u, theta)::

    u(x) = u_ref + theta x (x - x_ref)

i.e. the interface surface is kinematically rigid, as a stiff bolted flange or a closed,
stuck bearing contact (NASTRAN RBE2 with all 6 components). This is the kinematic
transformation u_S = T q.

Static (Guyan 1965) condensation onto the reference DOFs (exact for static loads applied
at the reference points)::

    K_c = T^T K_SS T - (K_IS T)^T K_II^-1 (K_IS T)

where S are the coupled surface DOFs and I all other (interior) DOFs. K_II is symmetric
positive definite (the interfaces hold every rigid-body motion) and is solved by a sparse
Cholesky factorisation, P K_II P^T = L L^T (:func:`spd_inverse_form`: CHOLMOD, supernodal,
AMD order, when the optional cvxopt is installed) or SciPy's SuperLU (otherwise).

References: R. J. Guyan, "Reduction of stiffness and mass matrices", AIAA J. 3(2), 1965;
Y. Chen, T. A. Davis, W. W. Hager, S. Rajamanickam, "Algorithm 887: CHOLMOD, supernodal sparse
Cholesky factorization and update/downdate", ACM Trans. Math. Softw. 35(3), 22, 2008.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementHexS2, Mesh


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    youngs_modulus_Pa : E [Pa]; poisson_ratio : nu [-]; density_kg_m3 : rho [kg/m^3].
    """

    name: str
    youngs_modulus_Pa: float
    poisson_ratio: float
    density_kg_m3: float

    @property
    def lame(self) -> tuple[float, float]:
        """(lambda, mu) [Pa]."""
        E, nu = self.youngs_modulus_Pa, self.poisson_ratio
        return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))

    @property
    def shear_modulus_Pa(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.lame[1]


#: Ti-6Al-4V, annealed (MIL-HDBK-5J / MMPDS typical values): E = 113.8 GPa, nu = 0.342,
#: rho = 4430 kg/m^3. The SSME gimbal bearing is titanium (public).
TI_6AL_4V = Material("Ti-6Al-4V annealed", 113.8e9, 0.342, 4430.0)


@dataclass(frozen=True)
class Interface:
    """An interface surface coupled rigidly (RBE2) to a reference point.

    name : label; nodes : mesh vertex indices spanning the surface (a boundary facet is on
    the interface when all its vertices are); ref_point_m : (3,) reference point [m].
    """

    name: str
    nodes: np.ndarray
    ref_point_m: tuple[float, float, float]


@dataclass(frozen=True)
class ElasticModel:
    """An assembled FE model.

    basis : scalar scikit-fem basis (ElementHexS2); displacement DOF ``3 d + c`` is component
    c (0 = x, 1 = y, 2 = z) at scalar DOF d, located at ``basis.doflocs[:, d]`` [m].
    K : stiffness [N/m] (csr, symmetric).
    """

    basis: Basis
    K: sp.csr_matrix
    material: Material

    @property
    def ndofs(self) -> int:
        return int(self.K.shape[0])

    @property
    def nelements(self) -> int:
        return int(self.basis.mesh.nelements)


def assemble_elasticity(mesh: Mesh, material: Material, chunk: int = 256) -> ElasticModel:
    """Assemble the linear-elastic stiffness matrix of ``mesh`` (coordinates in m).

    Element matrices are formed with 3x3x3 Gauss quadrature from the scalar shape-function
    gradients G_a = grad N_a (vectorised, instead of scikit-fem's per-basis-pair loop)::

        K_e[a i, b j] = sum_q w_q (lambda G_ai G_bj + mu G_aj G_bi + mu delta_ij G_ak G_bk)

    ``chunk`` elements at a time are written into one coordinate (COO) list of all elements,
    summed into CSR once: the per-chunk temporaries stay small (7 MB at 256 elements) and are
    reused instead of fresh pages at every step, the sum does not depend on ``chunk``.
    """
    lam, mu = material.lame
    basis = Basis(mesh, ElementHexS2(), intorder=4)
    nb = basis.element_dofs.shape[0]
    G = np.array([basis.basis[a][0].grad for a in range(nb)])  # (nb, 3, ne, nq)
    n = 3 * basis.N
    ne = basis.element_dofs.shape[1]
    m = (3 * nb) ** 2  # entries of one element matrix
    itype = np.int32 if n < 2 ** 31 else np.int64
    data = np.empty(ne * m)
    rows = np.empty(ne * m, itype)
    cols = np.empty(ne * m, itype)
    eye3 = np.eye(3)
    for e0 in range(0, ne, chunk):
        e1 = min(ne, e0 + chunk)
        sl = slice(e0, e1)
        g = G[:, :, sl]
        A = np.einsum("aien,bjen->eaibj", g * basis.dx[None, None, sl], g, optimize=True)
        tr = np.einsum("eakbk->eab", A)
        Ke = lam * A + mu * A.transpose(0, 1, 4, 3, 2) + mu * tr[:, :, None, :, None] * eye3[None, None, :, None, :]
        dof = (3 * basis.element_dofs[:, sl].T[:, :, None] + np.arange(3)[None, None, :]).reshape(-1, 3 * nb)
        out = slice(e0 * m, e1 * m)
        data[out] = Ke.reshape(-1)
        rows[out].reshape(-1, 3 * nb, 3 * nb)[...] = dof[:, :, None]
        cols[out].reshape(-1, 3 * nb, 3 * nb)[...] = dof[:, None, :]
    K = sp.csr_matrix((data, (rows, cols)), shape=(n, n))
    K = 0.5 * (K + K.T)
    return ElasticModel(basis, K.tocsr(), material)


def volume(model: ElasticModel) -> float:
    """Volume of the meshed body [m^3] (integral of 1 with the element quadrature)."""
    return float(model.basis.dx.sum())


def interface_dofs(model: ElasticModel, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """DOFs on the boundary facets spanned by ``nodes``: (dof indices, components, locations)."""
    mesh = model.basis.mesh
    bf = mesh.boundary_facets()
    mask = np.zeros(mesh.p.shape[1], bool)
    mask[np.asarray(nodes)] = True
    sel = bf[np.all(mask[mesh.facets[:, bf]], axis=0)]
    if sel.size == 0:
        raise ValueError("interface selects no boundary facet")
    sdofs = np.unique(model.basis.get_dofs(facets=sel).all())
    dofs = (3 * sdofs[:, None] + np.arange(3)[None, :]).ravel()
    comp = np.tile(np.arange(3), sdofs.size)
    locs = np.repeat(model.basis.doflocs[:, sdofs], 3, axis=1)
    return dofs, comp, locs


def rigid_transform(locs: np.ndarray, comp: np.ndarray, ref: Sequence[float]) -> np.ndarray:
    """T (n, 6) with u_dof = T q, q = (ux, uy, uz, rx, ry, rz) of the reference point.

    u = u_ref + theta x r, r = x - x_ref:
    u_x = ux + ry r_z - rz r_y;  u_y = uy + rz r_x - rx r_z;  u_z = uz + rx r_y - ry r_x.
    """
    r = locs - np.asarray(ref, float)[:, None]
    n = comp.size
    T = np.zeros((n, 6))
    T[np.arange(n), comp] = 1.0
    rx, ry, rz = r
    cx, cy, cz = comp == 0, comp == 1, comp == 2
    T[cx, 4], T[cx, 5] = rz[cx], -ry[cx]
    T[cy, 3], T[cy, 5] = -rz[cy], rx[cy]
    T[cz, 3], T[cz, 4] = ry[cz], -rx[cz]
    return T


#: the sparse solvers of :func:`spd_inverse_form`
SPD_SOLVERS = ("cholmod", "superlu")


def spd_solver() -> str:
    """The default solver of :func:`spd_inverse_form`: ``"cholmod"`` when the optional ``cvxopt``
    package (the extra ``fem-fast``; GPL-3.0, as CHOLMOD's supernodal module) is installed, else
    ``"superlu"`` (SciPy, no further dependency)."""
    import importlib.util

    return "cholmod" if importlib.util.find_spec("cvxopt") is not None else "superlu"


def spd_inverse_form(A: sp.spmatrix, B: np.ndarray, solver: str | None = None) -> np.ndarray:
    """Q = B^T A^-1 B (k, k) for a sparse symmetric positive definite A (n, n) and a dense B (n, k).

    Units: those of B^T B over those of A (here N/m, N/rad, N m/m, N m/rad). ``solver`` (default
    :func:`spd_solver`), equal to round-off (tests/test_fem_verification.py):

    * ``"cholmod"``: sparse Cholesky factorisation P A P^T = L D L^T with CHOLMOD (Chen, Davis,
      Hager, Rajamanickam 2008, ACM TOMS 35(3) 22; SuiteSparse as bundled by the optional cvxopt
      wheel): approximate minimum degree (AMD) fill-reducing order, supernodal numeric
      factorisation on dense BLAS blocks (cvxopt's single-threaded OpenBLAS; D = I then) or
      simplicial L D L^T for small matrices (CHOLMOD's choice). Then Q = Z^T D^-1 Z with
      Z = L^-1 P B: one forward substitution, half the work of solving A X = B. Only the lower
      triangle of A is read. Raises ArithmeticError if A is not positive definite.
    * ``"superlu"``: SciPy's SuperLU LU with a symmetric fill-reducing order (minimum degree on
      A + A^T) and diagonal pivots (symmetric mode), Q = B^T (A^-1 B).

    On the interior blocks of the gimbal halves (18-19k DOFs) CHOLMOD takes about a third of
    SuperLU's CPU and stores L only (8-11 M entries against 16-22 M in L + U)
    (benchmarks/bench_condense_lu.py).
    """
    solver = spd_solver() if solver is None else solver
    if solver == "superlu":
        from scipy.sparse.linalg import splu

        lu = splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        return B.T @ lu.solve(B)
    if solver != "cholmod":
        raise ValueError(f"solver must be one of {SPD_SOLVERS}, got {solver!r}")
    # imported here: cvxopt is only needed by the FEM rebuild, not at taos start-up
    from cvxopt import cholmod, matrix, spmatrix
    L = sp.tril(A, format="coo")
    M = spmatrix(L.data, L.row.astype(np.int64), L.col.astype(np.int64), A.shape)
    F = cholmod.symbolic(M, uplo="L")
    try:
        cholmod.numeric(M, F)
    except ArithmeticError as e:
        raise ArithmeticError(f"matrix not positive definite (CHOLMOD stopped at column {e})") from None
    Z = matrix(np.asarray(B, float))
    cholmod.solve(F, Z, sys=7)  # P B
    cholmod.solve(F, Z, sys=4)  # L^-1 P B
    W = matrix(Z)
    cholmod.solve(F, W, sys=6)  # D^-1 L^-1 P B
    return np.array(Z).T @ np.array(W)


def guyan_condense(model: ElasticModel, interfaces: Sequence[Interface], solver: str | None = None) -> np.ndarray:
    """Condense the model onto the 6 DOFs of each interface reference point (RBE2 + Guyan).

    Returns the symmetric (6 m, 6 m) free-free stiffness in SI units (N/m, N/rad, N m/m,
    N m/rad blocks), DOF order (ux, uy, uz, rx, ry, rz) per reference point, in the order
    of ``interfaces``. ``solver``: that of :func:`spd_inverse_form` (default :func:`spd_solver`).
    """
    K = model.K
    n = model.ndofs
    m = len(interfaces)
    rows, cols, vals = [], [], []
    slave = np.zeros(n, bool)
    for k, itf in enumerate(interfaces):
        dofs, comp, locs = interface_dofs(model, itf.nodes)
        if np.any(slave[dofs]):
            raise ValueError(f"interface {itf.name} overlaps another interface")
        slave[dofs] = True
        T = rigid_transform(locs, comp, itf.ref_point_m)
        rr, cc = np.nonzero(T)
        rows.append(dofs[rr])
        cols.append(6 * k + cc)
        vals.append(T[rr, cc])
    Tfull = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, 6 * m))
    S = np.flatnonzero(slave)
    interior = np.flatnonzero(~slave)
    TS = Tfull[S]
    KSS = (TS.T @ K[S][:, S] @ TS).toarray()
    KIS_T = (K[interior][:, S] @ TS).toarray()
    Kc = KSS - spd_inverse_form(K[interior][:, interior], KIS_T, solver)
    return 0.5 * (Kc + Kc.T)


def rigid_body_modes(ref_points: np.ndarray, origin: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """(6 m, 6) reference-point motions of the 6 rigid-body motions about ``origin``.

    Column j is the unit translation (j < 3) or unit rotation (j >= 3) of the whole body;
    a free-free condensed stiffness K satisfies K @ R = 0.
    """
    pts = np.atleast_2d(np.asarray(ref_points, float))
    R = np.zeros((6 * len(pts), 6))
    for k, p in enumerate(pts):
        comp = np.array([0, 1, 2])
        T = rigid_transform((p - np.asarray(origin))[:, None].repeat(3, 1) + np.asarray(origin)[:, None],
                            comp, origin)
        R[6 * k:6 * k + 3] = T
        R[6 * k + 3:6 * k + 6, 3:] = np.eye(3)
    return R
