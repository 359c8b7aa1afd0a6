"""MASV nonlinear time domain speed: four engines (eight actuators, the FEM's modes) over the
Green Run two-axis profile on one core, beside the single-engine planar kernel on the same
profile in the same run.

    PYTHONPATH=. NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/bench_masv_simulate.py [--dt 2e-4] [--repeat 3]

Peers, same machine, same run, best of ``--repeat`` (compiled kernels warmed first):
  * masv.simulate (masv.timedomain) on models/masv/core_stage.toml (8 engine-axis blocks with friction, limits
    and avionics, 5 modes to 200 Hz; compiled RK4 kernel masv._kernel.integrate): kernel time and
    the whole call;
  * taos.planar.simulate on models/rs25_hotfire.toml, two axes one after the other (threads=1):
    the single-engine kernel taos.planar.dynamics.integrate_samples, whole call.
Real-time factor = simulated seconds / wall seconds.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from masv.config import load_config
from masv.timedomain import simulate
from taos.model import load_model
from taos.planar.simulate import simulate as taos_simulate
from taos.profiles import load_profile

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dt", type=float, default=2e-4)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    prof = load_profile(ROOT / "models" / "profiles" / "greenrun_two_axis.toml")
    cfg = load_config(ROOT / "models" / "masv" / "core_stage.toml")
    model = load_model(ROOT / "models" / "rs25_hotfire.toml")
    T = prof.duration_s + 1.0
    simulate(cfg, prof, dt_s=a.dt, duration_s=0.2)
    taos_simulate(model, prof, dt_s=a.dt, duration_s=0.2, threads=1)
    best_k = best_m = best_t = float("inf")
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        h = simulate(cfg, prof, dt_s=a.dt)
        best_m = min(best_m, time.perf_counter() - t0)
        best_k = min(best_k, h.provenance["solver"]["kernel_wall_s"])
        t0 = time.perf_counter()
        taos_simulate(model, prof, dt_s=a.dt, threads=1)
        best_t = min(best_t, time.perf_counter() - t0)
    c = h.provenance["coupling"]
    print(f"Green Run two-axis, {T:.1f} s simulated, dt = {a.dt} s, one core, best of {a.repeat}")
    print(f"  masv simulate, 4 engines / {len(h.actuators)} actuators, {h.modal_q.shape[0]} modes, "
          f"{c['n_states']} states, nnz {c['nnz']}: kernel {best_k:.3f} s ({T / best_k:.1f}x real time), "
          f"whole call {best_m:.3f} s ({T / best_m:.1f}x)")
    print(f"  taos simulate, one engine, 2 axes:   whole call {best_t:.3f} s ({T / best_t:.1f}x real time); "
          f"per axis {best_t / 2:.3f} s")
    print(f"  masv kernel per actuator / taos per axis: {best_k / len(h.actuators) / (best_t / 2):.2f}")


if __name__ == "__main__":
    main()
