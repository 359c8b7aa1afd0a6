"""Compiled fixed-step RK4 of N nonlinear engine axes coupled through the structure's modes.

The linear part is :class:`masv.coupled.CoupledModel` (every block's state and the modal
coordinates; open inputs the post-avionics commands u_k and the gimbal torques T_k) in its
factored form x' = A_d x + B_d w + G_q q'', q'' = Q_x x + Q_w w, with the limits' correction
columns added (as in the planar lane kernels, :func:`taos.planar.dynamics._rates_lanes`): two
CSR matrices over the stage vector

    v = [x (N); u (n_a); T (n_a); e_v (n_a); c_q (n_a); q'' (n_m)]

``Q`` (n_m rows: q'' = Q v, reading x, u, T) and ``M`` (N rows: x' = M v). Per actuator k, at
every RK4 stage, the single-engine definitions close it (no second copy of the dynamics)::

    u_k        = avionics_k(theta_c,k(t))            taos.planar._avionics_kernels.apply
                 (a function of the command only: evaluated once per sample and mid-step)
    [w; T_a; th; u_v; q; P_L]_k = rows of R x   (w = omega_k - r_k', th = theta_k - r_k, and
                 the block's valve command, valve flow and load pressure rows of its limits)
    (z_k', T_f,k) = fid(w_k, z_k, T_a,k, fp_k)       the friction law's registry kernel
    T_k        = T_f,k - stop_torque(th_k, w_k, ...) taos.planar.saturation.stop_torque
    e_v,k      = valve_excess(u_v,k + K_v R u_k)     taos.planar.saturation.valve_excess
    c_q,k      = pressure_flow_correction(q_k, P_L,k) taos.planar.saturation (square-root law,
                 relief)
    q''        = Q v,   x' = M v                     (J theta'' = ... - T_k; the limit columns
                 are each block's uv_in and flow_in rows of taos.planar.saturation)

With one actuator on a rigid structure this is :func:`taos.planar.dynamics.integrate_samples`
on the simplex plant term for term (``tests/test_masv_simulate.py``).

Arrays: ``ip``, ``ix``, ``mv`` the CSR of M; ``qp``, ``qx``, ``qv`` the CSR of Q; ``rp``,
``rx``, ``rv`` the CSR of R (6 n_a rows over x, in the order above, actuator-major within each
quantity); ``H`` (n_a, N_HEAD) the blocks' packed limit heads (slots ``LIM_*`` of
:mod:`taos.planar.saturation`; zeros: limits off); ``fp`` (n_a, NPARAM) the friction packs,
``avp`` (n_a, L) the avionics packs; ``r`` (n_steps + 1, n_a) the commands [rad] (linear
between samples); ``dt`` [s].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from taos.planar import _avionics_kernels as _av
from taos.planar import saturation as _lim

_FM = {"reassoc", "contract", "arcp", "nsz"}


@njit(cache=True, fastmath=_FM, inline="always")
def _csr(p, ix, val, v, out, o0):
    """out[o0 + i] = row i of the CSR (``p``, ``ix``, ``val``) times ``v``."""
    for i in range(p.shape[0] - 1):
        s = 0.0
        for q in range(p[i], p[i + 1]):
            s += val[q] * v[ix[q]]
        out[o0 + i] = s


@njit(cache=True, fastmath=_FM, inline="always")
def _rates(x, z, u, ip, ix, mv, qp, qx, qv, rp, rx, rv, H, fid, fp, v, aux, dx, dz):
    """dx/dt into ``dx`` (N,), dz/dt into ``dz`` (n_a,), for state ``x`` [x], friction states
    ``z`` (n_a,) [rad], post-avionics commands ``u`` (n_a,) [rad]; ``v`` the stage vector
    (module docstring) scratch, ``aux`` (6 n_a,) scratch receives R x."""
    n = x.shape[0]
    na = z.shape[0]
    for i in range(n):
        v[i] = x[i]
    _csr(rp, rx, rv, x, aux, 0)
    for k in range(na):
        w = aux[k]
        h = H[k]
        dzk, tf = fid(w, z[k], aux[na + k], fp[k])
        dz[k] = dzk
        v[n + k] = u[k]
        v[n + na + k] = tf - _lim.stop_torque(aux[2 * na + k], w, h[_lim.LIM_THMAX], h[_lim.LIM_KS],
                                              h[_lim.LIM_CS])
        v[n + 2 * na + k] = _lim.valve_excess(h, aux[3 * na + k] + h[_lim.LIM_KVR] * u[k])
        v[n + 3 * na + k] = _lim.pressure_flow_correction(h, aux[4 * na + k], aux[5 * na + k])
    _csr(qp, qx, qv, v, v, n + 4 * na)
    _csr(ip, ix, mv, v, dx, 0)


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
def integrate(ip, ix, mv, qp, qx, qv, rp, rx, rv, H, fid, fp, avp, x0, z0, r, dt, rec_every, x_out, v_out, z_out):
    """RK4 over the command samples ``r`` (module docstring). Records every ``rec_every``
    steps the state into ``x_out`` (n_rec, N), [u; T] into ``v_out`` (n_rec, 2 n_a) [rad, N m]
    and the friction states into ``z_out`` (n_rec, n_a) [rad]. Returns -1, or the step at which
    the state became non-finite."""
    n = x0.shape[0]
    na = z0.shape[0]
    nm = qp.shape[0] - 1
    x, z = x0.copy(), z0.copy()
    k1, k2, k3, k4, xt = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    d1, d2, d3, d4, zt = np.empty(na), np.empty(na), np.empty(na), np.empty(na), np.empty(na)
    u0, um, u1 = np.empty(na), np.empty(na), np.empty(na)
    v = np.empty(n + 4 * na + nm)
    aux = np.empty(6 * na)
    nsteps = r.shape[0] - 1
    for k in range(na):
        u1[k] = _av.apply(r[0, k], avp[k])
    rec = 0
    for s in range(nsteps + 1):
        s1 = min(s + 1, nsteps)
        for k in range(na):
            u0[k] = u1[k]   # the avionics of this step's start sample, computed a step ago
            um[k] = _av.apply(0.5 * (r[s, k] + r[s1, k]), avp[k])
            u1[k] = _av.apply(r[s1, k], avp[k])
        _rates(x, z, u0, ip, ix, mv, qp, qx, qv, rp, rx, rv, H, fid, fp, v, aux, k1, d1)
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
        _rates(xt, zt, um, ip, ix, mv, qp, qx, qv, rp, rx, rv, H, fid, fp, v, aux, k2, d2)
        for i in range(n):
            xt[i] = x[i] + h * k2[i]
        for k in range(na):
            zt[k] = z[k] + h * d2[k]
        _rates(xt, zt, um, ip, ix, mv, qp, qx, qv, rp, rx, rv, H, fid, fp, v, aux, k3, d3)
        for i in range(n):
            xt[i] = x[i] + dt * k3[i]
        for k in range(na):
            zt[k] = z[k] + dt * d3[k]
        _rates(xt, zt, u1, ip, ix, mv, qp, qx, qv, rp, rx, rv, H, fid, fp, v, aux, k4, d4)
        for i in range(n):
            x[i] += dt * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0
        for k in range(na):
            z[k] += dt * (d1[k] + 2.0 * d2[k] + 2.0 * d3[k] + d4[k]) / 6.0
        if not _all_finite(x, z):
            return s + 1
    return -1
