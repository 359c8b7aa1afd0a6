"""
A flight sign-off against stated limits
=======================================

The stated (here notional) limits of ``models/specs/flight_signoff_notional.toml`` -- the
low-frequency gain margin and the phase margin of the loop with the TVC describing function, the
engine amplitude and the frequency band of any limit cycle -- checked over dispersed cases, with
the margin to each limit. ``taos lco ... --requirements FILE --signoff DIR`` does the same from
the command line and writes the JSON and the page.
"""

import math

import taos
from taos.flight.lco_map import SweepAxis
from taos.flight.signoff import load_requirements, sign_off
from taos.shipped import models_dir
from taos.units import to_si

req = load_requirements(models_dir() / "specs" / "flight_signoff_notional.toml")
ks = tuple(to_si(f"{k} lbf/in", "stiffness", source="example", field="K_L") for k in (90000, 115000, 205000))
so = sign_off(req, taos.load_flight("core_stage"), taos.load_model("rs25_flight"),
              sweep_axes=[SweepAxis("load_stiffness", ks)],
              amplitudes_rad=[math.radians(a) for a in (0.03, 0.1, 0.3)], freq_hz=[0.05, 0.08, 0.12, 0.18, 0.27, 0.4])
print(so.text())
print(so.table_text())

# %%
# The margin to each limit, case by case, as a chart.
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

names = [k.requirement for k in so.cases[0].checks]
fig, ax = plt.subplots(figsize=(8, 3.8))
w = 0.8 / len(so.cases)
for i, c in enumerate(so.cases):
    lim = [k.limit if not isinstance(k.limit, tuple) else k.limit[1] - k.limit[0] for k in c.checks]
    rel = [np.clip((k.margin if k.margin is not None else 0.0) / abs(L), -1.5, 1.5) if L else 0.0
           for k, L in zip(c.checks, lim)]
    ax.bar(np.arange(len(names)) + i * w, rel, w, label=c.label)
ax.axhline(0, color="k", lw=0.8)
ax.set_xticks(np.arange(len(names)) + 0.4 - w / 2, names, fontsize=8)
ax.set_ylabel("margin / limit [-] (< 0 fails)")
ax.legend(fontsize=7)
ax.set_title("notional flight sign-off: margin to each limit", fontsize=10)
fig.tight_layout()
