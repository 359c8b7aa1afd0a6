"""MASV 8x8 frequency-response speed: block elimination over the diagonal modal part vs naive
dense solves of the whole state space, 200 modes, 1000 frequencies.

    .venv/bin/python benchmarks/bench_masv.py [--modes 200] [--freqs 1000] [--naive-freqs 100]

Peers, same model, same run:
  * masv block elimination (MasvSystem.frf): structure receptance Phi diag(.) Phi^T in
    O(n m^2) (two real GEMMs over all frequencies), eight small engine blocks, one 28 x 28 solve
    per frequency (8 elongations, 8 gimbal rotations, 4 x 3 gimbal accelerations; batched numpy);
  * naive dense: scipy.linalg.solve(j w I - A, B) on the full balanced state space per frequency
    (MasvSystem.frf_dense);
  * taos.linear.StateSpace.freqresp (Hessenberg reduction once, then a dense solve per frequency).
The naive peers run on ``--naive-freqs`` frequencies (a subset of the same grid) and their time
is also scaled to the full grid; all three are checked to agree.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from masv.config import make_config
from masv.synthetic import core_stage_specs, synthetic_structure
from masv.system import build_system
from taos.model import load_model

ROOT = Path(__file__).resolve().parents[1]


def best_of(fn, repeat=3):
    ts = []
    out = None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return min(ts), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--modes", type=int, default=200)
    ap.add_argument("--freqs", type=int, default=1000)
    ap.add_argument("--naive-freqs", type=int, default=100)
    a = ap.parse_args()
    model = load_model(ROOT / "models" / "rs25_hotfire.toml")
    n_internal = max(0, int(np.ceil((a.modes / 6 - 12) / 4)))
    st = synthetic_structure(n_internal=n_internal, n_modes=a.modes)
    e, acts = core_stage_specs(model, st)
    t0 = time.perf_counter()
    s = build_system(make_config(e, acts, st))
    t_build = time.perf_counter() - t0
    ss = s.state_space()
    f = np.logspace(-1, 2, a.freqs)
    t_fast, (xp, th) = best_of(lambda: s.frf(f))
    sub = f[:: max(1, a.freqs // a.naive_freqs)]
    t_dense, (xd, _td) = best_of(lambda: s.frf_dense(sub), repeat=1)
    t_hess, h = best_of(lambda: ss.freqresp(sub), repeat=1)
    k = np.searchsorted(f, sub)
    err_dense = np.max(np.abs(xp[k] - xd)) / np.max(np.abs(xd))
    err_hess = np.max(np.abs(xp[k] - h[:, :8, :])) / np.max(np.abs(xd))
    scale = f.size / sub.size
    print(f"model: {s.n_actuators} actuators, {s.omega_rad_s.size} modes, {ss.A.shape[0]} states "
          f"(highest mode {st.freq_hz.max():.0f} Hz); build {t_build * 1e3:.1f} ms")
    print(f"| method | frequencies | wall [s] | per frequency [ms] | scaled to {f.size} [s] | max rel. diff |")
    print("|---|---|---|---|---|---|")
    print(f"| masv block elimination | {f.size} | {t_fast:.3f} | {t_fast / f.size * 1e3:.3f} | {t_fast:.3f} | - |")
    print(f"| naive dense solve | {sub.size} | {t_dense:.2f} | {t_dense / sub.size * 1e3:.1f} | "
          f"{t_dense * scale:.1f} | {err_dense:.1e} |")
    print(f"| taos StateSpace.freqresp (Hessenberg) | {sub.size} | {t_hess:.2f} | {t_hess / sub.size * 1e3:.1f} | "
          f"{t_hess * scale:.1f} | {err_hess:.1e} |")
    print(f"speed-up vs naive dense: {t_dense * scale / t_fast:.0f}x")


if __name__ == "__main__":
    main()
