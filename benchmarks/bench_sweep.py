"""What running a sweep through the Monte Carlo engine costs over a plain loop.

    python benchmarks/bench_sweep.py [--points 64] [--metrics load_resonance_hz,engine_peaking_db,phase_margin_deg]

1. The peer: the same variants (models/rs25_ambient.toml, load stiffness 80,000-200,000 lbf/in)
   built with the model loader and their figures computed one after another in this process
   (:func:`taos.montecarlo.sweep_metrics.evaluate`), no engine, no store.
2. (after one 1-point sweep, whose time is printed: the engine's one-off imports)
   ``run_sweep`` in this process (``--workers 1``): the same points through the engine, stored in
   a temporary Zarr store, read back.
3. ``run_sweep`` on a LocalCluster of 2 workers (cluster start-up included).

Prints one Markdown row per case with the ratio to the peer and the machine load
(os.getloadavg) at the start and end: figures taken while other jobs share the cores are
pessimistic, compare the ratios.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from taos.model import load_model
from taos.montecarlo import SweepDefinition, make_design, parse_set, run_sweep
from taos.montecarlo.sweep_metrics import evaluate
from taos.shipped import resolve


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=64)
    ap.add_argument("--metrics", default="load_resonance_hz,engine_peaking_db,phase_margin_deg")
    a = ap.parse_args()
    metrics = tuple(a.metrics.split(","))
    model = str(resolve("rs25_ambient", "model"))
    ks = np.linspace(80_000, 200_000, a.points)
    design = make_design([parse_set("structure.load_stiffness=" + ",".join(f"{k:.1f} lbf/in" for k in ks))])
    defn = SweepDefinition(model, design, metrics)
    t0 = time.perf_counter()
    run_sweep(SweepDefinition(model, make_design([parse_set("structure.load_stiffness=1e5 lbf/in")]), metrics))
    t_import = time.perf_counter() - t0   # the engine's one-off imports (xarray, zarr, dask) and pint's cache
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    peer = [evaluate(load_model(model, overrides=o), metrics, "pitch", None) for o in design.overrides]
    t_peer = time.perf_counter() - t0
    rows = [("plain loop in this process (peer)", t_peer)]
    for label, workers in (("run_sweep, --workers 1 (in process, stored)", 1), ("run_sweep, --workers 2", 2)):
        t0 = time.perf_counter()
        res = run_sweep(defn, workers=workers)
        rows.append((label, time.perf_counter() - t0))
        for m in metrics:
            assert np.array_equal(res.values[m], np.array([p[m] for p in peer]), equal_nan=True), m
    print(f"| case | {a.points} points, {','.join(metrics)} | ratio to peer |")
    print("|---|---|---|")
    for label, t in rows:
        print(f"| {label} | {t:.2f} s | {t / t_peer:.2f} |")
    print(f"one-off: the first (1-point) sweep of the process took {t_import:.2f} s (imports); "
          f"load average {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end; "
          "the engine's figures equal the peer's bit for bit")


if __name__ == "__main__":
    main()
