"""Benchmark: the Green Run's independent runs on both cores against the serial path, and the
time-domain two-axis run against a plain scipy LSODA peer, all in one process.

Rows (``rs25_hotfire``, the default two-axis profile ``models/profiles/greenrun_two_axis.toml``,
warm kernel cache; every case run ``--reps`` times, the cases interleaved so that a change of
machine load hits them alike; median and best wall time, and the process CPU time):

* ``taos.report.analysis.greenrun`` with the simplex engine and with the 3-D engine
  (``engine="taos"``), ``threads=1`` (the serial path: every run one after the other) against
  ``threads=2``; for the 3-D engine also the serial path with the linearisation recomputed on
  every call (as before this branch), the memo's share;
* the two-axis time-domain run alone (``taos.planar.simulate.simulate``), ``threads`` 1 and 2;
* the peer: ``scipy.integrate.solve_ivp`` (LSODA, rtol ``--rtol``, atol 1e-12, max_step 2e-3 s)
  on the same equations (plant matrices, friction law kernel, the avionics' pure-Python
  original, the actuator limits), one axis after the other, over the first ``--peer-s``
  seconds of the same profile (default 1 s: the peer needs about 110 s of wall time per
  simulated second under load, so the whole 33 s run would take up to an hour), beside
  our run over that slice; the peer's largest engine-angle difference from our run is printed.

Every parallel result is checked equal to the serial one (the summary without its time stamp,
the run's arrays) before any figure is printed.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_greenrun_parallel.py [--reps 5] [--peer-s 1]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "rs25_hotfire.toml"


def timed(fn):
    c, t = time.process_time(), time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t, time.process_time() - c


def _summary(r):
    s = r.summary()
    s.pop("created_utc")
    return s


class _NoMemo(dict):
    """A linearisation store that keeps nothing: every call linearises again (before this branch)."""

    def __setitem__(self, key, value):
        pass


def peer_lsoda(model, profile, T: float, t_eval: np.ndarray, rtol: float) -> tuple[float, np.ndarray]:
    """solve_ivp LSODA of each axis' planar model over [0, T], one axis after the other: the
    state equations of :mod:`taos.planar.dynamics` (the same plant matrices, friction law kernel,
    avionics as pure Python, the actuator limits' compiled function) with the exact command;
    (wall [s], engine angle (2, n) [rad] at ``t_eval``)."""
    from scipy.integrate import solve_ivp

    from taos.planar import avionics as av
    from taos.planar import saturation as lim_laws
    from taos.planar.simulate import _with_spool_output, kernel_args
    from taos.planar.simplex import simplex_plant

    rates, apply = model.friction.entry.rates, av.apply.py_func
    fp, avp = model.friction.pack(), model.avionics.pack()
    out = []
    t0 = time.perf_counter()
    for i, ax in enumerate(("pitch", "yaw")):
        plant = _with_spool_output(simplex_plant(model, ax))
        A, Br, bc, bf, cc, dc, cw, ca, lim = kernel_args(plant, model)
        Cth = plant.ss.C[plant.ss.output_index("theta_rad")]

        def rhs(t, s, i=i, A=A, Br=Br, bc=bc, bf=bf, cc=cc, dc=dc, cw=cw, ca=ca, lim=lim):
            x, z = s[:-1], s[-1]
            r = profile(np.array([t]))[i]
            u = apply(float(cc @ x + dc @ r), avp)
            dz, tf = rates(cw @ x, z, ca @ x, fp)
            dx = A @ x + Br @ r + bc * u + bf * tf
            lim_laws.apply(lim, x, u, dx)
            return np.append(dx, dz)

        sol = solve_ivp(rhs, (0.0, T), np.zeros(A.shape[0] + 1), method="LSODA", t_eval=t_eval, rtol=rtol,
                        atol=1e-12, max_step=2e-3)
        out.append(Cth @ sol.y[:-1])
    return time.perf_counter() - t0, np.vstack(out)


def bench_greenrun(model, prof, reps: int) -> None:
    """The Green Run (both engines) and the two-axis run, serial against parallel, interleaved."""
    import numba

    import taos.taos3d.simulate as t3
    from taos.planar.simulate import TimeHistory, simulate
    from taos.report.analysis import greenrun

    memo = t3._LINEARISED

    def gr(engine, n, memoised=True):
        t3._LINEARISED = memo if memoised else _NoMemo()
        try:
            return greenrun(model, engine=engine, threads=n)
        finally:
            t3._LINEARISED = memo

    cases = {
        "greenrun simplex, threads=1 (serial)": lambda: gr("simplex", 1),
        "greenrun simplex, threads=2": lambda: gr("simplex", 2),
        "greenrun taos (3-D), serial, linearised every call (before)": lambda: gr("taos", 1, memoised=False),
        "greenrun taos (3-D), threads=1 (serial)": lambda: gr("taos", 1),
        "greenrun taos (3-D), threads=2": lambda: gr("taos", 2),
        "two-axis run alone, threads=1": lambda: simulate(model, prof, threads=1),
        "two-axis run alone, threads=2": lambda: simulate(model, prof, threads=2),
    }
    for fn in cases.values():   # warm: kernels loaded, caches of the profile made
        fn()
    walls = {k: [] for k in cases}
    cpus = {k: [] for k in cases}
    results = {}
    for _ in range(reps):
        for k, fn in cases.items():
            results[k], w, c = timed(fn)
            walls[k].append(w)
            cpus[k].append(c)

    # the parallel results are the serial ones
    for eng in ("simplex", "taos (3-D)"):
        ser = _summary(results[f"greenrun {eng}, threads=1 (serial)"])
        assert ser == _summary(results[f"greenrun {eng}, threads=2"]), eng
    ths = [results[f"two-axis run alone, threads={n}"] for n in (1, 2)]
    for name in TimeHistory.ARRAYS + TimeHistory.OPTIONAL_ARRAYS:
        assert np.array_equal(getattr(ths[0], name), getattr(ths[1], name)), name

    print(f"# Green Run on both cores ({os.cpu_count()} cores, numba threads {numba.get_num_threads()}, "
          f"threading layer {numba.threading_layer()}); {reps} interleaved reps; parallel results == serial")
    print(f"# uptime: {os.popen('uptime').read().strip()}")
    print("| case | median wall [s] | best wall [s] | median CPU [s] | CPU / wall |")
    print("|---|---|---|---|---|")
    for k in cases:
        mw, mc = statistics.median(walls[k]), statistics.median(cpus[k])
        print(f"| {k} | {mw:.3f} | {min(walls[k]):.3f} | {mc:.3f} | {mc / mw:.2f} |")
    med = {k: statistics.median(v) for k, v in walls.items()}
    print()
    for label, s, p in (("greenrun simplex", "greenrun simplex, threads=1 (serial)", "greenrun simplex, threads=2"),
                        ("greenrun taos", "greenrun taos (3-D), threads=1 (serial)", "greenrun taos (3-D), threads=2"),
                        ("greenrun taos, before / now", "greenrun taos (3-D), serial, linearised every call (before)",
                         "greenrun taos (3-D), threads=2"),
                        ("two-axis run", "two-axis run alone, threads=1", "two-axis run alone, threads=2")):
        print(f"{label}: {med[s] / med[p]:.2f}x (median wall, {s} / {p})")


def bench_peer(model, prof, T: float, rtol: float, reps: int) -> None:
    """The first ``T`` s of the two-axis run: ours (threads 1 and 2) against the LSODA peer."""
    from taos.planar.simulate import simulate

    ours = {}
    for n in (1, 2):
        best = math.inf
        for _ in range(reps):
            th, w, _ = timed(lambda n=n: simulate(model, prof, duration_s=T, record_every=1, threads=n))
            best = min(best, w)
        ours[n] = (best, th)
    th = ours[1][1]
    t_eval = th.t_s[::10]
    wall_peer, eng_peer = peer_lsoda(model, prof, T, t_eval, rtol)
    diff = np.degrees(np.max(np.abs(eng_peer - th.engine_rad[:, ::10])))
    print(f"\n# peer: first {T:g} s of the two-axis profile, both axes; uptime {os.popen('uptime').read().strip()}")
    print("| run | wall [s] | x real time |")
    print("|---|---|---|")
    print(f"| solve_ivp LSODA rtol={rtol:g}, one axis after the other | {wall_peer:.3f} | {T / wall_peer:.3f} |")
    for n in (1, 2):
        print(f"| taos RK4 kernel dt=2e-4 s, threads={n} (best of {reps}) | {ours[n][0]:.4f} | {T / ours[n][0]:.0f} |")
    print(f"\npeer / ours: {wall_peer / ours[1][0]:.0f}x (serial), {wall_peer / ours[2][0]:.0f}x (threads=2); "
          f"largest engine-angle difference {diff:.2e} deg")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--peer-s", type=float, default=1.0, help="simulated seconds of the LSODA peer")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--peer-only", action="store_true", help="only the slice and its peer")
    a = ap.parse_args()

    from taos.model import load_model
    from taos.report.analysis import DEFAULT_PROFILE, _profile_of

    model = load_model(MODEL)
    prof = _profile_of(DEFAULT_PROFILE)[0]
    if not a.peer_only:
        bench_greenrun(model, prof, a.reps)
    bench_peer(model, prof, a.peer_s, a.rtol, a.reps)


if __name__ == "__main__":
    main()
