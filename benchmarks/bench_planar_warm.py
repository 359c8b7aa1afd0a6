"""Warm speed of the planar kernels (CPU time, best of N; one numba thread) and a SHA-256 prefix
of their numbers (the same prefix in two trees: the same bits), for A/B runs of two trees,
alternately, each with its own warm kernel cache:

    NUMBA_CACHE_DIR=/tmp/nbc_a PYTHONPATH=<tree> .venv/bin/python benchmarks/bench_planar_warm.py

RK4 simulation of the simplex plant (ambient model, LuGre, 20 s at 2e-4 s, records every 10
steps: ns per step, best of 7), the three dwell grids of ``bench_dwell_batch.py`` (ETDRK4, RK4,
shooting; best of 3) and 5 s of ``simulate`` with each integrator (hot-fire model, best of 3).
"""
import hashlib, math, time
import numpy as np
from taos.model import load_model
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import integrate_plant, simulate
from taos.planar.freqresp import sine_dwell_grid
def dig(*a):
    h = hashlib.sha256()
    for x in a: h.update(np.ascontiguousarray(x).tobytes())
    return h.hexdigest()[:12]
def best(f, k):
    b = math.inf
    for _ in range(k):
        c = time.process_time(); res = f(); b = min(b, time.process_time() - c)
    return b, res
m = load_model("models/rs25_ambient.toml", friction="lugre")
plant = simplex_plant(m)
dt = 2e-4; n = 100000
t = np.arange(n + 1) * dt
r = (0.1 * math.pi / 180 * np.sin(2 * math.pi * 0.5 * t))[:, None]
integrate_plant(plant, m, r[:100], dt, 10)
b, (y, aux) = best(lambda: integrate_plant(plant, m, r, dt, 10), 7)
print(f"simplex rk4 integrate_samples: {b / n * 1e9:.0f} ns/step  {dig(y, aux)}", flush=True)
hm = load_model("rs25_hotfire")
AMPS = np.array([0.05, 0.2, 0.4]) * math.pi / 180
FREQ = np.logspace(np.log10(0.5), np.log10(20.0), 8)
import numba; numba.set_num_threads(1)
for name, kw in (("dwell etdrk4", {}), ("dwell rk4", {"integrator": "rk4"}), ("shoot", {"method": "shoot"})):
    g = lambda: sine_dwell_grid(hm, AMPS, FREQ, settle_s=1.0, **kw)
    g()
    b, res = best(g, 3)
    print(f"{name}: cpu {b:.3f} s  {dig(*res)}", flush=True)
from taos.profiles import SineDwell
for integ in ("rk4", "exp"):
    f = lambda: simulate(hm, SineDwell(math.radians(0.4), 2.0, 10), duration_s=5.0, integrator=integ)
    f()
    b, res = best(f, 3)
    import dataclasses
    arrs = [getattr(res, fl.name) for fl in dataclasses.fields(res)]
    arrs = [np.asarray(v) for v in arrs if isinstance(v, np.ndarray)] + [np.asarray(v) for a in arrs if isinstance(a, dict) for v in a.values() if isinstance(v, np.ndarray)]
    print(f"simulate {integ} 5 s: cpu {b:.3f} s  {dig(*arrs)}", flush=True)
