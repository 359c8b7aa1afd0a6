"""
Ambient versus hot fire
=======================

The same engine hanging (ambient) and firing (hot fire): the thrust load stiffens the load path,
so the load resonance and the piston notch move up, and the bearing friction rises with the
normal load. :func:`taos.compare_models` tabulates every parameter and derived figure side by
side; :mod:`taos.plotting.compare` overlays the two Bode families.
"""

import numpy as np

import taos
from taos.plotting.compare import plot_compare_freqresp

ambient, hotfire = taos.load_model("rs25_ambient"), taos.load_model("rs25_hotfire")
cmp = taos.compare_models(ambient, hotfire, labels=("ambient", "hot fire"))
for name in ("load_stiffness", "load_resonance_pitch_hz", "notch_frequency_pitch_hz", "breakaway_deflection_deg"):
    a, b = cmp.value(name)
    print(f"{name:28s} ambient {a:12.5g}   hot fire {b:12.5g}   ratio {b / a:.3f}")

# %%
# The linear responses of both conditions, each with its load resonance.
f = np.logspace(-1, np.log10(30), 300)
fig = plot_compare_freqresp({"ambient": [taos.linear_freqresp(ambient, f)],
                             "hot fire": [taos.linear_freqresp(hotfire, f)]},
                            resonance_hz={"ambient": ambient.load_resonance_hz(), "hot fire": hotfire.load_resonance_hz()},
                            title="ambient vs hot fire: command → piston and engine (linear)")
