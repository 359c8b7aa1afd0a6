"""The 3-D kernels' small geometry: SO(3) maps on scalar locals and tuples (no heap arrays).

Every function here is small and compiled inline (``inline="always"``, the same fast-math
flags ``_FM``) into the few kernels that use it, each of which is compiled once: the
right-hand side, the torque kick and the step of :mod:`taos.taos3d.dynamics` (numba's inlining
re-types the callee inside each caller, cheap for these; the big kernels call each other):

* :func:`_logq4` / :func:`_logq`: the rotation vector r = log3(R) [rad] of a unit quaternion (xyzw),
  with a Taylor series of atan(t) / t below 17 deg (no ``atan2`` call);
* :func:`_rotation`, :func:`_rv`, :func:`_rtv`: the rotation matrix R (body -> world) as a
  row-major 9-tuple, R a and R^T a;
* :func:`_row6`, :func:`_mv6`, :func:`_cross3`: 6 x 6 matrix-vector products and the 3-vector cross
  product on scalars;
* :func:`_world_torque`: the world torque Jl(r)^-T g [N m] of a generalized torque g conjugate to
  the rotation vector r (Jl the SO(3) left Jacobian).
"""

from __future__ import annotations

import math

from numba import njit

#: the fast-math flags of every 3-D kernel (no ``nnan``/``ninf``: the step's finiteness check
#: must see a NaN)
_FM = {"reassoc", "contract", "arcp", "nsz"}


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _logq(q, r):
    """Rotation vector of the unit quaternion q (xyzw) into r; returns the angle."""
    r0, r1, r2, th = _logq4(q[0], q[1], q[2], q[3])
    r[0] = r0
    r[1] = r1
    r[2] = r2
    return th


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _logq4(qx, qy, qz, qw):
    """Rotation vector (r0, r1, r2) [rad] and angle [rad] of the unit quaternion (xyzw):
    a = 2 atan2(n, |w|), r = a q_xyz / n sgn(w) (n = |q_xyz|). Below t = n / |w| = 0.15 (angles
    below 17 deg, the gimbal's range) atan(t) / t is its Taylor series to t^22 (the next term,
    t^24 / 25, is below 1.1e-18 there): no call to atan2, whose call makes the compiled
    right-hand side spill every live register."""
    s = 1.0 if qw >= 0 else -1.0
    n = math.sqrt(qx * qx + qy * qy + qz * qz)
    aw = abs(qw)
    if n < 0.15 * aw:
        t = n / aw
        t2 = t * t
        at = 1.0 + t2 * (-1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (-1.0 / 7.0 + t2 * (1.0 / 9.0 + t2 * (
            -1.0 / 11.0 + t2 * (1.0 / 13.0 + t2 * (-1.0 / 15.0 + t2 * (1.0 / 17.0 + t2 * (
                -1.0 / 19.0 + t2 * (1.0 / 21.0 + t2 * (-1.0 / 23.0)))))))))))  # atan(t) / t
        f = 2.0 * at / aw * s
        return f * qx, f * qy, f * qz, f * s * n
    a = 2.0 * math.atan2(n, aw)
    f = a / n * s
    return f * qx, f * qy, f * qz, a


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _row6(M, i, a0, a1, a2, a3, a4, a5):
    return M[i, 0] * a0 + M[i, 1] * a1 + M[i, 2] * a2 + M[i, 3] * a3 + M[i, 4] * a4 + M[i, 5] * a5


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _mv6(M, a0, a1, a2, a3, a4, a5):
    """M (6, 6) times the vector (a0..a5), as a tuple (scalar locals: no heap arrays)."""
    return (_row6(M, 0, a0, a1, a2, a3, a4, a5), _row6(M, 1, a0, a1, a2, a3, a4, a5),
            _row6(M, 2, a0, a1, a2, a3, a4, a5), _row6(M, 3, a0, a1, a2, a3, a4, a5),
            _row6(M, 4, a0, a1, a2, a3, a4, a5), _row6(M, 5, a0, a1, a2, a3, a4, a5))


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _cross3(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rotation(qx, qy, qz, qw):
    """Rotation matrix R (body -> world) of the unit quaternion (xyzw), row-major 9-tuple."""
    return (1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw),
            2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw),
            2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy))


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rv(R, a0, a1, a2):
    """R a for R the row-major 9-tuple of :func:`_rotation` (body -> world)."""
    return (R[0] * a0 + R[1] * a1 + R[2] * a2, R[3] * a0 + R[4] * a1 + R[5] * a2,
            R[6] * a0 + R[7] * a1 + R[8] * a2)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _rtv(R, a0, a1, a2):
    """R^T a for R the row-major 9-tuple of :func:`_rotation` (world -> body)."""
    return (R[0] * a0 + R[3] * a1 + R[6] * a2, R[1] * a0 + R[4] * a1 + R[7] * a2,
            R[2] * a0 + R[5] * a1 + R[8] * a2)


@njit(cache=True, fastmath=_FM, error_model="numpy", inline="always")
def _world_torque(r0, r1, r2, th, g0, g1, g2):
    """World torque Jl(r)^-T g [N m] of the generalized torque g conjugate to the rotation
    vector r [rad] (angle th [rad]): g + r x g / 2 + c r x (r x g),
    c = 1/th^2 - (1 + cos th) / (2 th sin th) = 1/th^2 - cot(th/2) / (2 th); below 0.3 rad its
    Taylor series 1/12 + th^2/720 + th^4/30240 + th^6/1209600 + th^8/47900160 (the next term,
    5.3e-10 th^10, is below 4e-14 of c there)."""
    if th < 0.3:
        t2 = th * th
        c = 1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 * (1.0 / 47900160.0))))
    else:
        c = 1.0 / (th * th) - (1.0 + math.cos(th)) / (2.0 * th * math.sin(th))
    rg0, rg1, rg2 = _cross3(r0, r1, r2, g0, g1, g2)
    rrg0, rrg1, rrg2 = _cross3(r0, r1, r2, rg0, rg1, rg2)
    return g0 + 0.5 * rg0 + c * rrg0, g1 + 0.5 * rg1 + c * rrg1, g2 + 0.5 * rg2 + c * rrg2
