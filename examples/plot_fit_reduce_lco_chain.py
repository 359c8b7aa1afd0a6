"""
From Green Run records to the flight verdict: one chain
=======================================================

The paper's sec. 4 in one script: the ambient and hot-fire records are fitted with the 3-D TAOS
model (each condition with its own FEM gimbal pair), the two fits compared (the load-stiffness
shift and the part of it the FEM does not explain), the hot-fire fit reduced to the planar
simplex model the flight loop runs (the planar-equivalent friction), and the flight limit-cycle
verdict taken on that reduced model with its margin and its sensitivity to the load stiffness.

The "records" are made here by the 3-D model itself from known load stiffnesses (short two-axis
dwells with sensor noise), so the chain is checked end to end: the fits must give the truth
back. Short records, one free parameter per fit and coarse grids keep it quick; the guide page
"One chain" runs the same steps with the command line and full settings.
"""

import dataclasses
import math
import time

import matplotlib.pyplot as plt
import numpy as np

import taos
from taos.flight.lco_map import SweepAxis, lco_map
from taos.identify.compare3d import compare_taos
from taos.identify.data import from_time_history
from taos.identify.reduce import reduce_to_planar
from taos.profiles import Sequence, SineDwell, TwoAxis
from taos.taos3d import simulate_taos, taos_model, with_values

t_start = time.perf_counter()
deg, LBF_IN = math.pi / 180, 175.12683524647636   # rad per deg, N/m per lbf/in
start = {"ambient": taos_model(taos.load_model("rs25_ambient")),   # 3-D models: FEM gimbal hanging / thrust-loaded
         "hot fire": taos_model(taos.load_model("rs25_hotfire"))}
true_kl = {"ambient": 125000.0, "hot fire": 190000.0}              # lbf/in, the "hardware" behind the records

# %%
# The records: pitch and yaw 0.4 deg dwells at the same time (the Green Run practice), 4 s,
# engine and piston sampled at 250 Hz with sensor noise, from the 3-D model at the true K_L.
profile = TwoAxis(Sequence((SineDwell(0.4 * deg, 2.0, 4), SineDwell(0.4 * deg, 6.0, 12))),
                  Sequence((SineDwell(0.4 * deg, 3.0, 6), SineDwell(0.4 * deg, 8.0, 16))), "two-axis dwells")
rng = np.random.default_rng(7)
records = {}
for cond, tm in start.items():
    truth = with_values(tm, {"structure.load_stiffness": true_kl[cond] * LBF_IN})
    d = from_time_history(simulate_taos(truth, profile, dt_s=4e-4, record_every=10), condition=cond)
    records[cond] = dataclasses.replace(d, engine_rad=d.engine_rad + 0.004 * deg * rng.standard_normal(d.engine_rad.shape),
                                       piston_m=d.piston_m + 0.001 * 0.0254 * rng.standard_normal(d.piston_m.shape),
                                       load_pressure_Pa=None, spool_flow_m_s=None, supply_pressure_Pa=None)

# %%
# 3-D fits and the comparison (``taos compare --engine taos``): K_L of each condition, its
# standard error, and the shift between them split into the FEM gimbal pair's part and the
# rest (the line stiffness shift the FEM does not explain).
cmp = compare_taos([start["ambient"], start["hot fire"]], [[records["ambient"]], [records["hot fire"]]],
                   [["load_stiffness"], ["load_stiffness"]], global_stage=False, max_nfev=8)
for cond, k, se in zip(cmp.labels, cmp.total_N_per_m, cmp.total_se_N_per_m):
    print(f"{cond}: fitted K_L {k / LBF_IN:,.0f} +- {se / LBF_IN:,.0f} lbf/in (true {true_kl[cond]:,.0f}), "
          f"fitted / true = {k / LBF_IN / true_kl[cond]:.4f}")
st, sl = cmp.shift_total, cmp.shift_line
print(f"K_L shift ambient -> hot fire {st[0] / LBF_IN:+,.0f} +- {st[1] / LBF_IN:,.0f} lbf/in; "
      f"not explained by the FEM gimbal pair {sl[0] / LBF_IN:+,.0f} +- {sl[1] / LBF_IN:,.0f} lbf/in")

# %%
# Reduce the hot-fire fit to the planar model (``taos reduce``): planar friction fitted to the
# 3-D model's low-frequency engine dwells, refined to the worst point, checked on a grid
# between the fit points (here 3 x 3, both axes; the command's default is 9 x 9).
hot_fit = cmp.fits[1].taos
red = reduce_to_planar(hot_fit, freq_hz=(0.1, 0.5, 2.0), amplitudes_deg=(0.02, 0.1, 0.5),
                       check_freq_hz=(0.15, 0.7, 1.5), check_amplitudes_deg=(0.03, 0.07, 0.3),
                       greenrun_freq_hz=(1.0, 4.0), max_nfev=15, refine_nfev=15)
for line in red.summary_lines():
    print(line)
print("reduction within tolerance:", red.within_tolerance)

# %%
# The flight verdict on the reduced model (``taos lco PLANAR.toml --flight core_stage``) and
# its sensitivity to the load stiffness (``--sweep load_stiffness=...``): a softer structure
# than any fit, the paper's ambient 115,000 lbf/in, this chain's hot-fire fit and the paper's
# hot-fire 205,000 lbf/in. The friction is the hot-fire test's (sea-level thrust on the bearing);
# the flight bounding model (``rs25_flight``) carries the larger flight friction.
flight = taos.load_flight("core_stage")
grid = {"amplitudes_rad": [a * deg for a in (0.03, 0.1, 0.3)], "freq_hz": [0.05, 0.08, 0.12, 0.18, 0.27, 0.4]}
v = taos.analyse_lco(flight, red.model, time_domain=False, **grid).verdict()
print(v.text)
ks = [60000.0 * LBF_IN, 115000.0 * LBF_IN, red.model.structure.load_stiffness_N_per_m, 205000.0 * LBF_IN]
m = lco_map(flight, red.model, [SweepAxis("load_stiffness", tuple(ks))], **grid)
for k, lco, a, mg in zip(ks, m.lco, m.engine_amplitude_deg, m.margin_db):
    print(f"K_L = {k / LBF_IN:7,.0f} lbf/in: " + (f"LCO, engine {a:.3f} deg" if lco else f"no LCO, margin {mg:.2f} dB"))
print(f"chain run time {time.perf_counter() - t_start:.0f} s")

# %%
# One figure: the reduction (3-D vs reduced planar engine gain on the check grid) and the
# flight verdict over K_L.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
c = red.check
for f in np.unique(c.freq_hz):
    sel = (c.freq_hz == f) & (np.asarray(c.axis) == "pitch")
    line, = ax1.semilogx(c.amplitude_deg[sel], 20 * np.log10(np.abs(c.target[sel])), "o-", label=f"3-D, {f:g} Hz")
    ax1.semilogx(c.amplitude_deg[sel], 20 * np.log10(np.abs(c.planar[sel])), "x--", color=line.get_color(),
                 label=f"reduced planar, {f:g} Hz")
ax1.set(xlabel="command amplitude [deg]", ylabel="engine / command gain [dB]", title="reduction (pitch)")
ax1.legend(fontsize=7)
kl = np.array(ks) / LBF_IN
ax2.plot(kl, [a if lco else 0.0 for lco, a in zip(m.lco, m.engine_amplitude_deg)], "s-")
ax2.set(xlabel="load stiffness K_L [lbf/in]", ylabel="predicted LCO engine amplitude [deg] (0: none)",
        title="flight verdict on the reduced model")
fig.tight_layout()
