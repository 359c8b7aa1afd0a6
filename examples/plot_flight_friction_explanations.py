"""
Why flight friction exceeded the Green Run's
============================================

The seed paper (sec. 5) offers three explanations for flight friction above the Green Run's:
cross-axis dither present on the stand and absent in quiescent flight, the test stand's vibration
against flight's, and sea-level against flight thrust. Each is the flight TVC model with only that
difference (``taos.flight.friction_study``), measured by the low-frequency engine gain (sine dwell
at 0.15 Hz, 0.05 deg) and the flight loop's LCO margin (describing function, coarse grid). The
vibration and dither levels are notional; the thrusts are the model files'.
"""

import matplotlib.pyplot as plt

import taos
from taos.flight.friction_study import friction_explanations

res = friction_explanations(taos.load_flight("core_stage"), taos.load_model("rs25_flight"))


def fmt(x, unit=" dB"):
    return "LCO" if x is None else f"{x:+.2f}{unit}"


for e in res.explanations:
    print(f"{e.name}: Green Run ({e.green_run}) -> flight ({e.flight})")
    print(f"  low-frequency engine gain {e.gain_db[0]:+.2f} -> {e.gain_db[1]:+.2f} dB "
          f"(change {e.gain_change_db:+.2f} dB)")
    print(f"  LCO margin {fmt(e.margin_db[0])} -> {fmt(e.margin_db[1])}"
          + "".join(f"; LCO engine amplitude {a:.3f} deg ({w})" for a, w in zip(e.engine_amplitude_deg,
                                                                                ("Green Run", "flight")) if a))

# %%
# The gain change of each explanation.
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.barh([e.name for e in res.explanations], [e.gain_change_db for e in res.explanations], color="tab:red")
ax.set_xlabel("low-frequency engine gain, flight minus Green Run [dB]")
ax.grid(True, alpha=0.3)
fig.tight_layout()
