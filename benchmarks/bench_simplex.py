"""Benchmark: simplex model with LuGre friction, simulated seconds per wall second.

Our compiled fixed-step RK4 kernel and our exponential integrator (ETDRK4,
``simulate(integrator="exp")``: the command sampled at dt, the step chosen by the friction loop,
at most the record interval) against a plain scipy.integrate.solve_ivp (LSODA) on the
same equations (the same plant matrices; the friction law's registry kernels called from
Python and the avionics kernel's pure-Python original, ``.py_func``), run in the same script. Both are checked against a reference run
(our kernel at dt = 2.5e-5 s) so each figure is quoted at its accuracy.

    .venv/bin/python benchmarks/bench_simplex.py
"""

from __future__ import annotations

import math
import platform
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from taos.planar import avionics as av
from taos.model import load_model
from taos.profiles import MultiRamp, Sequence, SineDwell
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import kernel_args, simulate

DEG = math.pi / 180
T = 20.0
ROOT = Path(__file__).resolve().parents[1]


def profile():
    return Sequence((SineDwell(0.1 * DEG, 0.5, 5), MultiRamp((0.3 * DEG, -0.3 * DEG, 0.0), 0.5 * DEG, 1.0)))


def ours(model, dt, integrator="rk4", record_s=1e-3):
    simulate(model, profile(), dt_s=dt, duration_s=1.0, integrator=integrator)  # compile / warm
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        th = simulate(model, profile(), dt_s=dt, record_every=max(1, int(round(record_s / dt))), duration_s=T,
                      integrator=integrator)
        best = min(best, time.perf_counter() - t0)
    return best, th.t_s, th.engine_rad[0], th.provenance.get("exp", {}).get("pitch")


def scipy_baseline(model, t_eval, rtol):
    plant = simplex_plant(model)
    A, Br, bc, bf, cc, dc, cw, ca, _lim = kernel_args(plant, model)  # the scipy baseline has no limits
    fp, avp = model.friction.pack(), model.avionics.pack()
    rates, apply = model.friction.entry.rates, av.apply.py_func
    prof = profile()
    ith = plant.ss.output_index("theta_rad")
    Cth = plant.ss.C[ith]

    def rhs(t, s):
        x, z = s[:-1], s[-1]
        r = float(prof(t))
        u = apply(r, avp)
        w = cw @ x
        dz, tf = rates(w, z, ca @ x, fp)
        return np.append(A @ x + bc * u + bf * tf, dz)

    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0, T), np.zeros(A.shape[0] + 1), method="LSODA", t_eval=t_eval, rtol=rtol,
                    atol=1e-12, max_step=2e-3)
    wall = time.perf_counter() - t0
    return wall, Cth @ sol.y[:-1]


def main():
    model = load_model(ROOT / "models" / "rs25_ambient.toml", friction="lugre")
    _, t_ref, ref, _ = ours(model, 2.5e-5)
    rows = []
    for dt in (8e-4, 4e-4, 2e-4):
        wall, t, th, _ = ours(model, dt)
        err = np.degrees(np.max(np.abs(np.interp(t_ref, t, th) - ref)))
        rows.append((f"taos RK4 kernel, dt={dt:g} s", wall, err))
    # the exponential integrator: records every 1 ms (as the RK4 rows) and every 2 ms (simulate's
    # default record interval at dt = 2e-4 s); its step is at most the record interval
    for rec in (1e-3, 2e-3):
        wall, t, th, how = ours(model, 2e-4, "exp", rec)
        err = np.degrees(np.max(np.abs(np.interp(t_ref, t, th) - ref)))
        rows.append((f"taos ETDRK4, command at 2e-4 s, step <= {how['exp_max_step_s']:g} s "
                     f"({how['exp_steps']} steps, {how['exp_step_set_by']}), records every {rec:g} s", wall, err))
    for rtol in (1e-3, 1e-4, 1e-6):
        wall, th = scipy_baseline(model, t_ref, rtol)
        err = np.degrees(np.max(np.abs(th - ref)))
        rows.append((f"scipy solve_ivp LSODA, rtol={rtol:g}", wall, err))
    print(f"# simplex + LuGre, {T:g} s simulated ({platform.processor() or platform.machine()}, 1 core)")
    print(f"| run | wall [s] | x real time | max engine error [deg] |")
    print(f"|---|---|---|---|")
    for name, wall, err in rows:
        print(f"| {name} | {wall:.4f} | {T / wall:.0f} | {err:.1e} |")
    base = [r for r in rows if "LSODA" in r[0] and r[2] < 1e-4]
    mine = [r for r in rows if "kernel" in r[0] and r[2] < 1e-4]
    exp = [r for r in rows if "ETDRK4" in r[0]]
    rk = [r for r in rows if "dt=0.0002" in r[0]][0]
    for r in exp:
        print(f"\n{r[0]}: {rk[1] / r[1]:.2f}x the RK4 kernel's speed at its default dt = 2e-4 s, "
              f"error {r[2] / rk[2]:.2f}x its error")
    if base and mine:
        fastest = min(mine, key=lambda r: r[1])
        print(f"\nat < 1e-4 deg: fastest kernel {T / fastest[1]:.0f}x real time; "
              f"{min(b[1] for b in base) / fastest[1]:.0f}x faster than the most accurate-enough LSODA run")


if __name__ == "__main__":
    main()
