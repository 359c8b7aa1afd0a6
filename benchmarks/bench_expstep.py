"""Benchmark (issue 28, points 1-2): sine dwells with the exponential integrator (ETDRK4, the
linear block and the quantised command exact, the step from the friction loop) against the
scipy LSODA peer, in the same run.

1. Peers: a plain scipy script, ``solve_ivp(method="LSODA", rtol=1e-6, atol=1e-12)`` on the same
   plant (its A, b_c, b_f), the friction law's registry kernel, the avionics' pure-Python
   original and the limit corrections (``saturation.apply``), max step 1/64 of a period, and the
   same with the right-hand side compiled by numba as one function (a stronger peer); each one's cost
   per simulated second measured on two dwells here and scaled to the job's simulated time (the
   same settling and measured cycles), plus its own start-up (``import numpy, scipy.integrate``).
2. Ours, whole processes through the console script, start-up included: the 8 x 30 N(A, w) map
   (0.02-1 deg x 0.05-15 Hz, LuGre, ``rs25_flight``) in one call, and 3 calls of 10 dwells
   (one amplitude of 0.05, 0.2, 0.8 deg each, 0.2-10 Hz).
3. In-process, kernels warm: the same map with the exponential and with the RK4 kernel
   (``integrator="rk4"``, dt 2e-4 s), and both against a long-settled fine reference (60 s of
   settling, RK4 at 5e-5 s; RK4 at 2e-4 s samples the 12-bit command's steps at its stage
   times, 0.01 dB at 0.02 deg and 10 Hz): the largest gain and phase difference.
4. Time-domain accuracy of single dwells (2 cycles from rest, a quarter-cycle record): max
   engine error against RK4 at dt = 2.5e-5 s, of ETDRK4 at its chosen step and of RK4 at 2e-4 s.

5. ``--before-after`` (alone): the 3-call job and the map as whole processes with the RK4 kernel
   and with the exponential integrator, in the same run.
6. ``--startup`` (alone): the per-process start-up. The 3-call job and the map as whole
   processes (console script), median of 3 interleaved repeats, in four set-ups: every built-in
   friction law's kernels loaded at start (as before the per-law split: ``load_all()`` then the
   command) or only the law the command runs; and Python bytecode (.pyc) read, or every module
   compiled from source (``PYTHONDONTWRITEBYTECODE=1`` with an empty ``PYTHONPYCACHEPREFIX``:
   what a venv installed by uv without ``--compile-bytecode`` gives on a machine that sets
   ``PYTHONDONTWRITEBYTECODE``); an empty ``python -c pass`` and ``import numba`` as floors; and the
   LSODA peer (Python right-hand side, measured on two 2 s dwells and scaled, plus its start-up).

7. ``--first-kernel`` (alone; issue 44 point 3): the C dwell kernels (``TAOS_KERNELS=c``,
   :mod:`taos.planar._cdwell`, the law's library in the cache) against numba's
   (``TAOS_KERNELS=numba``, numba's cache warm), whole processes through the console script,
   interleaved: the time from launching the process to its first kernel call and to that
   call's return (the command prints ``time.time()`` there, ``TAOS_STARTUP_STAMP=1``; the
   parent subtracts its own ``time.time()`` just before starting the process), median and
   minimum of ``--repeat`` (default 7) one-dwell calls; then the 3-call job (wall and CPU,
   median of 3) on each path and the LSODA peer of item 6, in the same run, with ``uptime``.

Run:  .venv/bin/python benchmarks/bench_expstep.py [--quick] [--before-after | --startup | --first-kernel]
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

DEG = math.pi / 180
MODEL = "rs25_flight"
LAW = "lugre"
JOB_AMPS = [0.05, 0.2, 0.8]
JOB_FREQ = list(np.round(np.logspace(np.log10(0.2), np.log10(10), 10), 4))
MAP_AMPS = list(np.round(np.logspace(np.log10(0.02), 0, 8), 5))
MAP_FREQ = list(np.round(np.logspace(np.log10(0.05), np.log10(15), 30), 5))
TAOS = [str(Path(sys.executable).parent / "taos")]


def wall(cmd, env=None):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env)
    return time.perf_counter() - t0


def csv(v):
    return ",".join(f"{x:g}" for x in v)


def _compiled_rhs():
    """The peer's right-hand side compiled by numba (the same kernels), for the second peer."""
    from numba import njit

    from taos.planar import _avionics_kernels as av
    from taos.planar import saturation as lim_mod

    @njit(cache=False)
    def rhs(t, s, A, bc, bf, cw, ca, lim, fid, fp, avp, c_amp, w):
        n = A.shape[0]
        x = s[:n]
        u = av.apply(c_amp * np.sin(w * t), avp)
        dz, tf = fid(cw @ x, s[n], ca @ x, fp)
        out = np.empty(n + 1)
        dx = A @ x + bc * u + bf * tf
        lim_mod.apply(lim, x, u, dx)
        out[:n] = dx
        out[n] = dz
        return out
    return rhs


def lsoda_dwell(model, amp, f, t_end, compiled=False):
    """The peer: one dwell from rest by scipy LSODA (module docstring); returns wall [s]. With
    ``compiled`` the right-hand side is one numba-compiled function (a stronger peer)."""
    from scipy.integrate import solve_ivp

    from taos.planar import avionics as av
    from taos.planar import saturation as lim_mod
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import kernel_args

    A, Br, bc, bf, cc, dc, cw, ca, lim = kernel_args(simplex_plant(model), model)
    fp, avp = model.friction.pack(), model.avionics.pack()
    rates, apply = model.friction.entry.rates, av.apply.py_func
    w = 2 * math.pi * f

    def rhs(t, s):
        x, z = s[:-1], s[-1]
        u = apply(dc.sum() * amp * math.sin(w * t), avp)
        dz, tf = rates(cw @ x, z, ca @ x, fp)
        dx = A @ x + bc * u + bf * tf
        lim_mod.apply(lim, x, u, dx)
        return np.append(dx, dz)

    if compiled:
        crhs = _compiled_rhs()
        args = (A, bc, bf, cw, ca, lim, rates, fp, avp, dc.sum() * amp, w)
        crhs(0.0, np.zeros(A.shape[0] + 1), *args)   # compile outside the timing

        def rhs(t, s):   # noqa: F811
            return crhs(t, s, *args)

    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0, t_end), np.zeros(A.shape[0] + 1), method="LSODA", rtol=1e-6, atol=1e-12,
                    max_step=1.0 / (64 * f))
    assert sol.success
    return time.perf_counter() - t0


def simulated_s(settle_s, amps, freqs, settle_cycles=2, measure_cycles=2):
    return len(amps) * sum((max(settle_cycles, math.ceil(settle_s * f)) + measure_cycles) / f for f in freqs)


def time_domain(m, amp, f):
    """Max engine error [deg] of one dwell of ``amp`` [rad] at ``f`` [Hz] against RK4 at 2.5e-5 s
    (module docstring, item 4)."""
    from taos.planar import _expplan as P
    from taos.planar import _expstep as X
    from taos.planar import dynamics as ig
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import kernel_args

    p = simplex_plant(m)
    o = p.ss.output_index
    Cy = np.ascontiguousarray(p.ss.C[[o("x_p_m"), o("theta_rad")]])
    args = kernel_args(p, m)
    kern = (m.friction.entry.rates, m.friction.pack(), m.avionics.pack())
    ncyc = 2

    def rk4(npc, every):
        k = np.arange(ncyc * npc + 1)
        r = np.ascontiguousarray((amp * np.sin(2 * math.pi * k / npc))[:, None])
        y = np.empty((ncyc * npc // every + 1, 2))
        aux = np.empty((y.shape[0], ig.N_AUX))
        assert ig.integrate_samples(*args, Cy, *kern, np.zeros(8), 0.0, r, 1 / (f * npc), every, y, aux) < 0
        return y[:, 1]

    h, why = P.dwell_step_s(args, m, amp, f, 2e-4)
    npc = P.steps_per_cycle(h, f, 64)
    dt = 1 / (f * npc)
    co = X.etd_coefficients(args[0], dt)
    G, D = X.command_table(args[0], args[2], dt / 2, X.table_nodes(args[0], dt / 2))
    x = np.zeros(8)
    z = 0.0
    th = [0.0]
    out = np.zeros((2, 3))
    for k in range(0, ncyc * npc, npc // 4):
        z, st, _ = X.sine_steps_exp(*args, Cy, *kern, *co, G, D, 0, amp, npc, dt, x, z, k, npc // 4, False, out)
        th.append(Cy[1] @ x)
    ref = rk4(int(round(40000 / f)), int(round(10000 / f)))
    r4 = rk4(int(round(5000 / f)), int(round(1250 / f)))
    return (math.degrees(np.max(np.abs(np.array(th) - ref))), math.degrees(np.max(np.abs(r4 - ref))), dt, why)


def before_after(quick=False):
    """The same jobs as whole processes (``python -c``, start-up included) with the RK4 kernel
    (before) and the exponential integrator (after), in the same run."""
    code = ("import sys; from taos.model import load_model; from taos.planar.freqresp import sine_dwell_family; "
            f"m = load_model({MODEL!r}, friction={LAW!r}); "
            "sine_dwell_family(m, [float(x) for x in sys.argv[1].split(',')], "
            "[float(x) * 3.141592653589793 / 180 for x in sys.argv[2].split(',')], integrator=sys.argv[3])")
    run = lambda f, a, i: wall([sys.executable, "-c", code, csv(f), csv(a), i])  # noqa: E731
    run([1.0], [0.1], "exp")
    run([1.0], [0.1], "rk4")
    print("### Whole processes (python -c, start-up included), before and after\n")
    print("| job | RK4 kernel (before) [s] | ETDRK4 (after) [s] | ratio |\n|---|---|---|---|")
    jobs = [("3 calls of 10 dwells", [(JOB_FREQ, [a]) for a in JOB_AMPS])]
    if not quick:
        jobs.append(("8 x 30 map, one call", [(MAP_FREQ, MAP_AMPS)]))
    for name, calls in jobs:
        tb = sum(run(f, a, "rk4") for f, a in calls)
        ta = sum(run(f, a, "exp") for f, a in calls)
        print(f"| {name} | {tb:.2f} | {ta:.2f} | {tb / ta:.1f}x |")
    print()


#: the command line with every built-in law's kernels loaded first (the registry before the
#: per-law split loaded all eighteen C callbacks on the first lookup of any law)
_ALL_LAWS = ("import sys; from taos.friction.registry import load_all; from taos.cli import main; "
             "load_all(); sys.exit(main(sys.argv[1:]))")


def _cpu_wall(cmd, env):
    """(wall, user + system CPU) [s] of one process: the CPU time is the steadier figure on a
    loaded machine."""
    import resource

    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = wall(cmd, env)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return t, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def startup(quick=False):
    """Item 6 of the module docstring: whole processes in four set-ups, against the LSODA peer."""
    import statistics
    import tempfile

    from taos.model import load_model
    from taos.planar.freqresp import settle_time_s

    m = load_model(MODEL, friction=LAW)
    ts = settle_time_s(m)
    per_s = sum(lsoda_dwell(m, a * DEG, f, 2.0) for a, f in ((0.1, 0.5), (0.4, 2.0))) / 4.0
    t_np = wall([sys.executable, "-c", "import numpy, scipy.integrate"])
    empty = tempfile.mkdtemp(prefix="taos-nopyc-")
    env_pyc = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPYCACHEPREFIX")}
    env_src = dict(env_pyc, PYTHONDONTWRITEBYTECODE="1", PYTHONPYCACHEPREFIX=empty)
    setups = {"one law, bytecode (now, after `make .venv/.warm`)": (TAOS, env_pyc),
              "all laws, bytecode": ([sys.executable, "-c", _ALL_LAWS], env_pyc),
              "one law, from source": (TAOS, env_src),
              "all laws, from source (before)": ([sys.executable, "-c", _ALL_LAWS], env_src)}
    args = ["freqresp", MODEL, "--friction", LAW, "--json", os.devnull]
    jobs = {"3 calls of 10 dwells": [["--freq-hz", csv(JOB_FREQ), "--amplitude-deg", f"{a:g}"] for a in JOB_AMPS]}
    if not quick:
        jobs["8 x 30 map, one call"] = [["--freq-hz", csv(MAP_FREQ), "--amplitude-deg", csv(MAP_AMPS)]]
    peers = {"3 calls of 10 dwells": per_s * simulated_s(ts, JOB_AMPS, JOB_FREQ) + 3 * t_np,
             "8 x 30 map, one call": per_s * simulated_s(ts, MAP_AMPS, MAP_FREQ) + t_np}
    for pre, env in setups.values():
        wall(pre + args + ["--freq-hz", "1", "--amplitude-deg", "0.1"], env)   # kernels cached, pages warm
    floors = {"python -c pass": [sys.executable, "-c", "pass"],
              "import numpy": [sys.executable, "-c", "import numpy"],
              "import numba": [sys.executable, "-c", "import numba"],
              "freqresp, 1 dwell": TAOS + args + ["--freq-hz", "1", "--amplitude-deg", "0.1"]}
    times = {(s, j): [] for s in setups for j in jobs}
    ftimes = {(f, e): [] for f in floors for e in ("bytecode", "from source")}
    for _ in range(3):   # interleaved: the machine's load drifts
        for s, (pre, env) in setups.items():
            for j, calls in jobs.items():
                times[s, j].append(np.sum([_cpu_wall(pre + args + c, env) for c in calls], axis=0))
        for f, cmd in floors.items():
            for e, env in (("bytecode", env_pyc), ("from source", env_src)):
                ftimes[f, e].append(_cpu_wall(cmd, env))
    cpu = {k: statistics.median(t[1] for t in v) for k, v in times.items()}
    med = {k: statistics.median(t[0] for t in v) for k, v in times.items()}
    print(f"### Start-up: whole processes, {MODEL}, {LAW} (median of 3)\n")
    print("| job | " + " | ".join(f"{s} [s]" for s in setups) + " | LSODA peer [s] | speed-up (now) | speed-up (before) |")
    print("|---|" + "---|" * (len(setups) + 3))
    now, before = list(setups)[0], list(setups)[-1]
    for j in jobs:
        print(f"| {j} | " + " | ".join(f"{med[s, j]:.2f}" for s in setups)
              + f" | {peers[j]:.1f} | {peers[j] / med[now, j]:.1f}x | {peers[j] / med[before, j]:.1f}x |")
    print("\nCPU time (user + system, all processes of the job) [s]:\n")
    print("| job | " + " | ".join(setups) + " |\n|---|" + "---|" * len(setups))
    for j in jobs:
        print(f"| {j} | " + " | ".join(f"{cpu[s, j]:.2f}" for s in setups) + " |")
    print("\n| one process, wall / CPU [s] | bytecode | from source |\n|---|---|---|")
    for f in floors:
        b, src = (tuple(statistics.median(t[i] for t in ftimes[f, e]) for i in (0, 1))
                  for e in ("bytecode", "from source"))
        print(f"| {f} | {b[0]:.2f} / {b[1]:.2f} | {src[0]:.2f} / {src[1]:.2f} |")
    print(f"\nLSODA peer: {per_s:.2f} s per simulated second (Python rhs), start-up {t_np:.2f} s a process; "
          f"settling {ts:.2f} s + 2 + 2 cycles per dwell, scaled by simulated time\n")


def _stamped(cmd, env):
    """(to the first kernel call, to its return, whole process) [s] of one process (item 7)."""
    t0 = time.time()
    r = subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    t_end = time.time() - t0
    st = {ln.split()[1]: float(ln.split()[2]) - t0 for ln in r.stderr.splitlines() if ln.startswith("taos-stamp ")}
    return st["first-kernel-call"], st["first-kernel-return"], t_end


def first_kernel(repeat=7):
    """Item 7 of the module docstring."""
    import statistics

    from taos.model import load_model
    from taos.planar.freqresp import settle_time_s

    print(f"uptime (start): {os.popen('uptime').read().strip()}\n")
    base = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPYCACHEPREFIX")}
    envs = {e: dict(base, TAOS_KERNELS=e, TAOS_STARTUP_STAMP="1") for e in ("c", "numba")}
    args = TAOS + ["freqresp", MODEL, "--friction", LAW, "--json", os.devnull]
    one = args + ["--freq-hz", "1", "--amplitude-deg", "0.1"]
    for env in envs.values():
        _stamped(one, env)   # libraries and kernels cached, pages warm
    st = {e: [] for e in envs}
    for _ in range(repeat):
        for e, env in envs.items():
            st[e].append(_stamped(one, env))
    print("| kernels | to first kernel call, median / min [s] | to its return, median / min [s] | "
          "whole 1-dwell process, median [s] |\n|---|---|---|---|")
    for e, v in st.items():
        c = [x[0] for x in v]
        r = [x[1] for x in v]
        print(f"| {e} | {statistics.median(c):.3f} / {min(c):.3f} | {statistics.median(r):.3f} / {min(r):.3f} | "
              f"{statistics.median(x[2] for x in v):.3f} |")
    calls = [args + ["--freq-hz", csv(JOB_FREQ), "--amplitude-deg", f"{a:g}"] for a in JOB_AMPS]
    job = {e: [] for e in envs}
    for _ in range(3):
        for e, env in envs.items():
            quiet = {k: v for k, v in env.items() if k != "TAOS_STARTUP_STAMP"}
            job[e].append(np.sum([_cpu_wall(c, quiet) for c in calls], axis=0))
    m = load_model(MODEL, friction=LAW)
    per_s = sum(lsoda_dwell(m, a * DEG, f, 2.0) for a, f in ((0.1, 0.5), (0.4, 2.0))) / 4.0
    t_np = wall([sys.executable, "-c", "import numpy, scipy.integrate"])
    peer = per_s * simulated_s(settle_time_s(m), JOB_AMPS, JOB_FREQ) + 3 * t_np
    print(f"\n| 3 calls of {len(JOB_FREQ)} dwells | wall, median [s] | CPU, median [s] | LSODA peer [s] | speed-up |"
          "\n|---|---|---|---|---|")
    for e, v in job.items():
        w = statistics.median(x[0] for x in v)
        print(f"| {e} kernels | {w:.2f} | {statistics.median(x[1] for x in v):.2f} | {peer:.1f} | {peer / w:.0f}x |")
    print(f"\nLSODA peer: {per_s:.2f} s per simulated second (Python rhs), start-up {t_np:.2f} s a process")
    print(f"uptime (end): {os.popen('uptime').read().strip()}")


def main(quick=False):
    from taos.linear import gain_db
    from taos.model import load_model
    from taos.planar.freqresp import settle_time_s, sine_dwell_grid

    print(f"uptime: {os.popen('uptime').read().strip()}\n")
    m = load_model(MODEL, friction=LAW)
    ts = settle_time_s(m)
    tb = sum(lsoda_dwell(m, a * DEG, f, 2.0 if quick else 4.0) for a, f in ((0.1, 0.5), (0.4, 2.0)))
    per_s = tb / (4.0 if quick else 8.0)
    tbc = sum(lsoda_dwell(m, a * DEG, f, 2.0 if quick else 4.0, compiled=True) for a, f in ((0.1, 0.5), (0.4, 2.0)))
    per_sc = tbc / (4.0 if quick else 8.0)
    t_np = wall([sys.executable, "-c", "import numpy, scipy.integrate"])
    base = TAOS + ["freqresp", MODEL, "--friction", LAW, "--json", os.devnull]
    wall(base + ["--freq-hz", "1", "--amplitude-deg", "0.1"])  # kernels loaded once (cache warm)
    rows = []
    t3 = sum(wall(base + ["--freq-hz", csv(JOB_FREQ), "--amplitude-deg", f"{a:g}"]) for a in JOB_AMPS)
    sim3 = simulated_s(ts, JOB_AMPS, JOB_FREQ)
    rows.append((f"3 calls of {len(JOB_FREQ)} dwells (one amplitude each)", t3, per_s * sim3 + 3 * t_np,
                 per_sc * sim3 + 3 * t_np))
    if not quick:
        tm = wall(base + ["--freq-hz", csv(MAP_FREQ), "--amplitude-deg", csv(MAP_AMPS)])
        simm = simulated_s(ts, MAP_AMPS, MAP_FREQ)
        rows.append((f"{len(MAP_AMPS)} x {len(MAP_FREQ)} map, one call", tm, per_s * simm + t_np, per_sc * simm + t_np))
    print(f"### Whole processes, {MODEL}, {LAW}, start-up included\n")
    print("| job | taos (ETDRK4) [s] | LSODA peer, Python rhs [s] | speed-up | LSODA peer, numba rhs [s] | speed-up |")
    print("|---|---|---|---|---|---|")
    for name, t, peer, peerc in rows:
        print(f"| {name} | {t:.2f} | {peer:.1f} | {peer / t:.0f}x | {peerc:.1f} | {peerc / t:.0f}x |")
    print(f"\nLSODA peers: {tb:.2f} s (Python rhs) and {tbc:.2f} s (numba rhs) for {4.0 if quick else 8.0:.0f} s "
          f"simulated; settling {ts:.2f} s + 2 + 2 cycles per dwell, scaled by simulated time\n")

    amps = np.array(MAP_AMPS[::2] if quick else MAP_AMPS) * DEG
    freqs = np.array(MAP_FREQ[::3] if quick else MAP_FREQ)
    sine_dwell_grid(m, amps[:1], freqs[-1:], settle_s=0.0)
    sine_dwell_grid(m, amps[:1], freqs[-1:], settle_s=0.0, integrator="rk4")
    res = {}
    for name, kw in (("ETDRK4, step from the friction loop (default)", {}),
                     ("RK4 kernel, dt 2e-4 s (before)", {"integrator": "rk4"}),
                     ("RK4 kernel, dt 2e-4 s, 60 s settling", {"integrator": "rk4", "settle_s": 60.0,
                                                               "measure_cycles": 1}),
                     ("RK4 kernel, dt 5e-5 s, 60 s settling (reference)",
                      {"integrator": "rk4", "settle_s": 60.0, "measure_cycles": 1, "dt_max_s": 5e-5})):
        t0 = time.perf_counter()
        p, e = sine_dwell_grid(m, amps, freqs, **kw)
        res[name] = (time.perf_counter() - t0, p, e)
    _, pr, er = res["RK4 kernel, dt 5e-5 s, 60 s settling (reference)"]
    print(f"### In-process, kernels warm: {amps.size} x {freqs.size} map\n")
    sim_in = simulated_s(ts, list(amps), list(freqs))
    print(f"LSODA peers for this map, scaled: {per_s * sim_in:.0f} s Python rhs, {per_sc * sim_in:.0f} s numba rhs\n")
    print("| integrator | wall [s] | engine vs 60 s reference [dB / deg] | piston vs 60 s reference [dB / deg] |")
    print("|---|---|---|---|")
    for name, (t, p, e) in res.items():
        d = lambda a, b: (np.max(np.abs(gain_db(a) - gain_db(b))), np.max(np.abs(np.degrees(np.angle(a / b)))))  # noqa: E731
        de, dp = d(e, er), d(p, pr)
        print(f"| {name} | {t:.2f} | {de[0]:.4f} / {de[1]:.3f} | {dp[0]:.4f} / {dp[1]:.3f} |")
    print("\n### One dwell in time (2 cycles from rest), max engine error against RK4 at 2.5e-5 s\n")
    print("| dwell | ETDRK4 step [s] (set by) | ETDRK4 error [deg] | RK4 at 2e-4 s error [deg] |\n|---|---|---|---|")
    for a, f in ((0.1, 1.0), (1.0, 2.0), (0.02, 5.0)):
        e_exp, e_rk4, dt, why = time_domain(m, a * DEG, f)
        print(f"| {a:g} deg, {f:g} Hz | {dt:.3g} ({why}) | {e_exp:.1e} | {e_rk4:.1e} |")
    print(f"\nuptime: {os.popen('uptime').read().strip()}")


if __name__ == "__main__":
    if "--first-kernel" in sys.argv:
        first_kernel(int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 7)
        sys.exit(0)
    if "--before-after" in sys.argv or "--startup" in sys.argv:
        print(f"uptime: {os.popen('uptime').read().strip()}\n")
        (startup if "--startup" in sys.argv else before_after)(quick="--quick" in sys.argv)
        print(f"uptime: {os.popen('uptime').read().strip()}")
    else:
        main(quick="--quick" in sys.argv)
