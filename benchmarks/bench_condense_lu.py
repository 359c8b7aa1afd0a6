"""The sparse solve of the Guyan condensation (taos.fem.elasticity.guyan_condense): CHOLMOD's
supernodal Cholesky (taos.fem.elasticity.spd_inverse_form's "cholmod", with the optional cvxopt)
against SuperLU's LU with a symmetric minimum-degree order and diagonal pivots ("superlu", the
default without cvxopt and the previous method, the peer), in the same run on the
same matrices: the interior blocks K_II of the four condensations (2 gimbal halves x 2 load
conditions) of one level of the shipped FEM shift sweep (its nominal point, as
tests/test_fem_shift.py recomputes it), each with its own 12 columns B = K_IS T: the product
B^T K_II^-1 B that the condensation subtracts.

    .venv/bin/python benchmarks/bench_condense_lu.py

Prints for each matrix and method: factorisation + solve + product CPU time [s] (best of 3;
CHOLMOD's includes the conversion to cvxopt's sparse format and the symbolic analysis), its wall time
(single-threaded if wall ~ CPU on an idle machine), the stored factor entries (L + U for SuperLU,
L for CHOLMOD) and the largest difference of B^T K_II^-1 B from the peer's, relative to its
largest entry. Then the CPU time of one whole level (taos.fem.build.run_level: assembly and four
condensations).
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

import taos.fem.elasticity as el
from taos.fem.build import engine_actuator_line, run_level
from taos.fem.gimbal import MeshSpec
from taos.fem.shift import fem_shift_share, swept_geometry


def superlu(A: sp.spmatrix, B: np.ndarray) -> tuple[np.ndarray, int]:
    """el.spd_inverse_form's SuperLU (the default without cvxopt; the previous method); the
    factor's entries counted separately."""
    return el.spd_inverse_form(A, B, "superlu"), -1


def superlu_fill(A: sp.spmatrix) -> int:
    """Entries of SuperLU's L + U for A (not timed)."""
    lu = splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    return lu.L.nnz + lu.U.nnz


def cholmod(A: sp.spmatrix, B: np.ndarray) -> tuple[np.ndarray, int]:
    """el.spd_inverse_form's CHOLMOD (the optional cvxopt); the factor's entries counted separately."""
    return el.spd_inverse_form(A, B, "cholmod"), -1


def cholmod_fill(A: sp.spmatrix) -> int:
    """Entries of CHOLMOD's L for A (not timed)."""
    from cvxopt import cholmod as ch, spmatrix
    L = sp.tril(A, format="coo")
    M = spmatrix(L.data, L.row.astype(np.int64), L.col.astype(np.int64), A.shape)
    F = ch.symbolic(M, uplo="L")
    ch.numeric(M, F)
    return len(ch.getfactor(F))


METHODS = {"SuperLU LU, MMD(A + A^T), diagonal pivots (default; peer)": superlu,
           "CHOLMOD supernodal Cholesky, AMD (fem-fast extra)": cholmod}


def level() -> tuple[list[tuple[sp.spmatrix, np.ndarray]], float]:
    """The (K_II, K_IS T) pairs guyan_condense solves on one sweep level, and the level's CPU [s]."""
    seen = []
    real = el.spd_inverse_form

    def spy(A, B, solver=None):
        seen.append((A, B.copy()))
        return real(A, B, solver)

    r = fem_shift_share()
    spec, line = MeshSpec(r.mesh_h_m, r.mesh_n_theta), engine_actuator_line()
    geom = swept_geometry(0.004, 0.110)
    el.spd_inverse_form = spy
    try:
        run_level(geom, spec, line)
    finally:
        el.spd_inverse_form = real
    t = time.process_time()
    run_level(geom, spec, line)
    return seen, time.process_time() - t


def main() -> None:
    blocks, t_level = level()
    print("| K_II (n, nnz) | method | CPU [s] | wall [s] | factor entries | B^T K_II^-1 B vs peer |")
    print("|---|---|---|---|---|---|")
    for A, B in blocks:
        ref = None
        for name, f in METHODS.items():
            tc = tw = np.inf
            for _ in range(3):
                t, w = time.process_time(), time.perf_counter()
                x, fill = f(A, B)
                tc, tw = min(tc, time.process_time() - t), min(tw, time.perf_counter() - w)
            fill = (superlu_fill if f is superlu else cholmod_fill)(A)
            ref = x if ref is None else ref
            print(f"| {A.shape[0]:,}, {A.nnz:,} | {name} | {tc:.2f} | {tw:.2f} | {fill:,} | "
                  f"{np.abs(x - ref).max() / np.abs(ref).max():.1e} |")
    print(f"\nrun_level (assembly of 2 halves + 4 condensations), CPU: {t_level:.2f} s")


if __name__ == "__main__":
    main()
