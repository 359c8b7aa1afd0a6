"""Accuracy of ``simulate(integrator="exp")`` (ETDRK4, :mod:`taos.planar._exptime`) against the
fixed-step RK4 kernel at its default dt = 2e-4 s, both against RK4 at dt = 2.5e-5 s on the SAME
command (the profile sampled every 2e-4 s, linear between samples, resampled for the fine run:
so the figure is the integrators' error, not the command sampling's), per shipped model and
profile, with CPU seconds of each run (ratios only: the machine is shared).

    NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/bench_exptime_accuracy.py
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from taos.model import load_model
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import _with_spool_output, integrate_plant, kernel_args
from taos.planar import _exptime as XT
from taos.profiles import MultiRamp, Sequence, SineDwell, load_profile

DEG = math.pi / 180
DT = 2e-4
ROOT = Path(__file__).resolve().parents[1]
CASES = (("rs25_ambient", "lugre", "step_pitch"), ("rs25_ambient", "lugre", "multiramp_pitch"),
         ("rs25_ambient", "lugre", None), ("rs25_hotfire", None, "greenrun_two_axis"))


def main():
    print("| model, friction | profile (axis) | RK4 2e-4 s error [deg] | ETDRK4 error [deg] | ETDRK4 steps (set by) "
          "| CPU RK4 / ETDRK4 |")
    print("|---|---|---|---|---|---|")
    for mf, fr, pf in CASES:
        m = load_model(ROOT / "models" / f"{mf}.toml", **({"friction": fr} if fr else {}))
        prof = (load_profile(ROOT / "models" / "profiles" / f"{pf}.toml") if pf else
                Sequence((SineDwell(0.1 * DEG, 0.5, 5), MultiRamp((0.3 * DEG, -0.3 * DEG, 0.0), 0.5 * DEG, 1.0))))
        T = prof.duration_s + (1.0 if pf else 0.0)
        n = int(round(T / DT))
        cmd = np.atleast_2d(prof(np.arange(n + 1) * DT))
        for i, ax in enumerate(("pitch", "yaw")[:cmd.shape[0]]):
            plant = _with_spool_output(simplex_plant(m, ax))
            ith = plant.ss.output_index("theta_rad")
            r = np.ascontiguousarray(cmd[i])
            rf = np.interp(np.arange(8 * n + 1) * (DT / 8), np.arange(n + 1) * DT, r)
            ref = integrate_plant(plant, m, rf[:, None], DT / 8, 80)[0][:, ith]
            args = kernel_args(plant, m)
            integrate_plant(plant, m, r[:2001, None], DT, 10)      # warm both
            XT.integrate_plant_exp(plant, m, args, r[:2001], DT, 10, XT.breakpoints(prof, i), None)
            t0 = time.process_time()
            rk = integrate_plant(plant, m, r[:, None], DT, 10)[0][:, ith]
            t1 = time.process_time()
            y, _, how = XT.integrate_plant_exp(plant, m, args, r, DT, 10, XT.breakpoints(prof, i), None)
            t2 = time.process_time()
            ex = y[:, ith]
            e = lambda a: np.degrees(np.max(np.abs(a - ref)))  # noqa: E731
            print(f"| {mf}, {m.friction.name} | {pf or 'bench_simplex'} ({ax}) | {e(rk):.2e} | {e(ex):.2e} | "
                  f"{how.get('exp_steps')} ({how.get('exp_step_set_by', how.get('exp_fallback'))}) | "
                  f"{(t1 - t0) / (t2 - t1):.2f} |")


if __name__ == "__main__":
    main()
