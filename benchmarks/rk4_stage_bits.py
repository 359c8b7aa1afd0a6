"""The RK4 lane kernels' records, bit for bit, and their kernel CPU time (branch compile2: the
four stages through one inlined copy of their rates).

    PYTHONPATH=$PWD NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/rk4_stage_bits.py --save OUT.npz [--compare REF.npz]

Runs (1) a 32-run batch of the soft case of models/montecarlo/post_separation.toml through the
RK4 lanes at 1 ms (:func:`taos.planar.dynamics.integrate_segments_lanes`, as
``integrator = "rk4"``), (2) the same batch through the ETDRK4 lanes at the campaign's 5 ms
(:func:`taos.planar._explanes.integrate_segments_lanes_exp`, the Monte Carlo default; added on
branch lanesnrt) and (3) masv simulate (:func:`masv._kernel.integrate`) on
models/masv/core_stage.toml over the first 5 s of the Green Run two-axis profile; keeps every
array the kernels write (records, statuses) and the batch's stored outputs in ``--save``, and
with ``--compare`` reports whether each equals the reference file's bit for bit (exit 1 if not).
Prints the kernels' CPU seconds (time.process_time around each kernel call, best of
``--repeat`` after a first call that loads the compiled code) and the load average.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _capture(mod, name, outs, spent, idx):
    orig = getattr(mod, name)

    def wrapped(*a):
        c = time.process_time()
        ret = orig(*a)
        spent.append(time.process_time() - c)
        outs.append([np.array(a[i], copy=True) for i in idx] + [np.asarray(ret)])
        return ret
    setattr(mod, name, wrapped)
    return lambda: setattr(mod, name, orig)


def lanes(runs: int, repeat: int, exp: bool = False) -> tuple[dict, float]:
    import taos.planar._explanes as xl
    import taos.planar.dynamics as dyn
    from taos.montecarlo import load_campaign
    from taos.montecarlo.executor import flight_runs, montecarlo_design
    c = load_campaign("post_separation")
    kind, _ = flight_runs(c, "soft", None)
    if not exp:
        kind = replace(kind, campaign=replace(c, integrator="rk4", dt_s=1e-3))
    mod, name, idx, tag = ((xl, "integrate_segments_lanes_exp", (19, 20, 21), "exp") if exp
                           else (dyn, "integrate_segments_lanes", (17, 18, 19), "lanes"))
    d = montecarlo_design(c, runs + 1)
    kind.run_batch(d.names, d.factors[:2], d.seeds[:2])   # load the compiled kernel
    best, res = float("inf"), {}
    for _ in range(repeat):
        outs, spent = [], []
        undo = _capture(mod, name, outs, spent, idx)
        try:
            got = kind.run_batch(d.names, d.factors[1:], d.seeds[1:])
        finally:
            undo()
        best = min(best, sum(spent))
        res = {f"{tag}_call{i}_{j}": a for i, o in enumerate(outs) for j, a in enumerate(o)}
        res.update({f"{tag}_batch_{k}": np.asarray(v) for k, v in got.items() if k != "error"})
    return res, best


def masv(repeat: int) -> tuple[dict, float]:
    import masv._kernel as kn
    import masv.timedomain as td
    from masv.config import load_config
    from taos.profiles import load_profile
    prof = load_profile(ROOT / "models" / "profiles" / "greenrun_two_axis.toml")
    cfg = load_config(ROOT / "models" / "masv" / "core_stage.toml")
    td.simulate(cfg, prof, duration_s=0.2)
    best, res = float("inf"), {}
    for _ in range(repeat):
        outs, spent = [], []
        undo = _capture(kn, "integrate", outs, spent, (19, 20, 21))
        try:
            h = td.simulate(cfg, prof, duration_s=5.0)
        finally:
            undo()
        best = min(best, sum(spent))
        res = {f"masv_{j}": a for j, a in enumerate(outs[0])}
        res.update({f"masv_hist_{k}": v for k, v in vars(h).items() if isinstance(v, np.ndarray)})
    return res, best


def save_compare(res: dict, save: str, compare: str | None) -> None:
    """Keep the arrays ``res`` in ``save`` (.npz); with ``compare`` (a reference .npz), report
    whether every array equals the reference's bit for bit and exit 1 if not."""
    np.savez(save, **res)
    if compare:
        ref = np.load(compare)
        bad = sorted(set(ref.files) ^ set(res))
        bad += [k for k in ref.files if k in res and not (ref[k].dtype == res[k].dtype and ref[k].shape == res[k].shape
                                                           and ref[k].tobytes() == res[k].tobytes())]
        print(f"{len(res)} arrays against {compare}: " + ("all bit-identical" if not bad else f"DIFFER: {bad}"))
        sys.exit(1 if bad else 0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save", required=True)
    ap.add_argument("--compare", default=None)
    ap.add_argument("--runs", type=int, default=32)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    r1, t1 = lanes(a.runs, a.repeat)
    r3, t3 = lanes(a.runs, a.repeat, exp=True)
    r2, t2 = masv(a.repeat)
    print(f"RK4 lanes kernel, {a.runs} runs x 200 s at 1 ms: {t1:.3f} s CPU ({t1 / a.runs * 1e3:.1f} ms a run), "
          f"best of {a.repeat}")
    print(f"ETDRK4 lanes kernel, {a.runs} runs x 200 s at 5 ms: {t3:.3f} s CPU ({t3 / a.runs * 1e3:.1f} ms a run), "
          f"best of {a.repeat}")
    print(f"masv kernel, core_stage 5 s at 4e-4 s: {t2:.3f} s CPU, best of {a.repeat}")
    print(f"load {load0:.2f} -> {os.getloadavg()[0]:.2f}")
    res = {**r1, **r3, **r2}
    save_compare(res, a.save, a.compare)


if __name__ == "__main__":
    main()
