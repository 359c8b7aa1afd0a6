#!/usr/bin/env python
"""Benchmark: fit K_L and three friction parameters (LuGre T_c, sigma_0, sigma_2) to a
20-frequency sine-dwell data set, CasADi/IPOPT with exact derivatives beside
scipy.optimize.least_squares with finite-difference Jacobians on the same problem.

Data: the hot-fire model with a LuGre law reduced to its Dahl core plus viscous damping
(T_s = T_c, sigma_1 = 0: the surrogate's friction element is then exact under a sinusoidal
rate; the loop's harmonics are what the defect correction adds), time-domain sine dwells (taos.planar.freqresp.sine_dwell_grid) at the Green
Run amplitudes (0.4 deg to 7 Hz, 0.8 deg above), 20 log-spaced frequencies 0.3-14 Hz, 0.5 %
complex noise. Same start (K_L 150,000 lbf/in, T_c 100,000 in-lbf, sigma_0 and sigma_2 x 2),
same bounds, same residual function (the CasADi surrogate evaluated numerically for scipy,
its implicit amplitudes solved per call by the same bisection). Then the fit end to end with
and without the global first stage (issue 29.7), from this start and from the ambient model's
K_L and friction level.

Usage: .venv/bin/python benchmarks/bench_fit.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from taos.identify.estimation import MeasuredResponse  # noqa: E402
from taos.identify.fit import FitProblem, _pack, _stack_points, fit_frequency_response  # noqa: E402
from taos.identify.globalstage import grid_search  # noqa: E402
from taos.identify.surrogate import PARAMETERS, solve_implicit  # noqa: E402
from taos.planar.freqresp import sine_dwell_grid  # noqa: E402
from taos.model import load_model  # noqa: E402
from taos.units import to_si  # noqa: E402

DEG = math.pi / 180
LBF_IN = to_si("1 lbf/in", "stiffness", source="", field="")
INLBF = to_si("1 in*lbf", "torque", source="", field="")
FREE = ["load_stiffness", "coulomb_torque", "bristle_stiffness", "viscous_damping"]


def make_data(truth, noise=0.005, seed=0):
    f = np.geomspace(0.3, 14.0, 20)
    rng = np.random.default_rng(seed)
    out = []
    for fs, amp in ((f[f <= 7], 0.4 * DEG), (f[f > 7], 0.8 * DEG)):
        p, e = sine_dwell_grid(truth, [amp], fs, "pitch")
        n = fs.size
        z = lambda: np.exp(noise * (rng.standard_normal(n) + 1j * rng.standard_normal(n)))  # noqa: E731
        out.append(MeasuredResponse("pitch", fs, np.full(n, amp), p[0] * truth.actuator.moment_arm_m * z(), e[0] * z(),
                                    np.ones(n), np.ones(n), np.full(n, noise), np.full(n, noise)))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    import scipy.optimize

    base = load_model(ROOT / "models" / "rs25_hotfire.toml", friction="lugre")
    law = dataclasses.replace(base.friction, static_torque_Nm=base.friction.coulomb_torque_Nm,
                              bristle_damping_Nms_per_rad=0.0, viscous_damping_Nms_per_rad=1e5)
    truth = base.replace(friction=law)
    data = make_data(truth)
    true = np.array([truth.structure.load_stiffness_N_per_m, law.coulomb_torque_Nm,
                     law.bristle_stiffness_Nm_per_rad, law.viscous_damping_Nms_per_rad])
    start_vals = np.array([150000 * LBF_IN, 100000 * INLBF, 2 * true[2], 2 * true[3]])
    start = dict(zip(FREE, start_vals))
    m0 = truth
    for n, v in start.items():
        m0 = PARAMETERS[n].set(m0, float(v))

    rows = []
    # CasADi: build once (timed), then solve (timed)
    axes, f, A, hx, he, wx, we = _stack_points(data, True, 0.5, 1e-3)
    t0 = time.perf_counter()
    prob = FitProblem(m0, tuple(FREE), axes, f, A)
    t_build = time.perf_counter() - t0
    P = _pack(hx, he, wx, we)
    ts = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        s_ca, u_ca, cost_ca = prob.solve(P, np.ones(4))
        ts.append(time.perf_counter() - t0)
    st = prob.solver.stats()
    rows.append(("CasADi + IPOPT, exact derivatives (solve)", min(ts), cost_ca, s_ca * prob.p_ref,
                 f"{st['iter_count']} iterations"))
    rows.append(("CasADi NLP build (once per model/free set/points)", t_build, math.nan, None, ""))
    t0 = time.perf_counter()
    g = grid_search(prob, hx, he, wx, we, keep=3)
    rows.append(("global first stage alone: DF grid over K_L x T_c (numpy)", time.perf_counter() - t0, g.candidate_costs[0],
                 None, f"{g.cost.size} cells, {len(g.candidates)} local minim{'um' if len(g.candidates) == 1 else 'a'}"))
    for label, glob in (("taos fit end to end, global stage + 1 IPOPT start (default since issue 29.7)", True),
                        ("taos fit end to end, local start only (before issue 29.7; peer)", False)):
        t0 = time.perf_counter()
        res_full = fit_frequency_response(m0, data, FREE, starts=1, correct=True, global_stage=glob)
        rows.append((label + ", incl. build, statistics, defect correction", time.perf_counter() - t0,
                     res_full.cost, res_full.values, f"{res_full.corrections} corrections"))
    amb = load_model(ROOT / "models" / "rs25_ambient.toml", friction="lugre")
    m_amb = PARAMETERS["coulomb_torque"].set(truth, amb.friction.coulomb_torque_Nm)
    m_amb = PARAMETERS["load_stiffness"].set(m_amb, amb.structure.load_stiffness_N_per_m)
    for label, glob in (("same, from the AMBIENT start (115,000 lbf/in, 2,185 in-lbf), global stage", True),
                        ("same, from the ambient start, local start only", False)):
        t0 = time.perf_counter()
        r = fit_frequency_response(m_amb, data, FREE, starts=1, correct=True, global_stage=glob)
        rows.append((label, time.perf_counter() - t0, r.cost, r.values,
                     f"{r.corrections} corrections, {r.adequacy().verdict}"))

    # scipy least_squares, finite differences, same residual
    lo, hi = prob.lbx[:4], prob.ubx[:4]
    nfev = [0]

    def resid(s):
        nfev[0] += 1
        u = solve_implicit(prob.sur, s)
        return np.asarray(prob.r_fn(s, u, P)).ravel()

    ts = []
    for _ in range(args.repeat):
        nfev[0] = 0
        t0 = time.perf_counter()
        ls = scipy.optimize.least_squares(resid, np.ones(4), bounds=(lo, hi), jac="2-point", x_scale="jac",
                                          xtol=1e-10, ftol=1e-10, gtol=1e-10)
        ts.append(time.perf_counter() - t0)
    rows.append(("scipy least_squares, 2-point finite differences", min(ts), ls.cost, ls.x * prob.p_ref,
                 f"{nfev[0]} residual evaluations, status {ls.status}"))

    import os
    print(f"# bench_fit: K_L + 3 LuGre parameters, {f.size} frequencies x (piston, engine), "
          f"{'2-core shared machine'}; best of {args.repeat} per solve; load average {os.getloadavg()}")
    print(f"truth: K_L {true[0] / LBF_IN:.0f} lbf/in, T_c {true[1] / INLBF:.0f} in*lbf, "
          f"sigma_0 {true[2]:.4g} N*m/rad, sigma_2 {true[3]:.4g} N*m*s/rad\n")
    print("| method | wall time [s] | cost | K_L [lbf/in] | T_c [in*lbf] | sigma_0 [N m/rad] | sigma_2 [N m s/rad] | note |")
    print("|---|---|---|---|---|---|---|---|")
    for name, t, cost, v, note in rows:
        if v is None:
            c = "-" if math.isnan(cost) else f"{cost:.5g}"
            print(f"| {name} | {t:.3f} | {c} | - | - | - | - | {note} |")
        else:
            print(f"| {name} | {t:.3f} | {cost:.5g} | {v[0] / LBF_IN:.0f} | {v[1] / INLBF:.0f} | {v[2]:.4g} | "
                  f"{v[3]:.4g} | {note} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
