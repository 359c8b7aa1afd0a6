"""Compiled fixed-step integrator for Lur'e plants (linear block + friction + avionics).

State equations (see :class:`taos.planar.simplex.LurePlant`)::

    c   = cc . x + dc . r(t)                 pre-avionics command [rad]
    u   = avionics(c)                        post-avionics command [rad]
    w   = cw . x,  T_a = ca . x              friction relative rate [rad/s], applied torque [N m]
    (z', T_f) = friction.rates(w, z, T_a)    the law's kernel (registry entry)
    x'  = A x + Br r(t) + bc u + bf T_f  (+ the actuator/gimbal limit corrections of
                                          :mod:`taos.planar.saturation`, packed in ``lim``)

Classical fourth-order Runge-Kutta with a fixed step; the external input is evaluated at the
stage times (linear interpolation of samples, or exactly for sines). The friction kernels
come from the law's registry entry (:mod:`taos.friction.registry`): ``fid`` is its
``rates(w, z, T_a, p) -> (z', T_f)``, a compiled C callback passed as a first-class
function, so one compiled integrator serves every law, including laws registered at run
time. The avionics kernel is the single definition in :mod:`taos.planar.avionics`. A non-finite
state stops the run and reports the step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from . import _avionics_kernels as _av
from . import saturation as _lim

# reassociation and FMA contraction only: no-NaN/no-Inf flags would remove the stability checks
_FM = {"reassoc", "contract", "arcp", "nsz"}


@njit(cache=True, fastmath=_FM, inline="always")
def _rates(x, z, r, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, dx):
    n = x.shape[0]
    nr = r.shape[0]
    c = 0.0
    w = 0.0
    ta = 0.0
    for i in range(n):
        c += cc[i] * x[i]
        w += cw[i] * x[i]
        ta += ca[i] * x[i]
    for j in range(nr):
        c += dc[j] * r[j]
    u = _av.apply(c, avp)
    dz, tf = fid(w, z, ta, fp)
    for i in range(n):
        s = bc[i] * u + bf[i] * tf
        for j in range(n):
            s += A[i, j] * x[j]
        for j in range(nr):
            s += Br[i, j] * r[j]
        dx[i] = s
    _lim.apply(lim, x, u, dx)  # actuator/gimbal limits (taos.planar.saturation); no-op when none
    return dz, tf, u


@njit(cache=True, fastmath=_FM, inline="always")
def _finite(x, z):
    """True if the friction state and every linear state are finite."""
    ok = math.isfinite(z)
    for i in range(x.shape[0]):
        ok = ok and math.isfinite(x[i])
    return ok


@njit(cache=True, inline="always")
def work_buffers(n, nr):
    """Scratch of one RK4 integration: the stages k1..k4 and the trial state (n,), the input
    at the step start, middle and end (nr,)."""
    return (np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n),
            np.empty(nr), np.empty(nr), np.empty(nr))


@njit(cache=True, fastmath=_FM, inline="always")
def _rk4_step(x, z, r0, rm, r1, dt, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp,
              k1, k2, k3, k4, xt):
    """Advance (x, z) by one step in place; return (z_new, T_f, u) at the step start."""
    n = x.shape[0]
    dz1, tf, u = _rates(x, z, r0, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, k1)
    for i in range(n):
        xt[i] = x[i] + 0.5 * dt * k1[i]
    dz2, _, _ = _rates(xt, z + 0.5 * dt * dz1, rm, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, k2)
    for i in range(n):
        xt[i] = x[i] + 0.5 * dt * k2[i]
    dz3, _, _ = _rates(xt, z + 0.5 * dt * dz2, rm, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, k3)
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    dz4, _, _ = _rates(xt, z + dt * dz3, r1, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, k4)
    for i in range(n):
        x[i] += dt * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0
    z = z + dt * (dz1 + 2.0 * dz2 + 2.0 * dz3 + dz4) / 6.0
    return z, tf, u


@njit(cache=True, fastmath=_FM)
def integrate_samples(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, x0, z0, r, dt,
                      rec_every, y_out, aux_out):
    """Integrate over the input samples ``r`` (n_steps + 1, n_r) taken every ``dt``.

    Records every ``rec_every`` steps: ``y_out[k] = Cy x`` and ``aux_out[k] = (T_f, z, u)``.
    Returns -1 on success or the index of the step whose state became non-finite.
    """
    n = x0.shape[0]
    x = x0.copy()
    z = z0
    nsteps = r.shape[0] - 1
    nr = r.shape[1]
    k1, k2, k3, k4, xt, r0, rm, r1 = work_buffers(n, nr)
    rec = 0
    for k in range(nsteps + 1):
        k1n = min(k + 1, nsteps)
        for j in range(nr):
            r0[j] = r[k, j]
            r1[j] = r[k1n, j]
            rm[j] = 0.5 * (r0[j] + r1[j])
        if k % rec_every == 0:
            # outputs at the step start; T_f and u from a rate evaluation there
            dz, tf, u = _rates(x, z, r0, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, k1)
            for o in range(Cy.shape[0]):
                s = 0.0
                for i in range(n):
                    s += Cy[o, i] * x[i]
                y_out[rec, o] = s
            aux_out[rec, 0] = tf
            aux_out[rec, 1] = z
            aux_out[rec, 2] = u
            rec += 1
        if k == nsteps:
            break
        z, _, _ = _rk4_step(x, z, r0, rm, r1, dt, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp,
                            k1, k2, k3, k4, xt)
        if not _finite(x, z):
            return k + 1
    return -1


@njit(cache=True, fastmath=_FM)
def sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, z, nsteps, meas, out,
               k1, k2, k3, k4, xt, r0, rm, r1):
    """``nsteps`` steps of r = amp sin(2 pi k / n_per_cycle) (step ``dt`` [s], from phase 0) on
    every external input channel, in place on ``x``; returns (z, status, max |z|) with status -1
    or the failing step. With ``meas`` accumulates the correlation sums of y = Cy x into
    ``out`` (unnormalised: sum y sin, sum y cos, sum y)."""
    n = x.shape[0]
    nr = Br.shape[1]
    ny = Cy.shape[0]
    wdt = 2.0 * math.pi / n_per_cycle
    zmax = abs(z)
    for k in range(nsteps):
        ph = wdt * (k % n_per_cycle)
        s0 = math.sin(ph)
        for j in range(nr):
            r0[j] = amp * s0
            rm[j] = amp * math.sin(ph + 0.5 * wdt)
            r1[j] = amp * math.sin(ph + wdt)
        if meas:
            c0 = math.cos(ph)
            for o in range(ny):
                s = 0.0
                for i in range(n):
                    s += Cy[o, i] * x[i]
                out[o, 0] += s * s0
                out[o, 1] += s * c0
                out[o, 2] += s
        z, _, _ = _rk4_step(x, z, r0, rm, r1, dt, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp,
                            k1, k2, k3, k4, xt)
        zmax = max(zmax, abs(z))
        if not _finite(x, z):
            return z, k + 1, zmax
    return z, -1, zmax


@njit(cache=True, fastmath=_FM)
def _sine_dwell_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, freq, n_per_cycle,
                    n_settle, n_meas, out):
    """One sine dwell from rest: r = amp sin(2 pi f t) on every external input channel with a
    nonzero weight, ``n_settle`` steps (whole cycles) of settling, then out[o] = (2/N sum y sin,
    2/N sum y cos, 1/N sum y) over the ``n_meas`` measurement steps (whole cycles). Returns -1 or
    the failing step."""
    n = A.shape[0]
    nr = Br.shape[1]
    x = np.zeros(n)
    dt = 1.0 / (freq * n_per_cycle)
    k1, k2, k3, k4, xt, r0, rm, r1 = work_buffers(n, nr)
    out[:, :] = 0.0
    z, st, _ = sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, 0.0,
                          n_settle, False, out, k1, k2, k3, k4, xt, r0, rm, r1)
    if st >= 0:
        return st
    _, st, _ = sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, z,
                          n_meas, True, out, k1, k2, k3, k4, xt, r0, rm, r1)
    if st >= 0:
        return st + n_settle
    for o in range(Cy.shape[0]):
        out[o, 0] *= 2.0 / n_meas
        out[o, 1] *= 2.0 / n_meas
        out[o, 2] *= 1.0 / n_meas
    return -1


@njit(cache=True, parallel=True, fastmath=_FM)
def sine_dwell_batch(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amps, freqs, n_per_cycle,
                     n_settle, n_meas, out, status):
    """Independent sine dwells in parallel (one per entry of ``amps``/``freqs``)."""
    for b in prange(amps.shape[0]):
        status[b] = _sine_dwell_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amps[b], freqs[b],
                                    n_per_cycle[b], n_settle[b], n_meas[b], out[b])
