"""Packed friction-parameter slots (no numba here: model loading and ``taos info`` use them
without compiling any kernel). The kernels (:mod:`._kernels`) read the packed vector by these
indices."""

# Packed parameter slots (SI units).
SLOT_TC = 0        # Coulomb (dynamic) torque T_c [N m]
SLOT_TS = 1        # static (breakaway) torque T_s [N m]
SLOT_VS = 2        # Stribeck velocity v_s [rad/s]
SLOT_DELTA = 3     # Stribeck exponent delta [-]
SLOT_SIGMA0 = 4    # bristle stiffness sigma_0 [N m/rad]
SLOT_SIGMA1 = 5    # bristle damping sigma_1 [N m s/rad]
SLOT_SIGMA2 = 6    # viscous damping sigma_2 [N m s/rad]
SLOT_VD = 7        # vibration velocity amplitude V_d [rad/s]
SLOT_VEPS = 8      # stick band (switching) or regularisation velocity (smooth) [rad/s]
SLOT_ALPHA = 9     # Dahl exponent alpha [-]
SLOT_V1 = 10       # bristle-damping decay velocity v_1 [rad/s] (0: constant sigma_1)
SLOT_CSTICK = 11   # stick damping c_stick [N m s/rad] (switching law)
NPARAM = 12
