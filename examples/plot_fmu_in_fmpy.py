"""
The TVC as an FMU: build it, run it in FMPy, compare with the Python block
==========================================================================

:func:`taos.cosim.build_fmu` (the ``taos fmu`` command) packs one engine's nonlinear TVC (servo,
gimbal friction, avionics, valve and pressure limits, hard stops) as an FMI 2.0 co-simulation
FMU. FMPy validates it and runs a 0.4 deg pitch step with a 0.2 deg, 2 Hz yaw sine; the same
commands through :class:`taos.cosim.TvcBlock` (the block the FMU wraps, the same compiled kernels
as ``taos simulate``) give the same engine angles, to the last bit. The FMU needs a Python with
taos importable at run time (see the user guide's FMU page).
"""

import math
import shutil
import tempfile
from pathlib import Path

import fmpy
import matplotlib.pyplot as plt
import numpy as np
from fmpy.validation import validate_fmu

import taos
from taos.cosim import TvcBlock, build_fmu

model = taos.load_model("rs25_hotfire")
workdir = Path(tempfile.mkdtemp(prefix="taos-fmu-example-"))
fmu = build_fmu(model.source, workdir / "tvc.fmu")
print(f"built {fmu.path.name}: {fmu.n_inputs} inputs, {fmu.n_outputs} outputs, {fmu.n_parameters} parameters, "
      f"internal step {fmu.dt_s} s; FMPy validation problems: {validate_fmu(str(fmu.path))}")

# %%
# Commands as an input table. FMPy sets the command of time t at the start of each step; with
# ``command_hold = 1`` the FMU ramps to it over the step (as ``taos simulate`` reads its
# samples), so its output at t + h is ``taos simulate``'s at t.
h, T = 2e-4, 1.5
t = np.arange(0.0, T + h / 2, h)
pitch = np.where(t >= 0.1, math.radians(0.4), 0.0)
yaw = math.radians(0.2) * np.sin(2 * math.pi * 2.0 * t)
inputs = np.array(list(zip(t, pitch, yaw)),
                  dtype=[("time", float), ("pitch_command_rad", float), ("yaw_command_rad", float)])
res = fmpy.simulate_fmu(str(fmu.path), stop_time=T, step_size=h, output_interval=h,
                        input=inputs, start_values={"command_hold": 1},
                        output=["pitch_engine_rad", "yaw_engine_rad", "pitch_load_pressure_Pa"])
shutil.rmtree(workdir)   # the FMU file is not needed any more

# %%
# The same commands through the Python block, each step ramping to the command FMPy set at its
# start.
block = TvcBlock(model, hold="ramp")
block.reset()
eng = np.array([[block.step(h, p, y).pitch_engine_rad, block.outputs.yaw_engine_rad]
                for p, y in zip(pitch[:-1], yaw[:-1])])
n = min(len(eng), len(res) - 1)
diff = np.degrees(np.abs(eng[:n] - np.column_stack([res["pitch_engine_rad"][1:n + 1],
                                                     res["yaw_engine_rad"][1:n + 1]])).max())
print(f"FMPy against the block over {T} s: max engine-angle difference {diff:.3g} deg")
assert diff < 1e-6

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(res["time"], np.degrees(res["pitch_engine_rad"]), label="pitch engine (FMU in FMPy)")
ax.plot(res["time"], np.degrees(res["yaw_engine_rad"]), label="yaw engine (FMU in FMPy)")
ax.plot(t[1:n + 1], np.degrees(eng[:n, 0]), "k:", label="pitch engine (TvcBlock)")
ax.set_xlabel("time [s]")
ax.set_ylabel("engine angle [deg]")
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
ax.set_title("hot-fire TVC as an FMI 2.0 FMU")
