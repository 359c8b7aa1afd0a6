"""MASV nonlinear time domain speed: four engines (eight actuators, the FEM's modes) over the
Green Run two-axis profile on one core, beside the single-engine planar kernel on the same
profile in the same run.

    PYTHONPATH=. NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/bench_masv_simulate.py [--dt 4e-4] [--repeat 3]

Peers, same machine, same run, best of ``--repeat`` (compiled kernels warmed first):
  * masv.simulate (masv.timedomain) on models/masv/core_stage.toml (8 engine-axis blocks with friction, limits
    and avionics, 5 modes to 200 Hz; compiled RK4 lane kernel masv._kernel.integrate; "nnz" the
    non-zeros of its factored linear part): kernel time and the whole call;
  * taos.planar.simulate on models/rs25_hotfire.toml, two axes one after the other (threads=1):
    the single-engine kernel taos.planar.dynamics.integrate_samples, whole call.
Real-time factor = simulated seconds / seconds, both by the wall clock and by this process's CPU
time (time.process_time: what one core delivers to this run when other sessions share the
machine); the load average is printed beside them. taos simulate runs at its own default step
(2e-4 s); masv simulate at ``--dt`` (default its DEFAULT_DT_S, 4e-4 s).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from masv.config import load_config
from masv.timedomain import DEFAULT_DT_S, simulate
from taos.model import load_model
from taos.planar.simulate import simulate as taos_simulate
from taos.profiles import load_profile

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dt", type=float, default=DEFAULT_DT_S)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    prof = load_profile(ROOT / "models" / "profiles" / "greenrun_two_axis.toml")
    cfg = load_config(ROOT / "models" / "masv" / "core_stage.toml")
    model = load_model(ROOT / "models" / "rs25_hotfire.toml")
    T = prof.duration_s + 1.0
    simulate(cfg, prof, dt_s=a.dt, duration_s=0.2)
    taos_simulate(model, prof, duration_s=0.2, threads=1)
    best_k = best_m = best_t = best_mc = best_tc = float("inf")
    load0 = os.getloadavg()[0]
    for _ in range(a.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        h = simulate(cfg, prof, dt_s=a.dt)
        best_m = min(best_m, time.perf_counter() - t0)
        best_mc = min(best_mc, time.process_time() - c0)
        best_k = min(best_k, h.provenance["solver"]["kernel_wall_s"])
        t0, c0 = time.perf_counter(), time.process_time()
        taos_simulate(model, prof, threads=1)
        best_t = min(best_t, time.perf_counter() - t0)
        best_tc = min(best_tc, time.process_time() - c0)
    c = h.provenance["coupling"]
    print(f"Green Run two-axis, {T:.1f} s simulated, dt = {a.dt} s, one core, best of {a.repeat}")
    print(f"  masv simulate, 4 engines / {len(h.actuators)} actuators, {h.modal_q.shape[0]} modes, "
          f"{c['n_states']} states, nnz {c['nnz']}: kernel {best_k:.3f} s ({T / best_k:.1f}x real time), "
          f"whole call {best_m:.3f} s ({T / best_m:.1f}x)")
    print(f"  taos simulate, one engine, 2 axes:   whole call {best_t:.3f} s ({T / best_t:.1f}x real time); "
          f"per axis {best_t / 2:.3f} s")
    print(f"  CPU time (one core's share): masv whole call {best_mc:.3f} s ({T / best_mc:.1f}x real time); "
          f"taos whole call {best_tc:.3f} s ({T / best_tc:.1f}x)")
    print(f"  masv kernel per actuator / taos per axis: {best_k / len(h.actuators) / (best_t / 2):.2f}")
    print(f"  load average {load0:.2f} at the start, {os.getloadavg()[0]:.2f} at the end ({os.cpu_count()} cores)")


if __name__ == "__main__":
    main()
