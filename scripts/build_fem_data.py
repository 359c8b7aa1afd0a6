#!/usr/bin/env python
"""Rebuild fem_data/ from nothing: gimbal-half stiffness matrices (hanging, thrust),
mesh study, FE verification, thrust-structure modes, provenance files and README.

Usage: python scripts/build_fem_data.py [--coarse] [--out DIR]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from taos.fem.build import build_fem_data  # noqa: E402
from taos.units import N_PER_M_PER_LBF_PER_IN  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--coarse", action="store_true", help="coarse meshes (seconds; for tests)")
    ap.add_argument("--out", type=Path, default=ROOT / "fem_data", help="output directory")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    s = build_fem_data(args.out, coarse=args.coarse)
    sh = s["shift"]
    print(f"K_L ambient {sh.K_L_ambient_N_per_m / N_PER_M_PER_LBF_PER_IN:,.0f} lbf/in -> hot fire "
          f"{sh.K_L_hotfire_N_per_m / N_PER_M_PER_LBF_PER_IN:,.0f} lbf/in; modes {[round(float(f), 2) for f in s['modes'].freq_hz]} Hz")
    print(f"wrote {args.out} in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
