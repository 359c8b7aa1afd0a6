"""Monte Carlo campaign throughput on Dask, and the LCO fraction for soft and stiff structure.

    python benchmarks/bench_montecarlo.py [--runs 2000] [--speedup-runs 100] [--out DIR]

1. The peer: the same runs one after another in this process (no Dask), on ``--speedup-runs``
   runs: the per-run cost without any executor.
2. ``--speedup-runs`` runs on a LocalCluster of 1 and of 2 workers: the speed-up from 1 to 2.
3. The whole campaign (models/montecarlo/post_separation.toml, 200 s after separation) with
   ``--runs`` runs, soft structure (2 workers, timed end to end, start-up included), then stiff.
Prints a Markdown table for benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

from taos.montecarlo import load_campaign, run_campaign, run_one
from taos.montecarlo.campaign import base_models


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--speedup-runs", type=int, default=100)
    ap.add_argument("--out", default=None, help="keep the campaigns here (default: a temporary folder)")
    a = ap.parse_args()
    c = load_campaign("post_separation")
    root = Path(a.out) if a.out else Path(tempfile.mkdtemp(prefix="bench_mc_"))
    root.mkdir(parents=True, exist_ok=True)
    rows = []

    base = base_models(c)
    run_one(c, "soft", 0, base=base)  # load the compiled kernels
    t0 = time.perf_counter()
    for i in range(a.speedup_runs):
        run_one(c, "soft", i, base=base)
    serial = time.perf_counter() - t0
    rows.append(("in-process loop, no Dask (peer)", a.speedup_runs, 1, serial, a.speedup_runs / serial))

    for w in (1, 2):
        out = root / f"speedup_w{w}"
        shutil.rmtree(out, ignore_errors=True)
        t0 = time.perf_counter()
        run_campaign(c, out, runs=a.speedup_runs, case="soft", workers=w)
        el = time.perf_counter() - t0
        rows.append((f"LocalCluster, {w} worker(s), start-up included", a.speedup_runs, w, el, a.speedup_runs / el / w))

    fractions = {}
    for case in ("soft", "stiff"):
        out = root / f"campaign_{case}"
        shutil.rmtree(out, ignore_errors=True)
        t0 = time.perf_counter()
        res = run_campaign(c, out, runs=a.runs, case=case, workers=2, progress=True)
        el = time.perf_counter() - t0
        rows.append((f"campaign '{case}', 2 workers, end to end", a.runs, 2, el, a.runs / el / 2))
        fractions[case] = res.summary

    print(f"\nmachine: {os.cpu_count()} cores; campaign {c.source}")
    print("| what | runs | workers | wall [s] | runs/s per worker |")
    print("|---|---|---|---|---|")
    for name, n, w, el, rate in rows:
        print(f"| {name} | {n} | {w} | {el:.1f} | {rate:.2f} |")
    w1 = rows[1][3]
    w2 = rows[2][3]
    print(f"\nspeed-up 1 -> 2 workers: {w1 / w2:.2f}x")
    print("\n| case | runs | LCO runs | LCO fraction | 95 % CI (Wilson) | amplitude p50 [deg] | p5-p95 | strongest driver |")
    print("|---|---|---|---|---|---|---|---|")
    for case, s in fractions.items():
        f = s["lco_fraction"]
        amp = s["amplitude_deg_lco_runs"] or {}
        top = s["sensitivity_of_amplitude"][0] if s["sensitivity_of_amplitude"] else {"parameter": "-", "spearman_rho": 0}
        print(f"| {case} | {s['runs_ok']} | {f['lco_runs']} | {f['value']:.3f} | {f['ci_low']:.3f}-{f['ci_high']:.3f} | "
              f"{amp.get('p50', float('nan')):.3f} | {amp.get('p5', float('nan')):.3f}-{amp.get('p95', float('nan')):.3f} | "
              f"{top['parameter']} ({top['spearman_rho']:+.2f}) |")
    (root / "bench.json").write_text(json.dumps({"rows": rows, "fractions": {k: v["lco_fraction"] for k, v in fractions.items()}},
                                                indent=1))


if __name__ == "__main__":
    main()
