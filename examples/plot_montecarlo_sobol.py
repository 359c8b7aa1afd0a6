"""
A Monte Carlo with Sobol' indices
=================================

Which of three uncertain TVC values drives the servo's figures of merit? The load-path
stiffness K_L, the piston area A and the servo loop gain K_v of the ambient Green Run model are
each spread uniformly over a range; Saltelli's design (N (k + 2) model variants for N base
samples) is run through the Monte Carlo engine, each variant built and checked by the model
loader as if its file held those values; SALib estimates the first-order (S1) and total (ST)
Sobol' indices with bootstrap confidence intervals.

The command line does the same::

    taos sweep models/rs25_ambient.toml --sensitivity sobol --samples 32 \\
        --set "structure.load_stiffness=100000 lbf/in:130000 lbf/in" \\
        --set "actuator.piston_area=13.5 in**2:16.5 in**2" --set "actuator.loop_gain=16 1/s:24 1/s" \\
        --metric load_resonance_hz,engine_peaking_db,phase_margin_deg --json sobol.json

(and ``taos montecarlo CAMPAIGN --sensitivity sobol`` for the flight limit cycle's dispersions,
docs/guide/montecarlo.md). A check with a known answer: the load resonance
w_L = sqrt((K_L R^2 + K_n)/J) (seed paper eq. 1) does not depend on A or K_v, so K_L must carry
all of its variance (S1 = ST = 1, the others 0).
"""

import matplotlib.pyplot as plt
import numpy as np

from taos.montecarlo import SweepDefinition, make_design, parse_set, run_sweep
from taos.shipped import resolve

ranges = ["structure.load_stiffness=100000 lbf/in:130000 lbf/in",
          "actuator.piston_area=13.5 in**2:16.5 in**2",
          "actuator.loop_gain=16 1/s:24 1/s"]
design = make_design([parse_set(r) for r in ranges], samples=32, seed=1, sensitivity="sobol")
metrics = ("load_resonance_hz", "engine_peaking_db", "phase_margin_deg")
definition = SweepDefinition(str(resolve("rs25_ambient", "model")), design, metrics)
result = run_sweep(definition, workers=1)   # in this process; workers=K: a local Dask cluster
print(f"{design.n} model variants ({design.design} design), "
      f"{int(np.sum(result.status == 1))} computed")

# %%
# The indices, strongest first, with their 95 % bootstrap half-widths.
sens = {m: result.sensitivity(m)["indices"] for m in metrics}
for m, rows in sens.items():
    print(m)
    for r in rows:
        print(f"  {r['parameter']:<26s} S1 {r['S1']:5.2f} +- {r['S1_conf']:.2f}   "
              f"ST {r['ST']:5.2f} +- {r['ST_conf']:.2f}")

wl = {r["parameter"]: r for r in sens["load_resonance_hz"]}
others = max(wl[k]["ST"] for k in wl if k != "structure.load_stiffness")
print(f"load resonance: ST of the load stiffness {wl['structure.load_stiffness']['ST']:.2f}, "
      f"of the others at most {others:.3f} (analytic: 1 and 0)")

# %%
# S1 and ST per metric: bars with their confidence intervals.
names = [k.key for k in design.keys]
fig, axs = plt.subplots(1, len(metrics), figsize=(12, 3.6), sharey=True)
for ax, m in zip(axs, metrics):
    by = {r["parameter"]: r for r in sens[m]}
    x = np.arange(len(names))
    for off, idx, col in ((-0.18, "S1", "C0"), (0.18, "ST", "C1")):
        ax.bar(x + off, [by[n][idx] for n in names], 0.36, yerr=[by[n][idx + "_conf"] for n in names],
               color=col, label=idx, capsize=3)
    ax.set_xticks(x, [n.split(".")[1] for n in names], rotation=20)
    ax.set_title(m, fontsize=10)
    ax.axhline(0, color="k", lw=0.5)
axs[0].set_ylabel("Sobol' index")
axs[0].legend()
fig.suptitle(f"Sobol' indices of the servo figures, ambient model ({design.n} variants)", fontsize=10)
fig.tight_layout()
