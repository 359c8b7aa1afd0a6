"""The sparse factorisation of the Guyan condensation (taos.fem.elasticity.guyan_condense):
the order it uses (symmetric minimum degree on K + K^T, diagonal pivots, for the symmetric
positive definite interior block) against the previous one (COLAMD with partial pivoting), the
peer, in the same run on the same matrix: the interior block of one gimbal half of the shipped
sweep mesh (the FEM shift sweep's nominal point, as tests/test_fem_shift.py recomputes it).

    .venv/bin/python benchmarks/bench_condense_lu.py

Prints for each order: factorisation and solve CPU time [s] (best of 3), fill (nnz of L + U)
and the largest difference of the 12-column solution from the peer's, relative to its largest
entry.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.sparse.linalg import splu

import taos.fem.elasticity as el
from taos.fem.build import engine_actuator_line, run_level
from taos.fem.gimbal import MeshSpec
from taos.fem.shift import fem_shift_share, swept_geometry

ORDERS = {
    "COLAMD, partial pivoting (previous; peer)": dict(permc_spec="COLAMD"),
    "MMD_AT_PLUS_A, diagonal pivots, symmetric mode (now)": dict(
        permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}),
}


def interior_block():
    """The first matrix guyan_condense factors while one sweep level is computed."""
    seen = []
    real = el.splu

    def spy(A, **kw):
        seen.append(A)
        return real(A, **kw)

    el.splu = spy
    try:
        r = fem_shift_share()
        run_level(swept_geometry(0.004, 0.110), MeshSpec(r.mesh_h_m, r.mesh_n_theta), engine_actuator_line())
    finally:
        el.splu = real
    return seen[0]


def main() -> None:
    A = interior_block()
    b = np.random.default_rng(0).standard_normal((A.shape[0], 12))
    print(f"interior block {A.shape[0]} x {A.shape[1]}, nnz {A.nnz}")
    print("| order | factor [s] | solve [s] | nnz(L + U) | solution vs peer |")
    print("|---|---|---|---|---|")
    ref = None
    for name, kw in ORDERS.items():
        tf = ts = np.inf
        for _ in range(3):
            t = time.process_time()
            lu = splu(A, **kw)
            t1 = time.process_time()
            x = lu.solve(b)
            tf, ts = min(tf, t1 - t), min(ts, time.process_time() - t1)
        ref = x if ref is None else ref
        print(f"| {name} | {tf:.2f} | {ts:.2f} | {lu.L.nnz + lu.U.nnz:,} | "
              f"{np.abs(x - ref).max() / np.abs(ref).max():.1e} |")


if __name__ == "__main__":
    main()
