"""The step of an exponential (ETDRK4) sine dwell, chosen by the physics that needs it.

With the linear block advanced exactly (:mod:`taos.planar._expstep`) the valve and the oil
column no longer bound the step. What does is the part integrated explicitly, the friction loop
and the limits, and the measurement:

* **Friction loop.** Linearised about the dwell's orbit, the friction adds to the linear block
  N_x = b_f (T_w w' + T_a T_a' + T_z z') and z' = g_w w' + g_a T_a' + g_z z' (partial derivatives
  of the law's kernel ``rates``). Its nonzero rates are the eigenvalues of the 2 x 2 matrix::

      M = [[T_w (c_w . b_f) + T_a (c_a . b_f),  T_z],
           [g_w (c_w . b_f) + g_a (c_a . b_f),  g_z]]

  (the rank-2 Jacobian U V^T has the spectrum of V^T U). For the planar engine c_w . b_f =
  -1 / J: the stuck bristle's spring sqrt(sigma_0 / J) [rad/s], the bristle damping
  sigma_1 / J [1/s] and, sliding at rate w, the bristle relaxation sigma_0 |w| / G(w) [1/s]
  (Dahl, LuGre). They are taken at 64 points of the second cycle of the friction law driven by
  the linear orbit's rate (:func:`taos.friction._kernels.prescribed_rate_response`, an upper
  bound: friction only slows the engine) and at its rate reversals (w = 0, where a regularised
  law is stiffest: a smooth Coulomb law's slope T_c / v_eps), and the step is
  h <= :data:`KAPPA` / max |lambda(M)|.
* **Limits.** The supply-pressure law adds the rate |dN_P / dP_L| = (4 beta / V_t) |q|
  g'(d) / P_s on the load-pressure state (largest along the orbit); the step keeps h times it
  within :data:`KAPPA` too. A dwell whose linear orbit reaches the valve's rate limit or the
  hard stops keeps the fixed-step default :data:`taos.planar.simulate.DEFAULT_DT_S` (the
  clipped valve loop, the contact stiffness and their switching are then the fast physics).
* **Measurement.** At least ``min_steps_per_cycle`` steps a cycle (a multiple of 4: the
  command is monotone within a step) and at most :data:`H_MAX_S`: 100 samples a second put
  20 or more on a period of the load mode (4-7 Hz), and the harmonics that could alias onto
  the fundamental (orders n_per_cycle +- 1, at 1 / h and above) lie beyond the actuator's
  roll-off.

:data:`KAPPA` is set by the step-refinement study of ``tests/test_expstep.py`` (ETDRK4's error
falls as h^4 until h |lambda(M)| ~ 1).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _expcoef as _xc
from . import _expstep as _ex
from ._expcoef import (  # noqa: F401  (the step plan, numba-free; re-exported here)
    H_MAX_S, JUMP_RATIO, KAPPA, N_ORBIT, limits_rate, orbit, steps_per_cycle)


@njit(cache=True)
def _law_at(fid, fp, w, z, ta, k, h):
    """The law's (dz/dt, T_f) with variable ``k`` (0: w, 1: z, 2: t_app) shifted by ``h``."""
    if k == 0:
        return fid(w + h, z, ta, fp)
    if k == 1:
        return fid(w, z + h, ta, fp)
    return fid(w, z, ta + h, fp)


@njit(cache=True)
def _jumps(a0, ah, a1):
    """Whether a change a0 -> a1 over a stencil side, ah its value at the side's middle, is a
    jump: one half of the side changes more than JUMP_RATIO times the other (a continuous law
    changes alike over both halves of a stencil this small; a kink into a flat part is flagged
    too, harmlessly: the other side's quotient is then that regime's own rate)."""
    d1, d2 = abs(ah - a0), abs(a1 - ah)
    return max(d1, d2) > JUMP_RATIO * min(d1, d2) and max(d1, d2) > 1e-12 * (abs(a0) + abs(a1))


@njit(cache=True)
def _quotients(fid, fp, w, z, ta, k, d):
    """(dT_f/dx, d(dz/dt)/dx) along variable ``k`` (:func:`_law_at`) with step ``d``: central
    quotients, or, where one side of the stencil holds a jump of the law (:func:`_jumps`: the
    switching law's step at the edge of its stick band), the other side's one-sided quotients.
    A jump is no rate: the law's own explicit-step rule covers it
    (:meth:`taos.friction.FrictionLaw.check_step`)."""
    g0, t0 = _law_at(fid, fp, w, z, ta, k, 0.0)
    gp, tp = _law_at(fid, fp, w, z, ta, k, d)
    gm, tm = _law_at(fid, fp, w, z, ta, k, -d)
    gph, tph = _law_at(fid, fp, w, z, ta, k, 0.5 * d)
    gmh, tmh = _law_at(fid, fp, w, z, ta, k, -0.5 * d)
    jp = _jumps(t0, tph, tp) or _jumps(g0, gph, gp)
    jm = _jumps(t0, tmh, tm) or _jumps(g0, gmh, gm)
    if jp and not jm:
        return (t0 - tm) / d, (g0 - gm) / d
    if jm and not jp:
        return (tp - t0) / d, (gp - g0) / d
    return (tp - tm) / (2 * d), (gp - gm) / (2 * d)


@njit(cache=True)
def _friction_rate(fid, fp, w, ta, z, cwbf, cabf):
    """max |lambda(M)| [1/s] (module docstring) over the samples ``w`` [rad/s], ``ta`` [N m],
    ``z`` [rad] (equal lengths); ``cwbf``, ``cabf`` the products c_w . b_f, c_a . b_f. The
    partial derivatives are central quotients except at a jump of the law (:func:`_quotients`)."""
    rho = 0.0
    for k in range(w.shape[0]):
        dw = max(1e-7, 1e-5 * abs(w[k]))
        dz = max(1e-12, 1e-5 * abs(z[k]))
        da = max(1e-3, 1e-5 * abs(ta[k]))
        Tw, gw = _quotients(fid, fp, w[k], z[k], ta[k], int(0), dw)
        Tz, gz = _quotients(fid, fp, w[k], z[k], ta[k], int(1), dz)
        Ta, ga = _quotients(fid, fp, w[k], z[k], ta[k], int(2), da)
        m11 = Tw * cwbf + Ta * cabf
        m21 = gw * cwbf + ga * cabf
        tr = m11 + gz
        det = m11 * gz - Tz * m21
        disc = 0.25 * tr * tr - det
        if disc >= 0:
            lam = abs(0.5 * tr) + math.sqrt(disc)
        else:
            lam = math.sqrt(det)   # complex pair: |lambda|^2 = det
        if math.isfinite(lam):
            rho = max(rho, lam)
    return rho


class _NumbaKernels:
    """The dwell kernel set (:class:`taos.planar._expcoef.KernelSet`) of numba's compiled
    kernels: the reference, and the fallback of the C path (:mod:`taos.planar._cdwell`)."""

    name = "numba"
    provenance = {"kernels": "numba"}

    @staticmethod
    def expm(W):
        return _ex.expm_small(W)

    @staticmethod
    def law(model):
        return model.friction.entry.rates

    @staticmethod
    def rate_response_z(fid, fp, v, dt, z0):
        from ..friction._kernels import prescribed_rate_response

        return prescribed_rate_response(fid, fp, v, dt, z0)[1]

    @staticmethod
    def friction_rate(fid, fp, w, ta, z, cwbf, cabf):
        return _friction_rate(fid, fp, w, ta, z, cwbf, cabf)

    @staticmethod
    def dwell_batch(*args):
        _ex.dwell_batch(*args)


#: numba's dwell kernels
NUMBA = _NumbaKernels()


def dwell_step_s(args, model, amp: float, freq: float, fixed_dt_s: float) -> tuple[float, str]:
    """:func:`taos.planar._expcoef.dwell_step_s` by numba's kernels."""
    return _xc.dwell_step_s(args, model, amp, freq, fixed_dt_s, NUMBA)


def step_tables(A: np.ndarray, bc: np.ndarray, dts: np.ndarray):
    """:func:`taos.planar._expcoef.step_tables` by numba's kernels."""
    return _xc.step_tables(A, bc, dts, NUMBA.expm)


def run_dwells(args, Cy, kern, amps, freqs, npc, n_settle, n_meas, out, status):
    """:func:`taos.planar._expcoef.run_dwells` by numba's kernels."""
    _xc.run_dwells(args, Cy, kern, amps, freqs, npc, n_settle, n_meas, out, status, NUMBA)


def exp_steps_per_cycle(args, model, inertia_kgm2: float, amps, freqs, fixed_dt_s: float,
                        min_steps_per_cycle: int) -> np.ndarray:
    """:func:`taos.planar._expcoef.exp_steps_per_cycle` by numba's kernels."""
    return _xc.exp_steps_per_cycle(args, model, inertia_kgm2, amps, freqs, fixed_dt_s, min_steps_per_cycle, NUMBA)
