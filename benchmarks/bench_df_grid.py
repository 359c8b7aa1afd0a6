"""Benchmark: the full TVC describing-function grid N(A, w) (8 amplitudes 0.02..1 deg x 30
frequencies 0.05..15 Hz, Dahl friction, flight model) with the compiled parallel sine dwell,
beside a plain scipy.integrate.solve_ivp baseline run on a fair subset and scaled by simulated
time. Also checks the shortened settling (one settling + one measured cycle, 3 s settling
time instead of four decades of the slowest linear mode) against two + two cycles.

Run:  .venv/bin/python benchmarks/bench_df_grid.py
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.integrate

from taos.flight.describing import describing_function_map
from taos.planar.freqresp import settle_time_s
from taos.model import load_model
from taos.planar.simplex import simplex_plant

DEG = math.pi / 180
AMPS = np.logspace(np.log10(0.02), 0, 8) * DEG
FREQ = np.logspace(np.log10(0.05), np.log10(15), 30)


def simulated_seconds(model, settle_cycles, measure_cycles, settle_s=None):
    ts = settle_time_s(model) if settle_s is None else settle_s
    per = sum((max(settle_cycles, math.ceil(ts * f)) + measure_cycles) / f for f in FREQ)
    return per * AMPS.size


def scipy_dwell(model, amp, f, t_end):
    """Same plant, friction law and avionics, integrated by solve_ivp (RK45, rtol 1e-6)."""
    p = simplex_plant(model)
    A, B = p.ss.A, p.ss.B
    bc = B[:, p.ss.input_index("command_rad")]
    bf = B[:, p.ss.input_index("friction_torque_Nm")]
    law, av = model.friction, model.avionics
    w = 2 * math.pi * f

    def rhs(t, y):
        x, z = y[:-1], y[-1]
        u = av(amp * math.sin(w * t))
        v = p.rate_c @ x
        tf = law(v, z, p.applied_c @ x)
        return np.append(A @ x + bc * u + bf * tf, law.derivative(v, z))

    y0 = np.zeros(A.shape[0] + 1)
    t0 = time.perf_counter()
    sol = scipy.integrate.solve_ivp(rhs, (0, t_end), y0, method="RK45", rtol=1e-6, atol=1e-12, max_step=0.01)
    return time.perf_counter() - t0, sol.success


def main():
    m = load_model("models/rs25_flight.toml", friction="dahl")
    describing_function_map(m, AMPS[:1], FREQ[-2:], settle_cycles=1, measure_cycles=1)  # compile / cache load
    rows = []
    maps = {}
    for sc, mc, ss in ((1, 1, 3.0), (2, 2, None)):
        t0 = time.perf_counter()
        maps[sc] = describing_function_map(m, AMPS, FREQ, settle_cycles=sc, measure_cycles=mc, settle_s=ss)
        wall = time.perf_counter() - t0
        rows.append((sc, mc, ss, wall, simulated_seconds(m, sc, mc, ss)))
    # baseline: solve_ivp on a subset (2 dwells, 10 s each), scaled per simulated second
    tb = 0.0
    sim_b = 0.0
    for amp, f in ((0.1 * DEG, 0.5), (0.4 * DEG, 2.0)):
        dt, ok = scipy_dwell(m, amp, f, 4.0)
        assert ok
        tb += dt
        sim_b += 4.0
    per_s = tb / sim_b
    g1, g2 = maps[1].gain_db(), maps[2].gain_db()
    p1, p2 = maps[1].phase_deg(), maps[2].phase_deg()
    import os
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores\n")
    print("| settle + measure cycles, settle time | grid | simulated time [s] | wall [s] | scipy solve_ivp (scaled) [s] | speed-up |")
    print("|---|---|---|---|---|---|")
    for sc, mc, ss, wall, sim in rows:
        print(f"| {sc} + {mc}, {'%.1f s' % ss if ss else 'default %.1f s' % settle_time_s(m)} | {AMPS.size} x {FREQ.size} | {sim:.0f} | {wall:.2f} | {per_s * sim:.0f} | "
              f"{per_s * sim / wall:.0f}x |")
    print(f"\nscipy baseline: {tb:.2f} s wall for {sim_b:.0f} s simulated ({per_s:.3f} s per simulated s)")
    print(f"1+1 vs 2+2 cycles: max |gain difference| {np.max(np.abs(g1 - g2)):.3f} dB, "
          f"max |phase difference| {np.max(np.abs(p1 - p2)):.2f} deg")
    lo = FREQ <= 1.0
    print(f"   below 1 Hz: {np.max(np.abs(g1 - g2)[:, lo]):.3f} dB, {np.max(np.abs(p1 - p2)[:, lo]):.2f} deg")


if __name__ == "__main__":
    main()
