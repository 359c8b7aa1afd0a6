#!/usr/bin/env python
"""Benchmark: rebuild fem_data/ from nothing, with a peer baseline in the same run.

* rebuild: taos.fem.build.build_fem_data into a temporary directory (fine meshes, as shipped;
  ``--coarse`` for the test-size build), wall time per stage;
* peer baseline: stiffness assembly of the same quadratic hexahedral mesh with scikit-fem's
  generic BilinearForm (``skfem.models.elasticity.linear_elasticity``) against the vectorised
  assembly of taos.fem.elasticity, and the agreement of the two matrices.

Prints a Markdown table for benchmarks/RESULTS.md (``--out FILE`` also writes it).
Usage: python benchmarks/bench_fem_rebuild.py [--coarse] [--out PATH]
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from taos.fem import TI_6AL_4V  # noqa: E402
from taos.fem.build import build_fem_data  # noqa: E402
from taos.fem.elasticity import assemble_elasticity  # noqa: E402
from taos.fem.mesh import curved_mesh, tube_mesh  # noqa: E402


def peer_assembly(h: float = 0.03, n_theta: int = 8) -> dict:
    from skfem import Basis, ElementHexS2, ElementVector
    from skfem.models.elasticity import lame_parameters, linear_elasticity
    rm = tube_mesh(0.03, 0.06, 0.8, h, n_theta)
    mesh = curved_mesh(rm, n_theta)
    t0 = time.perf_counter()
    ours = assemble_elasticity(mesh, TI_6AL_4V)
    t_ours = time.perf_counter() - t0
    t0 = time.perf_counter()
    vb = Basis(mesh, ElementVector(ElementHexS2()), intorder=4)
    lam, mu = lame_parameters(TI_6AL_4V.youngs_modulus_Pa, TI_6AL_4V.poisson_ratio)
    Kp = linear_elasticity(lam, mu).assemble(vb)
    t_peer = time.perf_counter() - t0
    # map skfem's vector DOF numbering onto ours (3 d + c) through the split indices
    perm = np.empty(Kp.shape[0], int)
    for c, ix in enumerate(vb.split_indices()):
        perm[ix] = 3 * np.arange(ix.size) + c
    P = Kp.tocoo()
    from scipy.sparse import csr_matrix
    Kp2 = csr_matrix((P.data, (perm[P.row], perm[P.col])), shape=Kp.shape)
    diff = abs(Kp2 - ours.K).max() / abs(ours.K).max()
    return {"dofs": ours.ndofs, "elements": ours.nelements, "ours_s": t_ours, "peer_s": t_peer, "rel_diff": diff}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--coarse", action="store_true")
    ap.add_argument("--out", type=Path, default=None,
                    help="also write the table here (default: print only; paste into benchmarks/RESULTS.md)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        s = build_fem_data(Path(tmp), coarse=args.coarse, log=lambda *a: None)
        total = time.perf_counter() - t0
        files = sorted(p.name for p in Path(tmp).iterdir())
    peer = peer_assembly()
    t = s["timing"]
    lines = [
        "# FEM data rebuild benchmark",
        "",
        f"Command: `python benchmarks/bench_fem_rebuild.py{' --coarse' if args.coarse else ''}`; machine: "
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores (shared), Python {platform.python_version()}.",
        "",
        f"## Rebuild of fem_data/ from nothing ({'coarse' if args.coarse else 'fine, as shipped'})",
        "",
        "| stage | wall time [s] |",
        "|---|---|",
        f"| FE verification (cantilever tube) | {t['verification_s']:.1f} |",
    ]
    for lv in s["levels"]:
        lines.append(f"| gimbal level h = {lv.spec.h} m, n_theta = {lv.spec.n_theta} "
                     f"({lv.halves['upper', 'thrust'].n_dofs} + {lv.halves['lower', 'thrust'].n_dofs} DOFs, "
                     f"2 halves x 2 conditions) | {lv.seconds:.1f} |")
    lines += [
        f"| thrust-structure modes ({s['modes'].n_dofs} DOFs) | {t['modes_s']:.1f} |",
        f"| **total** | **{total:.1f}** |",
        "",
        f"Files written: {', '.join(files)}.",
        "",
        "## Peer baseline: stiffness assembly, same mesh",
        "",
        f"Quadratic serendipity hexahedra, tube mesh, {peer['elements']} elements, {peer['dofs']} DOFs.",
        "",
        "| assembler | wall time [s] |",
        "|---|---|",
        f"| scikit-fem generic `linear_elasticity` BilinearForm | {peer['peer_s']:.2f} |",
        f"| taos.fem.elasticity vectorised einsum | {peer['ours_s']:.2f} |",
        "",
        f"Speed-up x{peer['peer_s'] / peer['ours_s']:.0f}; matrices agree to max|dK|/max|K| = {peer['rel_diff']:.1e}.",
        "",
    ]
    if args.out is not None:
        args.out.write_text("\n".join(lines))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
