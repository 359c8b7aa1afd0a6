"""The 3-D kernel's SO(3) log map (:func:`taos.taos3d.dynamics._logq4`: a Taylor series of
atan(t)/t below t = 0.15, atan2 above) against an independent one: scipy's rotation vector
of the same quaternion."""

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from taos.taos3d.dynamics import _logq4


@njit(cache=False)
def _log(q):
    return _logq4(q[0], q[1], q[2], q[3])


def test_log_map_matches_scipy_on_both_branches():
    rng = np.random.default_rng(28)
    # angles across the series branch (t = tan(th / 2) < 0.15: th < 0.2978 rad) and beyond it,
    # the switch itself, tiny angles and both signs of the quaternion
    th = np.concatenate([np.linspace(0.0, 1.0, 801), [1e-14, 1e-8, 0.29777, 0.29778, 0.2978, 3.0]])
    worst = 0.0
    for a in th:
        ax = rng.normal(size=3)
        ax /= np.linalg.norm(ax)
        q = np.r_[np.sin(a / 2) * ax, np.cos(a / 2)]
        for sgn in (1.0, -1.0):
            r0, r1, r2, ang = _log(sgn * q)
            ref = Rotation.from_quat(q).as_rotvec()
            worst = max(worst, np.abs(np.array([r0, r1, r2]) - ref).max() / max(a, 1e-300))
            assert abs(ang - a) <= 4e-16 * max(a, 1.0)
    assert worst < 2e-15  # measured 3.5e-16
