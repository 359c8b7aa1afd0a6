"""
python-control interop: the TVC model in one's own loop
=======================================================

:func:`taos.to_control` turns the planar simplex model into a ``control.StateSpace`` (signal
names kept). Here the engine-angle response to the command is put into a simple rigid-vehicle
attitude loop designed with python-control, its margins computed by python-control and by
:func:`taos.loop_margins` (every crossing), and the closed loop's step response drawn.
"""

import control
import matplotlib.pyplot as plt
import numpy as np

import taos
from taos.planar.simplex import simplex_state_space

model = taos.load_model("rs25_flight")
tvc = taos.to_control(simplex_state_space(model, "pitch"))
G = tvc[tvc.output_labels.index("theta_rad"), tvc.input_labels.index("command_rad")]
print(f"TVC states {G.nstates}, DC gain {float(np.real(G.dcgain())):.4f}")

# %%
# A notional rigid vehicle (attitude per engine deflection a / s^2 with a = 2 1/s^2) with a PD
# attitude controller; the loop is broken at the TVC command.
vehicle = control.tf([2.0], [1, 0, 0])
pd = control.tf([1.2, 1.0], [0.05, 1])
L = control.series(G, vehicle, pd)
gm, pm, wcg, wcp = control.margin(L)
print(f"python-control: gain margin {20 * np.log10(gm):.2f} dB, phase margin {pm:.1f} deg at {wcp / 2 / np.pi:.3f} Hz")
f = np.logspace(-2, 1.5, 4000)
lm = taos.loop_margins(f, np.asarray(L(2j * np.pi * f)))
print(f"taos.loop_margins: phase margin {lm.min_phase_margin[0]:.1f} deg at {lm.min_phase_margin[1]:.3f} Hz")
assert abs(lm.min_phase_margin[0] - pm) < 0.5

# %%
# The closed attitude loop's step response.
T = control.feedback(L, 1)
t, y = control.step_response(T, np.linspace(0, 8, 2000))
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(t, y)
ax.set_xlabel("time [s]")
ax.set_ylabel("attitude / command [-]")
ax.grid(True, alpha=0.3)
ax.set_title("closed attitude loop with the TVC model, unit step")
