"""
Fitting one's own record
========================

A test record (here made by simulation, standing in for a measured one: a hot-fire model whose
load path is 15 % softer than the model file says) is read as a test engineer's record would be,
its frequency response estimated from its dwells, and the load stiffness and friction level
fitted from the model file's values, with standard errors and the adequacy verdict.
"""

import math

import taos
from taos.identify.data import from_time_history
from taos.profiles import Sequence, SineDwell

deg = math.pi / 180
model = taos.load_model("rs25_hotfire")
truth = model.with_values({"structure.load_stiffness": 0.85 * model.structure.load_stiffness_N_per_m})  # a variant, SI

# %%
# The "record": 0.4 deg dwells in pitch at five frequencies around the load resonance.
profile = Sequence(tuple(SineDwell(0.4 * deg, f, n) for f, n in ((1.0, 6), (3.0, 12), (5.0, 16), (7.0, 20), (10.0, 25))))
record = from_time_history(taos.simulate(truth, profile), condition="stand-in record")

# %%
# Estimate: the estimator says what excitation it found and why.
responses = taos.estimate(record)
for r in responses:
    print(r.axis, r.method, r.meta["excitation"]["reason"])

# %%
# Fit the load stiffness and the Coulomb level, starting from the model file's values.
fit = taos.fit_frequency_response(model, responses, ["load_stiffness", "coulomb_torque"], starts=1)
print(fit.table())
k = fit.values[fit.names.index("load_stiffness")]
print(f"fitted K_L / true K_L = {k / truth.structure.load_stiffness_N_per_m:.4f}")
assert abs(k / truth.structure.load_stiffness_N_per_m - 1) < 0.02
