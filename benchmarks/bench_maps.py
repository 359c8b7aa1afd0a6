"""Benchmark (issue 15): what a user waits for, end to end, beside the plain scipy script.

1. Start-up: ``taos --help`` and ``taos info MODEL`` (warm install, kernels cached), beside a
   bare interpreter and ``import numpy, scipy.integrate`` (what the plain script pays).
2. The user job of 3 amplitudes x 10 frequencies: three ``taos freqresp`` calls (one
   amplitude each) and one call with the amplitude list; and the 8 x 30 N(A, w) map in one
   call, settled and by shooting (``--steady shoot``). Every figure includes start-up.
3. Peer: a plain scipy script (``solve_ivp`` RK45, rtol 1e-6, the same plant, friction and
   avionics; ``bench_df_grid.scipy_dwell``), its cost per simulated second measured on two
   dwells here and scaled to the job's simulated time (the same settling and measurement),
   plus its own start-up.
4. Shooting against full settling on the 8 x 30 map: time, and the largest gain/phase
   difference to full settling and to a long (60 s) settling reference.

Run:  .venv/bin/python benchmarks/bench_maps.py [--quick]
      (TAOS_BEFORE=/path/to/previous/checkout adds the previous version's start-up, run from
      that source tree on this venv)
"""

from __future__ import annotations

import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

DEG = math.pi / 180
MODEL = "rs25_flight"
LAW = "dahl"
JOB_AMPS = [0.05, 0.2, 0.8]
JOB_FREQ = list(np.round(np.logspace(np.log10(0.2), np.log10(10), 10), 4))
MAP_AMPS = list(np.round(np.logspace(np.log10(0.02), 0, 8), 5))
MAP_FREQ = list(np.round(np.logspace(np.log10(0.05), np.log10(15), 30), 5))
TAOS = [str(Path(sys.executable).parent / "taos")]  # the console script, as a user runs it


def wall(cmd, repeat=1, env=None, cwd=None, warm=False):
    """Median wall time [s] of a subprocess (output discarded; a failure stops the run), in
    ``cwd`` with ``env`` (``python -m`` puts the working folder first on the path); ``warm``:
    one untimed run first (another checkout compiles its kernels)."""
    if warm:
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env, cwd=cwd)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env, cwd=cwd)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def speedup_table(title, runs, peer_s):
    """A markdown table of ``runs`` (name -> wall [s]) beside the peer's time [s]."""
    print(f"{title}\n\n| run | wall [s] | plain scipy script [s] | speed-up |\n|---|---|---|---|")
    for k, v in runs.items():
        print(f"| {k} | {v:.2f} | {peer_s:.0f} | {peer_s / v:.0f}x |")


def csv(v):
    return ",".join(f"{x:g}" for x in v)


def simulated_s(settle_s, amps, freqs, settle_cycles=2, measure_cycles=2):
    return len(amps) * sum((max(settle_cycles, math.ceil(settle_s * f)) + measure_cycles) / f for f in freqs)


def main(quick=False):
    from bench_df_grid import scipy_dwell

    from taos.planar.freqresp import settle_time_s, sine_dwell_grid, sine_dwell_points
    from taos.linear import gain_db
    from taos.model import load_model

    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores\n")
    n = 3 if quick else 7
    t_bare = wall([sys.executable, "-c", "pass"], n)
    t_np = wall([sys.executable, "-c", "import numpy, scipy.integrate"], n)
    t_help = wall(TAOS + ["--help"], n)
    t_info = wall(TAOS + ["info", MODEL], n)
    before = os.environ.get("TAOS_BEFORE")   # a checkout of the previous version, run on this venv
    if before:
        env = dict(os.environ, PYTHONPATH=before)
        old = [sys.executable, "-m", "taos"]
        tb_help = wall(old + ["--help"], n, env, before, warm=True)
        tb_info = wall(old + ["info", MODEL], n, env, before, warm=True)
    print("### Start-up (median of %d, warm)\n" % n)
    print("| command | wall [s] |\n|---|---|")
    print(f"| python -c pass | {t_bare:.3f} |\n| python -c 'import numpy, scipy.integrate' (plain script) | {t_np:.3f} |")
    print(f"| taos --help | {t_help:.3f} |\n| taos info {MODEL} | {t_info:.3f} |")
    if before:
        print(f"| previous version ({before}): taos --help | {tb_help:.3f} |\n"
              f"| previous version: taos info {MODEL} (with its simulated step figures) | {tb_info:.3f} |")
        t_steps = wall(TAOS + ["info", MODEL, "--steps"], n)
        print(f"| taos info {MODEL} --steps (the same figures as the previous version) | {t_steps:.3f} |")
    print()

    m = load_model(MODEL, friction=LAW)
    ts = settle_time_s(m)
    # scipy peer: cost per simulated second on two dwells
    tb = 0.0
    for amp, f in ((0.1 * DEG, 0.5), (0.4 * DEG, 2.0)):
        dt, ok = scipy_dwell(m, amp, f, 2.0 if quick else 4.0)
        assert ok
        tb += dt
    per_s = tb / (4.0 if quick else 8.0)

    base = TAOS + ["freqresp", MODEL, "--friction", LAW, "--json", os.devnull]
    job = {}
    job["3 calls (one amplitude each), settled"] = sum(
        wall(base + ["--freq-hz", csv(JOB_FREQ), "--amplitude-deg", f"{a:g}"]) for a in JOB_AMPS)
    job["1 call (amplitude list), settled"] = wall(base + ["--freq-hz", csv(JOB_FREQ), "--amplitude-deg", csv(JOB_AMPS)])
    job["1 call (amplitude list), shooting"] = wall(base + ["--freq-hz", csv(JOB_FREQ), "--amplitude-deg", csv(JOB_AMPS),
                                                           "--steady", "shoot"])
    peer_job = per_s * simulated_s(ts, JOB_AMPS, JOB_FREQ) + t_np
    speedup_table(f"### User job: {len(JOB_AMPS)} amplitudes x {len(JOB_FREQ)} frequencies, {MODEL}, {LAW} "
                  "(start-up included)", job, peer_job)
    if not quick:
        mp = {}
        mp["1 call, settled"] = wall(base + ["--freq-hz", csv(MAP_FREQ), "--amplitude-deg", csv(MAP_AMPS)])
        mp["1 call, shooting"] = wall(base + ["--freq-hz", csv(MAP_FREQ), "--amplitude-deg", csv(MAP_AMPS),
                                              "--steady", "shoot"])
        peer_map = per_s * simulated_s(ts, MAP_AMPS, MAP_FREQ) + t_np
        speedup_table(f"\n### Map: {len(MAP_AMPS)} x {len(MAP_FREQ)} in one call (start-up included)", mp, peer_map)
    print(f"\nscipy peer: {tb:.2f} s for {4.0 if quick else 8.0:.0f} s simulated ({per_s:.3f} s per simulated s); "
          f"settling time {ts:.2f} s + 2 settling and 2 measured cycles per dwell")

    # shooting vs full settling, in-process (kernels warm)
    amps = np.array(MAP_AMPS[::2] if quick else MAP_AMPS) * DEG
    freqs = np.array(MAP_FREQ[::3] if quick else MAP_FREQ)
    A, F = (g.ravel() for g in np.meshgrid(amps, freqs, indexing="ij"))
    shape = (amps.size, freqs.size)
    sine_dwell_points(m, A[:1], F[-1:], method="shoot")
    sine_dwell_grid(m, amps[:1], freqs[-1:], settle_s=0.0)
    t0 = time.perf_counter()
    st = sine_dwell_points(m, A, F, method="shoot")
    t_shoot = time.perf_counter() - t0
    st_piston, st_engine = st.piston.reshape(shape), st.engine.reshape(shape)
    t0 = time.perf_counter()
    p_full, e_full = sine_dwell_grid(m, amps, freqs)
    t_full = time.perf_counter() - t0
    t0 = time.perf_counter()
    p_long, e_long = sine_dwell_grid(m, amps, freqs, settle_s=60.0, measure_cycles=1)
    t_long = time.perf_counter() - t0

    def diff(a, b):
        return (float(np.max(np.abs(gain_db(a) - gain_db(b)))), float(np.max(np.abs(np.degrees(np.angle(a / b))))))

    print(f"\n### Periodic steady state: shooting vs settling, {amps.size} x {freqs.size} dwells, {MODEL}, {LAW}\n")
    print("| method | wall [s] | engine vs 60 s reference [dB / deg] | piston vs 60 s reference [dB / deg] |")
    print("|---|---|---|---|")
    for name, t, p, e in (("shooting (linear start + RRE)", t_shoot, st_piston, st_engine),
                          (f"full settling ({ts:.1f} s + 2 cycles)", t_full, p_full, e_full),
                          ("long settling (60 s), the reference", t_long, p_long, e_long)):
        de, dp = diff(e, e_long), diff(p, p_long)
        print(f"| {name} | {t:.2f} | {de[0]:.4f} / {de[1]:.3f} | {dp[0]:.4f} / {dp[1]:.3f} |")
    de, dp = diff(st_engine, e_full), diff(st_piston, p_full)
    print(f"\nshooting vs full settling: engine {de[0]:.4f} dB / {de[1]:.3f} deg, piston {dp[0]:.4f} dB / {dp[1]:.3f} deg")
    print(f"shooting: {int(st.converged.sum())}/{st.converged.size} converged to the default tolerance 1e-4, max residual "
          f"{st.residual.max():.1e}, periods per dwell median {int(np.median(st.periods))} max {st.periods.max()}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
