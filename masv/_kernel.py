"""Compiled fixed-step RK4 of N nonlinear engine axes coupled through the structure's modes.

The linear part is :class:`masv.coupled.CoupledModel` (every block's state and the modal
coordinates; open inputs the post-avionics commands u_k and the gimbal torques T_k), held as
one CSR matrix over v = [x; u; T]. Per actuator k, at every RK4 stage, the single-engine
definitions close it (no second copy of the dynamics)::

    u_k        = avionics_k(theta_c,k(t))            taos.planar._avionics_kernels.apply
    w_k        = cw_k . x      (omega_k - r_k': rate relative to the structure)     [rad/s]
    T_a,k      = ca_k . x      (R F_L - K_n (theta - r), the applied torque)       [N m]
    (z_k', T_f,k) = fid(w_k, z_k, T_a,k, fp_k)       the friction law's registry kernel
    T_stop,k   = stop_torque(ct_k . x, w_k, ...)     taos.planar.saturation.stop_torque
    T_k        = T_f,k - T_stop,k                    (J theta'' = ... - T_k)
    x'         = M [x; u; T], then the valve-flow and pressure limits of each block
                 (taos.planar.saturation.apply_valve_pressure over the block's states)

With one actuator on a rigid structure this is :func:`taos.planar.dynamics.integrate_samples`
on the simplex plant term for term (``tests/test_masv_simulate.py``).

Arrays: ``ip``, ``ix``, ``mv`` the CSR of M (N rows, N + 2 n_a columns); ``rp``, ``rx``,
``rv`` the CSR of the rows [cw_k; ca_k; ct_k] (3 n_a rows over x); ``fp`` (n_a, NPARAM) the
friction packs, ``avp`` (n_a, L) the avionics packs, ``lim`` the blocks' limit packs
concatenated (``lptr`` (n_a + 1,) bounds, ``loff`` (n_a,) each block's first state); ``r``
(n_steps + 1, n_a) the commands [rad] (linear between samples); ``dt`` [s].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from taos.planar import _avionics_kernels as _av
from taos.planar import saturation as _lim

_FM = {"reassoc", "contract", "arcp", "nsz"}


@njit(cache=True, fastmath=_FM, inline="always")
def _rates(x, z, r, ip, ix, mv, rp, rx, rv, fid, fp, avp, lim, lptr, loff, v, aux, dx, dz):
    """dx/dt into ``dx`` (N,), dz/dt into ``dz`` (n_a,), for state ``x`` [x], friction states
    ``z`` (n_a,) [rad], commands ``r`` (n_a,) [rad]; ``v`` (N + 2 n_a,) scratch receives
    [x; u; T]; ``aux`` (3 n_a,) scratch receives [w; T_a; theta_rel]."""
    n = x.shape[0]
    na = z.shape[0]
    for i in range(n):
        v[i] = x[i]
    for h in range(3 * na):
        s = 0.0
        for q in range(rp[h], rp[h + 1]):
            s += rv[q] * x[rx[q]]
        aux[h] = s
    for k in range(na):
        u = _av.apply(r[k], avp[k])
        w = aux[k]
        dzk, tf = fid(w, z[k], aux[na + k], fp[k])
        dz[k] = dzk
        lk = lim[lptr[k]:lptr[k + 1]]
        if lk.shape[0] > 0 and lk[_lim.LIM_THMAX] > 0.0:
            tf -= _lim.stop_torque(aux[2 * na + k], w, lk[_lim.LIM_THMAX], lk[_lim.LIM_KS], lk[_lim.LIM_CS])
        v[n + k] = u
        v[n + na + k] = tf
    for i in range(n):
        s = 0.0
        for q in range(ip[i], ip[i + 1]):
            s += mv[q] * v[ix[q]]
        dx[i] = s
    for k in range(na):
        lk = lim[lptr[k]:lptr[k + 1]]
        if lk.shape[0] > 0:
            _lim.apply_valve_pressure(lk, x, loff[k], v[n + k], dx)


@njit(cache=True)
def _all_finite(x, z):
    """True if every entry of ``x`` and ``z`` is finite (compiled without fast-math, so the
    test is never folded away)."""
    for i in range(x.shape[0]):
        if not math.isfinite(x[i]):
            return False
    for k in range(z.shape[0]):
        if not math.isfinite(z[k]):
            return False
    return True


@njit(cache=True, fastmath=_FM, nogil=True)
def integrate(ip, ix, mv, rp, rx, rv, fid, fp, avp, lim, lptr, loff, x0, z0, r, dt, rec_every,
              x_out, v_out, z_out):
    """RK4 over the command samples ``r`` (module docstring). Records every ``rec_every``
    steps the state into ``x_out`` (n_rec, N), [u; T] into ``v_out`` (n_rec, 2 n_a) [rad, N m]
    and the friction states into ``z_out`` (n_rec, n_a) [rad]. Returns -1, or the step at which
    the state became non-finite."""
    n = x0.shape[0]
    na = z0.shape[0]
    x, z = x0.copy(), z0.copy()
    k1, k2, k3, k4, xt = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    d1, d2, d3, d4, zt = np.empty(na), np.empty(na), np.empty(na), np.empty(na), np.empty(na)
    r0, rm, r1 = np.empty(na), np.empty(na), np.empty(na)
    v = np.empty(n + 2 * na)
    aux = np.empty(3 * na)
    nsteps = r.shape[0] - 1
    rec = 0
    for s in range(nsteps + 1):
        s1 = min(s + 1, nsteps)
        for k in range(na):
            r0[k] = r[s, k]
            r1[k] = r[s1, k]
            rm[k] = 0.5 * (r0[k] + r1[k])
        _rates(x, z, r0, ip, ix, mv, rp, rx, rv, fid, fp, avp, lim, lptr, loff, v, aux, k1, d1)
        if s % rec_every == 0:
            for i in range(n):
                x_out[rec, i] = x[i]
            for k in range(2 * na):
                v_out[rec, k] = v[n + k]
            for k in range(na):
                z_out[rec, k] = z[k]
            rec += 1
        if s == nsteps:
            break
        h = 0.5 * dt
        for i in range(n):
            xt[i] = x[i] + h * k1[i]
        for k in range(na):
            zt[k] = z[k] + h * d1[k]
        _rates(xt, zt, rm, ip, ix, mv, rp, rx, rv, fid, fp, avp, lim, lptr, loff, v, aux, k2, d2)
        for i in range(n):
            xt[i] = x[i] + h * k2[i]
        for k in range(na):
            zt[k] = z[k] + h * d2[k]
        _rates(xt, zt, rm, ip, ix, mv, rp, rx, rv, fid, fp, avp, lim, lptr, loff, v, aux, k3, d3)
        for i in range(n):
            xt[i] = x[i] + dt * k3[i]
        for k in range(na):
            zt[k] = z[k] + dt * d3[k]
        _rates(xt, zt, r1, ip, ix, mv, rp, rx, rv, fid, fp, avp, lim, lptr, loff, v, aux, k4, d4)
        for i in range(n):
            x[i] += dt * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0
        for k in range(na):
            z[k] += dt * (d1[k] + 2.0 * d2[k] + 2.0 * d3[k] + d4[k]) / 6.0
        if not _all_finite(x, z):
            return s + 1
    return -1
