"""
A friction law of one's own
===========================

A law is a frozen parameter class (fields with their model-file keys and units) plus numba
kernels, registered with :func:`taos.friction.register`; it then runs in every simulation and
analysis, here a sine dwell. The same entry, exposed by an installed package through the
entry-point group ``taos.friction_laws``, makes ``--friction NAME`` work on the command line
(README, "Adding a friction model").

The law here is viscous plus smooth Coulomb friction, T = c v + T_c v / sqrt(v^2 + v_eps^2):
with c = 0 it is the built-in ``coulomb-smooth`` law, which the dwell reproduces.
"""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import taos
from taos import friction
from taos.friction._slots import SLOT_SIGMA2, SLOT_TC, SLOT_VEPS

LAW = "viscous-coulomb-example"


@dataclass(frozen=True)
class ViscousCoulomb(friction.FrictionLaw):
    """T = c v + T_c v / sqrt(v^2 + v_eps^2) [N m]; v [rad/s]."""

    name: ClassVar[str] = LAW
    viscous_damping_Nms_per_rad: float = friction.param(0.0, "viscous_damping", "rotational_damping", SLOT_SIGMA2,
                                                        torque_like=True)
    regularization_velocity_rad_s: float = friction.param(1e-3, "regularization_velocity", "angular_velocity",
                                                          SLOT_VEPS)

    def steady_state(self, v):
        v = np.asarray(v, float)
        e = self.regularization_velocity_rad_s
        return self.viscous_damping_Nms_per_rad * v + self.coulomb_torque_Nm * v / np.sqrt(v * v + e * e)


def rates(v, z, t_app, p):
    e = p[SLOT_VEPS]
    return 0.0, p[SLOT_SIGMA2] * v + p[SLOT_TC] * v / math.sqrt(v * v + e * e)


def zdot3(w0, w1, z0, z1, p):
    return 0.0, 0.0


def torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    e = p[SLOT_VEPS]
    a = p[SLOT_SIGMA2] + p[SLOT_TC] / math.sqrt(w0 * w0 + w1 * w1 + e * e)
    return a * w0, a * w1


@njit
def _coeffs(s, p, dt, kappa):
    e = p[SLOT_VEPS]
    return p[SLOT_SIGMA2] + p[SLOT_TC] / math.sqrt(s * s + e * e), 0.0


def bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return friction.coeff_bearing_step(_coeffs, _coeffs, False, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


if LAW not in friction.ids():
    friction.register(friction.FrictionLawEntry(LAW, ViscousCoulomb, rates, zdot3, torque3, bearing))

# %%
# The hot-fire model with the new law (keeping its torque levels), against coulomb-smooth.
model = taos.load_model("rs25_hotfire")
f = np.array([1.0, 4.0])
amp = math.radians(0.2)
mine = taos.sine_dwell_freqresp(model.with_friction(LAW), f, amp)
ref = taos.sine_dwell_freqresp(model.with_friction("coulomb-smooth"), f, amp)
for k in range(f.size):
    print(f"{f[k]:.0f} Hz: engine gain {20 * np.log10(abs(mine.engine[k])):.3f} dB ({LAW}), "
          f"{20 * np.log10(abs(ref.engine[k])):.3f} dB (coulomb-smooth)")
assert np.allclose(mine.engine, ref.engine, rtol=1e-6)

# %%
# Adding viscous damping c changes the response: a law parameter like any other, and a model
# variant like any other (the model file with other values, through the loader and its bounds).
damped = model.with_values({"friction.model": LAW, "friction.viscous_damping": "2e5 N*m*s/rad"})
print("with c = 2e5 N m s/rad:", np.round(20 * np.log10(np.abs(taos.sine_dwell_freqresp(damped, f, amp).engine)), 3), "dB")
