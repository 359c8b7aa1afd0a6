"""
MASV: engine-to-engine coupling through the thrust structure
============================================================

Four engines, eight actuators on a modal thrust structure (``models/masv/core_stage.toml``):
the modes in the actuators' band, the strongest engine-to-engine and axis-to-axis coupling
beside the direct response, and the peak-gain matrix. With a rigid structure
(``core_stage_rigid.toml``) the eight blocks are independent simplex models: no cross-coupling.
"""

import masv
from masv.plotting import plot_coupling_matrix
from taos.shipped import models_dir

system = masv.build_system(masv.load_config(models_dir() / "masv" / "core_stage.toml"))
mp = masv.modes_in_band(system)
print(f"{system.config.structure.n_modes} modes; {mp.freq_hz.size} in {mp.band_hz[0]:.2f}-{mp.band_hz[1]:.2f} Hz")
c = masv.coupling(system, n_freq=200)
e2e = c.engine_to_engine()
print(f"strongest engine-to-engine: {e2e['command']} -> {e2e['response']} {e2e['cross_db']:.1f} dB at "
      f"{e2e['cross_hz']:.2f} Hz, {e2e['below_direct_db']:.1f} dB below the direct response")
a2a = c.strongest_axis_to_axis
print(f"strongest axis-to-axis: {a2a['command']} -> {a2a['response']} {a2a['gain_db']:.1f} dB at {a2a['freq_hz']:.2f} Hz")

# %%
# The rigid structure: the cross terms vanish (numerically).
rigid = masv.coupling(masv.build_system(masv.load_config(models_dir() / "masv" / "core_stage_rigid.toml")), n_freq=200)
print(f"rigid structure, strongest engine-to-engine: {rigid.engine_to_engine()['cross_db']:.0f} dB")

# %%
# The peak-gain matrix (command -> response) over the band.
fig = plot_coupling_matrix(c)
