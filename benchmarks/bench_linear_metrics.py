"""CPU time of the linear and servo sweep figures per model variant, and their agreement.

    python benchmarks/bench_linear_metrics.py [--samples 32] [--save REF.npz | --compare REF.npz] [--profile]

The variants are those of the gallery's Sobol example (examples/plot_montecarlo_sobol.py):
Saltelli's design over the load stiffness, the piston area and the loop gain of
models/rs25_ambient.toml, N (k + 2) = 160 variants for 32 base samples. The models are built
first (not timed); then every metric of the ``linear`` and ``servo`` families
(:func:`taos.montecarlo.sweep_metrics.evaluate`) is computed for each variant, and the process
CPU time of that loop is printed per variant. ``--save`` writes the figures to an .npz file;
``--compare`` prints, per metric, the largest relative difference to such a file (written
before a change), so a speed-up can show that its figures equal the old ones to round-off.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from taos.model import load_model
from taos.montecarlo import make_design, parse_set
from taos.montecarlo.sweep_metrics import METRICS, evaluate
from taos.shipped import resolve

RANGES = ["structure.load_stiffness=100000 lbf/in:130000 lbf/in",
          "actuator.piston_area=13.5 in**2:16.5 in**2",
          "actuator.loop_gain=16 1/s:24 1/s"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--save")
    ap.add_argument("--compare")
    ap.add_argument("--profile", action="store_true", help="print a cProfile of the timed loop")
    a = ap.parse_args()
    names = tuple(k for k, m in METRICS.items() if m.family in ("linear", "servo"))
    design = make_design([parse_set(r) for r in RANGES], samples=a.samples, seed=1, sensitivity="sobol")
    path = str(resolve("rs25_ambient", "model"))
    models = [load_model(path, overrides=o) for o in design.overrides]
    evaluate(models[0], names, "pitch", None)   # one-off imports outside the timing
    if a.profile:
        import cProfile
        import pstats
        prof = cProfile.Profile()
        prof.enable()
    c0, t0 = time.process_time(), time.perf_counter()
    vals = [evaluate(m, names, "pitch", None) for m in models]
    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
    if a.profile:
        prof.disable()
        pstats.Stats(prof).sort_stats("cumulative").print_stats(30)
    print(f"{len(models)} variants, {len(names)} metrics (linear + servo): {cpu:.2f} CPU-s, {wall:.2f} s wall, "
          f"{1e3 * cpu / len(models):.1f} CPU-ms per variant")
    table = {n: np.array([v[n] for v in vals]) for n in names}
    if a.save:
        np.savez(a.save, **table)
    if a.compare:
        ref = np.load(a.compare)
        print("| metric | max relative difference | max absolute difference | max |value| |")
        print("|---|---|---|---|")
        for n in names:
            x, y = table[n], ref[n]
            same_nan = np.array_equal(np.isnan(x), np.isnan(y))
            ok = ~np.isnan(y)
            d = np.abs(x[ok] - y[ok]) / np.maximum(np.abs(y[ok]), 1e-300)
            e = np.abs(x[ok] - y[ok])
            print(f"| {n} | {d.max() if d.size else 0.0:.3g}{'' if same_nan else ' (NaN pattern differs!)'} | "
                  f"{e.max() if e.size else 0.0:.3g} | {np.abs(y[ok]).max() if ok.any() else 0.0:.4g} |")


if __name__ == "__main__":
    main()
