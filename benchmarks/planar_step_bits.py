"""The planar kernels' numbers, bit for bit (branch stage4: the RK4 step's four stages through one
inlined copy of its rates), and their CPU time.

    PYTHONPATH=$PWD NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/planar_step_bits.py --save OUT.npz [--compare REF.npz]

Runs, on the hot-fire model (models/rs25_hotfire.toml) with every built-in friction law
(``--law`` to pick some):

1. ``simulate`` over the Green Run two-axis profile (models/profiles/greenrun_two_axis.toml,
   the first ``--duration`` s; whole profile by default) with the RK4 integrator
   (:func:`taos.planar.dynamics.integrate_samples`, :func:`taos.planar.dynamics._rk4_step`)
   and the exponential one (``integrator="exp"``);
2. the dwells of a 2 x 4 grid (0.1 and 0.4 deg, 0.5-20 Hz; settle 1 s): settled RK4
   (:func:`taos.planar.dynamics.sine_steps`), settled ETDRK4, and shooting
   (:mod:`taos.planar.steady`) with each integrator (numba's kernels: ``TAOS_KERNELS=numba``),
   and the settled ETDRK4 dwells on the C kernels (:mod:`taos.planar._cdwell`);
3. the LCO confirmation's kernel (:func:`taos.flight.lco_confirm.confirm`'s
   ``integrate_samples`` call: zero input from a displaced state, 20 s at 4e-4 s, records every 10).

Keeps every array (the TimeHistory's arrays, the dwells' complex responses, the confirmation's
records and status) in ``--save``; with ``--compare`` reports whether each equals the reference
file's bit for bit (exit 1 if not). Prints the CPU seconds of each part (time.process_time) and
the load average.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
AMPS = np.radians([0.1, 0.4])
FREQS = np.array([0.5, 2.0, 7.0, 20.0])


def _arrays(prefix: str, obj) -> dict:
    out = {}
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray):
            out[f"{prefix}_{f.name}"] = v
        elif isinstance(v, dict):
            out.update({f"{prefix}_{f.name}_{k}": np.asarray(a) for k, a in v.items() if isinstance(a, np.ndarray)})
    return out


def run_law(law: str, duration: float | None, spent: dict) -> dict:
    from taos.flight.lco_confirm import RECORD_EVERY, kernel_args
    from taos.model import load_model
    from taos.planar import dynamics as dyn
    from taos.planar._cdwell import ENV
    from taos.planar.freqresp import sine_dwell_grid
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import simulate
    from taos.profiles import load_profile

    res = {}
    m = load_model("rs25_hotfire", friction=law)
    prof = load_profile(ROOT / "models" / "profiles" / "greenrun_two_axis.toml")

    def timed(key, f):
        c = time.process_time()
        r = f()
        spent[key] = spent.get(key, 0.0) + time.process_time() - c
        return r

    for integ in ("rk4", "exp"):
        h = timed(f"simulate {integ}", lambda: simulate(m, prof, duration_s=duration, integrator=integ, threads=1))
        res.update(_arrays(f"{law}_sim_{integ}", h))
    for name, kw in (("dwell_rk4", {"integrator": "rk4"}), ("dwell_exp", {}), ("dwell_exp_c", {}),
                     ("shoot_exp", {"method": "shoot"}), ("shoot_rk4", {"method": "shoot", "integrator": "rk4"})):
        os.environ[ENV] = "c" if name.endswith("_c") else "numba"   # the C dwells only where named
        try:
            p, e = timed(name.replace("_", " "), lambda: sine_dwell_grid(m, AMPS, FREQS, settle_s=1.0, **kw))
        finally:
            os.environ.pop(ENV, None)
        res[f"{law}_{name}_piston"] = p
        res[f"{law}_{name}_engine"] = e
    plant = simplex_plant(m, "pitch")
    n = plant.ss.A.shape[0]
    x0 = np.zeros(n)
    x0[: min(n, 4)] = 1e-3   # a displaced start (units of the first states)
    k = 50000
    dt = 4e-4
    Cy = np.ascontiguousarray(np.vstack([plant.cmd_c, np.eye(n)]))
    y = np.empty((k // RECORD_EVERY + 1, Cy.shape[0]))
    aux = np.empty((k // RECORD_EVERY + 1, dyn.N_AUX))
    st = timed("confirmation", lambda: dyn.integrate_samples(
        *kernel_args(plant, m), Cy, m.friction.entry.rates, m.friction.pack(), m.avionics.pack(), x0, 2e-4,
        np.zeros((k + 1, 1)), dt, RECORD_EVERY, y, aux))
    res[f"{law}_confirm_y"], res[f"{law}_confirm_aux"], res[f"{law}_confirm_status"] = y, aux, np.asarray(st)
    return res


def main() -> None:
    from rk4_stage_bits import save_compare   # (this folder: the script's own)

    from taos.friction._builtin import modules

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save", required=True)
    ap.add_argument("--compare", default=None)
    ap.add_argument("--law", action="append", default=None, help="friction law id (repeatable; default: all)")
    ap.add_argument("--duration", type=float, default=None, help="seconds of the Green Run (default: all)")
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    laws = a.law or sorted(modules())
    res, spent = {}, {}
    for law in laws:
        res.update(run_law(law, a.duration, spent))
    print(f"laws: {', '.join(laws)}")
    print("CPU s: " + ", ".join(f"{k} {v:.2f}" for k, v in spent.items()))
    print(f"load {load0:.2f} -> {os.getloadavg()[0]:.2f}")
    save_compare(res, a.save, a.compare)


if __name__ == "__main__":
    main()
