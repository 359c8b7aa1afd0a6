"""The switching (Karnopp) Coulomb law's LCO describing-function map on the paper's soft and stiff
load paths (115,000 and 205,000 lbf/in; tests/test_lco.py's 8 amplitudes x 6 frequencies,
0.01-1 deg x 0.06-0.5 Hz, flight model), exponential dwells (the default) against the fixed-step
RK4 dwells at the default 2e-4 s (the peer), in the same run, kernels warm.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_lco_switching_map.py

Prints per structure: the largest and total ETDRK4 steps (steps a cycle x cycles) of the map's
48 dwells, the map's CPU time on each integrator, and the largest difference of the engine's
describing function between them, relative to its largest (the stuck small-amplitude dwells'
N is near zero). Until 2026-11-28 one orbit sample of
the stiff map's 0.037-deg 0.5-Hz dwell lay within a difference quotient's stencil of the stick
band's edge, where the law's torque jumps; the central quotient across the jump made that
dwell's step 3.3e-7 s (6,082,140 steps a cycle, 29.8 M steps for the map, 16.7 CPU-s) instead of
the stick band's 5.2e-4 s (taos.planar._expplan._quotients).
"""

from __future__ import annotations

import math
import time

import numpy as np

from taos.model import Structure, load_model
from taos.planar._expplan import exp_steps_per_cycle
from taos.planar.freqresp import settle_time_s, sine_dwell_points
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import DEFAULT_DT_S, kernel_args

LBF_IN = 4.4482216152605 / 0.0254
AMPS = np.logspace(np.log10(0.01), 0.0, 8) * math.pi / 180
FREQ = np.logspace(np.log10(0.06), np.log10(0.5), 6)


def main() -> None:
    A, F = (x.ravel() for x in np.meshgrid(AMPS, FREQ, indexing="ij"))
    print("| K_L [lbf/in] | ETDRK4 steps a cycle, max | ETDRK4 steps, map | exp CPU [s] | RK4 2e-4 s CPU [s] (peer) "
          "| max abs(N_exp - N_rk4) / max abs(N_rk4) |")
    print("|---|---|---|---|---|---|")
    base = load_model("models/rs25_flight.toml", friction="coulomb-switching")
    sine_dwell_points(base, A[:1], F[:1], settle_s=0.1)                       # kernels loaded
    sine_dwell_points(base, A[:1], F[:1], settle_s=0.1, integrator="rk4")
    for kl in (115000, 205000):
        m = base.replace(structure=Structure(kl * LBF_IN))
        plant = simplex_plant(m)
        npc = exp_steps_per_cycle(kernel_args(plant, m), m, plant.inertia_kgm2, A, F, DEFAULT_DT_S, 64)
        cycles = np.maximum(2, np.ceil(settle_time_s(m, "pitch") * F)) + 2
        t = time.process_time()
        e = sine_dwell_points(m, A, F)
        te = time.process_time() - t
        t = time.process_time()
        r = sine_dwell_points(m, A, F, integrator="rk4")
        tr = time.process_time() - t
        d = np.max(np.abs(e.engine - r.engine)) / np.max(np.abs(r.engine))
        print(f"| {kl:,} | {npc.max():,} | {int((npc * cycles).sum()):,} | {te:.2f} | {tr:.2f} | {d:.2e} |")


if __name__ == "__main__":
    main()
