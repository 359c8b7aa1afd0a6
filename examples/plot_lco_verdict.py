"""
The flight limit-cycle verdict and its sensitivity
==================================================

The core-stage flight loop with the TVC's describing function (gimbal friction, bounding
avionics): is a limit cycle expected, how large, at what frequency, and how far is the loop from
the other verdict? Then the verdict over the load-path stiffness, where it flips (the paper's
soft-LCO / stiff-none result). A coarse describing-function grid keeps it quick.
"""

import math

import taos
from taos.flight.lco_map import SweepAxis, lco_map
from taos.plotting.nichols import plot_lco_nichols
from taos.units import from_si, to_si

flight = taos.load_flight("core_stage")
model = taos.load_model("rs25_flight")
grid = dict(amplitudes_rad=[math.radians(a) for a in (0.03, 0.1, 0.3)],
            freq_hz=[0.05, 0.08, 0.12, 0.18, 0.27, 0.4])
rep = taos.analyse_lco(flight, model, time_domain=False, **grid)
v = rep.verdict()
print(v.text)
print(v.table_text())

# %%
# Sensitivity: the verdict over the load stiffness (prediction only).
ks = [to_si(f"{k} lbf/in", "stiffness", source="example", field="K_L") for k in (80000, 115000, 205000)]
m = lco_map(flight, model, [SweepAxis("load_stiffness", tuple(ks))], **grid)
# Where the loop is still unstable at the grid's largest amplitude the cycle lies above it: the
# analysis extends the amplitudes (a few rows, :func:`taos.flight.lco.extend_to_cover`) and flags a
# point it still cannot settle (``grid_may_miss_cycle``) instead of stating a margin there.
for k, lco, a, mg, miss in zip(ks, m.lco, m.engine_amplitude_deg, m.margin_db, m.grid_may_miss_cycle):
    print(f"K_L = {from_si(k, 'N/m', 'lbf/in'):7.0f} lbf/in: "
          + (f"LCO, engine {a:.3f} deg" if lco else f"no LCO, margin {mg:.2f} dB")
          + (" (WARNING: a cycle may lie outside the map)" if miss else ""))
for flip in m.flips():
    lo, hi = (from_si(x, "N/m", "lbf/in") for x in flip["between"])
    print(f"the verdict flips between {lo:.0f} and {hi:.0f} lbf/in")

# %%
# The Nichols chart of the nominal case.
fig = plot_lco_nichols(rep.prediction)
