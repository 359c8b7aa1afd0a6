#!/usr/bin/env python
"""The FEM-explained share of the ambient -> hot-fire load-stiffness shift with its range over
plausible notional gimbal geometry (issues 12.8, 24.8): writes fem_data/fem_shift_range.toml,
read by taos.fem.shift.fem_shift_share (shown by `taos compare`, README, docs/theory/taos3d.md).

For each geometry of lip thickness x seat sphere radius (taos.fem.shift.swept_geometry; ranges and
why in taos.fem.shift): both gimbal halves condensed in both conditions (hanging on the lip, seat
in thrust) on one mesh level (taos.fem.build.run_level), the actuator-line compliances C_g, the
implied K_L ratio with the rest of the load path fixed by the ambient 115,000 lbf/in fit
(taos.fem.load_path.implied_load_stiffness), and share = (ratio - 1) / (1.78 - 1). A convergence
check computes the nominal geometry on coarser and finer meshes (and reads the shipped finest level
from fem_data/mesh_study.toml).

Usage: python scripts/fem_shift_sensitivity.py [--lip-mm 4,5,6] [--radius-m 0.10,0.11,0.12]
                                               [--h 0.014] [--no-convergence] [--out PATH]
"""

from __future__ import annotations

import argparse
import datetime
import subprocess
import sys
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from taos.fem.build import engine_actuator_line, run_level  # noqa: E402
from taos.fem.gimbal import GimbalGeometry, MeshSpec  # noqa: E402
from taos.fem.io import write_toml  # noqa: E402
from taos.fem.load_path import implied_load_stiffness  # noqa: E402
from taos.fem.shift import PAPER_RATIO, compute_shift_range, explained_share  # noqa: E402


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              timeout=10).stdout.strip() or "unknown"
    except OSError:
        return "unknown"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lip-mm", default="4,5,6")
    ap.add_argument("--radius-m", default="0.10,0.11,0.12")
    ap.add_argument("--h", type=float, default=0.014, help="mesh size [m] of the sweep (n_theta 12)")
    ap.add_argument("--no-convergence", action="store_true", help="skip the nominal-geometry mesh check")
    ap.add_argument("--out", type=Path, default=ROOT / "fem_data" / "fem_shift_range.toml")
    a = ap.parse_args(argv)
    lips = [float(x) / 1000 for x in a.lip_mm.split(",")]
    radii = [float(x) for x in a.radius_m.split(",")]
    spec = MeshSpec(a.h, 12)
    t0 = time.perf_counter()
    r = compute_shift_range(lips, radii, spec, log=lambda s: print(s, flush=True))
    line = engine_actuator_line()
    conv_h, conv_s = [], []
    if not a.no_convergence:
        for ms in (MeshSpec(0.020, 8), MeshSpec(0.010, 12)):
            lv = run_level(GimbalGeometry(), ms, line)
            sh = implied_load_stiffness(lv.compliance["hanging"], lv.compliance["thrust"])
            conv_h.append(ms.h)
            conv_s.append(explained_share(sh.ratio))
            print(f"nominal geometry, h = {ms.h} m: share {conv_s[-1]:.3f}", flush=True)
        conv_h.append(spec.h)
        conv_s.append(r.nominal)
    study = tomllib.loads((ROOT / "fem_data" / "mesh_study.toml").read_text())
    lp = study["load_path"]
    fine = explained_share(lp["K_L_hotfire_N_per_m"] / lp["K_L_ambient_N_per_m"])
    h_fine = max(int(k.split("_")[1]) for k in study if k.startswith("level_"))
    conv_h.append(study[f"level_{h_fine}"]["h_m"])
    conv_s.append(fine)
    order = sorted(range(len(conv_h)), key=lambda i: -conv_h[i])
    seconds = time.perf_counter() - t0
    pts = r.points
    write_toml(a.out, {
        "": {"generator": "scripts/fem_shift_sensitivity.py (taos.fem.shift.compute_shift_range)",
             "commit": _commit(), "date": datetime.date.today().isoformat(), "seconds": round(seconds, 1),
             "definition": "share = (K_L hot / K_L ambient from the gimbal FEM - 1) / (205000 / 115000 - 1); "
                           "rest of the load path fixed by the 115,000 lbf/in ambient fit",
             "ranges": "lip 4-6 mm, seat sphere radius 0.10-0.12 m (why: taos.fem.shift)"},
        "mesh": {"h_m": spec.h, "n_theta": spec.n_theta,
                 "element": "20-node serendipity hexahedron on 27-node curved geometry"},
        "share": {"nominal": r.nominal, "minimum": r.minimum, "maximum": r.maximum, "paper_ratio": PAPER_RATIO,
                  "fine_mesh_nominal": fine},
        "points": {"lip_m": [p.lip_m for p in pts], "seat_sphere_radius_m": [p.seat_sphere_radius_m for p in pts],
                   "valid": [p.share is not None for p in pts], "ratio": [p.ratio or 0.0 for p in pts],
                   "share": [p.share or 0.0 for p in pts], "lip_stress_Pa": [p.lip_stress_Pa for p in pts]},
        "convergence": {"h_m": [conv_h[i] for i in order], "nominal_share": [conv_s[i] for i in order]},
    }, header="FEM-explained share of the Green Run K_L shift over plausible gimbal geometry (generated; do not "
              "edit).\nRebuild: python scripts/fem_shift_sensitivity.py")
    print(f"\n| lip [mm] \\ seat radius [m] | " + " | ".join(f"{x:.3f}" for x in radii) + " |")
    print("|---|" + "---|" * len(radii))
    for i, t in enumerate(lips):
        row = pts[i * len(radii):(i + 1) * len(radii)]
        print(f"| {1000 * t:g} | " + " | ".join("-" if p.share is None else f"x{p.ratio:.2f} ({100 * p.share:.0f} %)"
                                                for p in row) + " |")
    print(f"\nnominal {100 * r.nominal:.0f} % (h = {spec.h} m; {100 * fine:.0f} % on the finest shipped mesh), "
          f"range {100 * r.minimum:.0f}-{100 * r.maximum:.0f} %; {seconds:.0f} s -> {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
