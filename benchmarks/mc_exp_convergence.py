"""The Monte Carlo lanes' ETDRK4 integrator against the RK4 lockstep kernel at a fine step.

    PYTHONPATH=. python benchmarks/mc_exp_convergence.py [--runs 64] [--out DIR]

The first ``--runs`` runs of the soft case of models/montecarlo/post_separation.toml (200 s
after separation, Dahl friction, dispersed) as one in-process batch each, flown by RK4
(``integrator = "rk4"``) at 0.25 ms (the reference), 0.5 ms and 1 ms (the previous campaign
step) and by ETDRK4 (``"etdrk4"``) at 1, 2, 2.5, 4, 5 and 10 ms: every per-run output the
campaign stores (the LCO flag, command and engine amplitudes, frequency, growth, peak engine
angle, rate and attitude, the command and engine traces), the largest difference over the runs
from the reference, and each configuration's CPU seconds a run. Writes ``convergence.json`` and
``mc_exp_convergence.png`` (error against step, log-log, with the h^4 slope; one run's FCS command
difference in time) into ``--out`` and prints Markdown rows for benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time
from pathlib import Path

import numpy as np

from taos.montecarlo import load_campaign
from taos.montecarlo.executor import flight_runs, montecarlo_design

REF = ("rk4", 2.5e-4)
CONFIGS = [("rk4", 5e-4), ("rk4", 1e-3)] + [("etdrk4", h) for h in (1e-3, 2e-3, 2.5e-3, 4e-3, 5e-3, 1e-2)]
SCALARS = ("amplitude_deg", "engine_amplitude_deg", "frequency_hz", "growth", "peak_engine_deg",
           "peak_engine_rate_deg_s", "peak_attitude_deg")
TRACES = ("trace", "engine_trace")


def fly(c0, d, integrator: str, h: float) -> tuple[dict, float]:
    c = dataclasses.replace(c0, dt_s=h, integrator=integrator)
    kind, _ = flight_runs(c, "soft", None)
    kind.run_batch(d.names, d.factors[:1], d.seeds[:1])   # the kernels loaded
    t0 = time.process_time()
    out = kind.run_batch(d.names, d.factors, d.seeds)
    return out, (time.process_time() - t0) / len(d.seeds)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--runs", type=int, default=64)
    ap.add_argument("--out", default="/tmp/mc_exp_convergence")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    load0 = os.getloadavg()
    c0 = load_campaign("post_separation")
    d = montecarlo_design(c0, a.runs)
    ref, ref_cpu = fly(c0, d, *REF)
    assert np.all(ref["status"] == 1), ref["error"]
    rows = {}
    for integ, h in CONFIGS:
        got, cpu = fly(c0, d, integ, h)
        err = {k: float(np.nanmax(np.abs(np.asarray(got[k], float) - np.asarray(ref[k], float))))
               for k in SCALARS + TRACES}
        rows[f"{integ}:{h * 1e3:g}ms"] = {"integrator": integ, "h_s": h, "cpu_s_per_run": cpu, "max_abs_err": err,
                                          "lco_flips": int(np.sum(np.asarray(got["lco"]) != np.asarray(ref["lco"]))),
                                          "status_ok": int(np.sum(got["status"] == 1)),
                                          "trace0": np.asarray(got["trace"][0]).tolist()}
        print(f"{integ} {h * 1e3:g} ms: {cpu:.4f} CPU-s/run, amplitude err {err['amplitude_deg']:.2e} deg", flush=True)
    spread = {k: float(np.std(np.asarray(ref[k], float))) for k in SCALARS}
    res = {"runs": a.runs, "reference": f"rk4:{REF[1] * 1e3:g}ms", "reference_cpu_s_per_run": ref_cpu,
           "spread_over_runs": spread, "rows": rows, "load_start": load0, "load_end": os.getloadavg()}
    (out / "convergence.json").write_text(json.dumps(res, indent=1))
    _figure(res, np.asarray(ref["trace"][0]), c0, out / "mc_exp_convergence.png")
    print(f"\nload average at start {load0[0]:.1f}, at end {res['load_end'][0]:.1f}; {a.runs} runs, reference RK4 "
          f"0.25 ms ({ref_cpu:.3f} CPU-s a run)")
    print("| integrator, step | CPU-s a run | " + " | ".join(SCALARS + TRACES) + " | LCO flags changed |")
    print("|---" * (len(SCALARS + TRACES) + 3) + "|")
    for k, r in rows.items():
        e = r["max_abs_err"]
        print(f"| {k} | {r['cpu_s_per_run']:.4f} | " + " | ".join(f"{e[q]:.1e}" for q in SCALARS + TRACES)
              + f" | {r['lco_flips']} of {a.runs} |")
    print("| spread over the runs (std) | | " + " | ".join(f"{spread[q]:.2g}" for q in SCALARS) + " | | | |")


def _figure(res: dict, ref_trace: np.ndarray, c0, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.6))
    rows = res["rows"]
    for integ, mk in (("etdrk4", "o-"), ("rk4", "s--")):
        sel = [r for r in rows.values() if r["integrator"] == integ]
        h = np.array([r["h_s"] for r in sel]) * 1e3
        for k, col in (("amplitude_deg", "C0"), ("peak_engine_deg", "C1"), ("peak_engine_rate_deg_s", "C2"),
                       ("trace", "C3")):
            ax.loglog(h, [r["max_abs_err"][k] for r in sel], mk, color=col,
                      label=f"{integ}: {k}" + (" [deg/s]" if "rate" in k else " [deg]" if k != "trace" else " [rad]"))
    hh = np.array([1.0, 10.0])
    e5 = rows["etdrk4:5ms"]["max_abs_err"]["amplitude_deg"]
    ax.loglog(hh, e5 * (hh / 5.0) ** 4, "k:", label="slope h^4")
    ax.axhline(1e-4, color="grey", lw=0.8)
    ax.text(1.05, 1.2e-4, "1e-4 deg (the campaign file's accuracy claim)", fontsize=8, color="grey")
    ax.set_xlabel("step h [ms]")
    ax.set_ylabel(f"max |output - RK4 at 0.25 ms| over {res['runs']} runs")
    ax.set_title("Per-run outputs against RK4 at 0.25 ms")
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(True, which="both", alpha=0.3)
    t = c0.start_s + np.arange(ref_trace.size) * c0.trace_interval_s
    for k, col in (("etdrk4:5ms", "C0"), ("etdrk4:10ms", "C3"), ("rk4:1ms", "k")):
        bx.plot(t, np.degrees(np.asarray(rows[k]["trace0"]) - ref_trace), color=col, lw=0.8, label=k)
    bx.set_xlabel("flight time [s]")
    bx.set_ylabel("FCS command - RK4 at 0.25 ms [deg]")
    bx.set_title("Run 0: the stored command trace's difference")
    bx.legend(fontsize=8)
    bx.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
