"""
Green Run of one's own model
============================

Start from a shipped model file, change what differs on your hardware (here a softer load
path and a higher gimbal friction level, its breakaway level with it), and run the Green Run analysis on it: the verdict in
words, the figures of merit, and the Bode plot with the spec mask. A short two-axis profile
keeps it quick; ``taos.greenrun(model, out="DIR")`` (or ``taos greenrun FILE --out DIR``)
writes the full interactive report.
"""

import math
import tempfile
from pathlib import Path

import tomlkit

import taos
from taos.plotting import bode
from taos.profiles import Sequence, SineDwell, TwoAxis
from taos.shipped import models_dir

# %%
# One's own model file: a copy of the shipped hot-fire model with two values changed (its
# shared parameter sets, named relative to ``models/``, are still found from the copy).
doc = tomlkit.parse((models_dir() / "rs25_hotfire.toml").read_text())
doc["structure"]["load_stiffness"] = "180000 lbf/in"      # our load path, softer than 205000
doc["friction"]["coulomb_torque"] = "130000 in*lbf"       # our bearing, more friction
doc["friction"]["static_torque"] = "130000 in*lbf"        # breakaway at least the sliding torque
doc["name"] = "my engine (hot fire, softer load path, more friction)"
with tempfile.TemporaryDirectory() as folder:
    path = Path(folder) / "my_engine.toml"
    path.write_text(tomlkit.dumps(doc))
    model = taos.load_model(path)
print(f"{model.name}: load resonance {model.load_resonance_hz('pitch'):.2f} Hz")

# %%
# A short two-axis profile (0.4 deg dwells in pitch, one in yaw) and the analysis.
deg = math.pi / 180
profile = TwoAxis(Sequence(tuple(SineDwell(0.4 * deg, f, c) for f, c in ((1.0, 6), (2.0, 8), (4.0, 12)))),
                  SineDwell(0.4 * deg, 3.0, 10), name="short two-axis")
res = taos.greenrun(model, profile)
print(res.spec_verdict_text)
fm = res.figures_of_merit["pitch"]["engine"]
print(f"pitch engine: -3 dB at {fm['bandwidth_3db_hz']:.2f} Hz, peak {fm['peak_gain_db']:+.2f} dB "
      f"at {fm['peak_freq_hz']:.2f} Hz")

# %%
# The pitch Bode plot: the linear response, the 0.4 deg sine dwells, the load resonance.
fig = bode.plot_freqresp([res.linear["pitch"], *res.dwell["pitch"]], resonance_hz=res.load_resonance_hz["pitch"],
                         notch_hz=res.notch_hz["pitch"], title=f"pitch: {model.name}")
