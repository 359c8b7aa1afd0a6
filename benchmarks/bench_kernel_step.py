"""Per-step CPU cost of the compiled integrators for one friction law, for A/B comparisons
of two checkouts on a shared machine (CPU time, best of several runs, so other jobs' load
matters less than in wall time).

    PYTHONPATH=<checkout> NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/bench_kernel_step.py LAW OUT.npz

Simplex: 20 s of a 0.1 deg 0.5 Hz sine through the ambient model (dt 2e-4 s, best of 7).
TAOS: 10 s of the two-axis Green Run profile, hot-fire model (best of 3). The records are
saved to OUT.npz so two checkouts' results can be compared number for number.
"""
import math, sys, time
import numpy as np
from taos.model import load_model
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import integrate_plant
from taos.taos3d import load_taos_model
from taos.taos3d.simulate import run_samples, pack
from taos.profiles import load_profile
m = load_model("models/rs25_ambient.toml", friction=sys.argv[1])
plant = simplex_plant(m)
dt = 2e-4; n = 100000
t = np.arange(n + 1) * dt
r = (0.1 * math.pi / 180 * np.sin(2 * math.pi * 0.5 * t))[:, None]
integrate_plant(plant, m, r[:100], dt, 10)
best = math.inf
for _ in range(7):
    t0 = time.process_time(); y, aux = integrate_plant(plant, m, r, dt, 10); best = min(best, time.process_time() - t0)
print(f"simplex {sys.argv[1]}: {best / n * 1e9:.0f} ns/step", end="; ")
tm = load_taos_model("models/rs25_hotfire.toml", friction=sys.argv[1])
p = load_profile("models/profiles/greenrun_two_axis.toml")
n3 = 50000; t3 = np.arange(n3 + 1) * dt
cmd = np.ascontiguousarray(np.asarray(p(t3)).T)
pk = pack(tm)
run_samples(tm, cmd[:11], dt, 10, pk)
best = math.inf
for _ in range(3):
    t0 = time.process_time(); out = run_samples(tm, cmd, dt, 10, pk); best = min(best, time.process_time() - t0)
print(f"taos3d: {best / n3 * 1e6:.2f} us/step")
np.savez(sys.argv[2], y=y, aux=aux, out=out)
