"""Compiled fixed-step RK4 of N nonlinear engine axes coupled through the structure's modes.

The linear part is :class:`masv.coupled.CoupledModel` (every block's state and the modal
coordinates; open inputs the post-avionics commands u_k and the gimbal torques T_k) in its
factored form x' = A_d x + B_d w + G_q q'', q'' = Q_x x + Q_w w, with the limits' correction
columns added as in the planar lane kernels (:func:`taos.planar.dynamics._rates_lanes`). Per
actuator k, at every RK4 stage, the single-engine definitions close it (no second copy of the
dynamics)::

    u_k        = avionics_k(theta_c,k(t))            taos.planar._avionics_kernels.apply
                 (a function of the command only: evaluated once per sample and mid-step)
    [w; T_a; th; u_v; q; P_L]_k                      rows of R over the state (w = omega_k - r_k',
                 th = theta_k - r_k, the block's valve command, valve flow, load pressure)
    (z_k', T_f,k) = fid(w_k, z_k, T_a,k, fp_k)       the friction law's registry kernel (its lane
                 form rates_lanes: every actuator in one call, the scalar law's bits)
    T_k        = T_f,k - stop_torque(th_k, w_k, ...) taos.planar.saturation.stop_torque
    e_v,k      = valve_excess(u_v,k + K_v R u_k)     taos.planar.saturation.valve_excess
    c_q,k      = pressure_flow_correction(q_k, P_L,k) taos.planar.saturation (square-root law,
                 relief)
    q''        = Q w_s,   x' = M w_s                 (J theta'' = ... - T_k; the limit columns
                 are each block's uv_in and flow_in rows of taos.planar.saturation)

**Lane layout** (:func:`lane_layout`). The n_a blocks are lanes: block state i of actuator k
is x[i n_a + k] (blocks padded to the largest block's m states with states that stay 0), then
the modal q, q' (2 n_m). The stage vector is

    w_s = [L ((m + 4) n_a): block states, u, T, e_v, c_q, row-major (quantity, lane);
           S (3 n_m): q, q', q'']

Every per-actuator row (the blocks' state rows, the rows of R) is a "lane row": entries over
the row's own lane of L (one column index, a value per lane: the union of the lanes'
patterns) and over S (broadcast to every lane), evaluated across the lanes at once (SIMD);
entries that reach another lane (residual flexibility) are a scalar CSR added after. The modal
rows and q'' are scalar CSRs over w_s. With one actuator on a rigid structure this is
:func:`taos.planar.dynamics.integrate_samples` on the simplex plant term for term
(``tests/test_masv_simulate.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse
from numba import njit

from taos.planar import _avionics_kernels as _av
from taos.planar import saturation as _lim

_FM = {"reassoc", "contract", "arcp", "nsz"}
#: the lane quantities after the block states in L, and the rows of R (per lane)
L_ROWS = ("u", "T", "e_v", "c_q")
R_ROWS = ("w", "T_a", "th", "u_v", "q", "P_L")


@dataclass(frozen=True, eq=False)
class LaneOperator:
    """Rows over the stage vector w_s: lane rows (``lp``, ``lc``, ``lv`` (nnz, n_a): lane
    entries over L's row ``lc``; ``sp``, ``sc``, ``sv`` (nnz, n_a): broadcast entries over S),
    then the cross-lane rest as a CSR over w_s on the flat rows (row i lane k at i n_a + k)."""

    lp: np.ndarray
    lc: np.ndarray
    lv: np.ndarray
    sp: np.ndarray
    sc: np.ndarray
    sv: np.ndarray
    xp: np.ndarray
    xc: np.ndarray
    xv: np.ndarray

    def arrays(self) -> tuple:
        return (self.lp, self.lc, self.lv, self.sp, self.sc, self.sv, self.xp, self.xc, self.xv)


def _csr_arrays(a) -> tuple:
    a = scipy.sparse.csr_matrix(a)
    a.eliminate_zeros()
    return (a.indptr.astype(np.int64), a.indices.astype(np.int64), a.data.astype(float))


def lane_operator(rows: list, colmap: np.ndarray, na: int, ws0: int, nw: int) -> LaneOperator:
    """The :class:`LaneOperator` of lane rows ``rows`` (each (n_a, n_v): lane k's row over the
    original stage vector), ``colmap`` the original columns' indices in w_s, S from ``ws0``."""
    lp, lc, lv, sp, sc, sv = [0], [], [], [0], [], []
    cross = np.zeros((len(rows) * na, nw))
    for i, r in enumerate(rows):
        loc, sh = {}, {}
        for k, c in zip(*np.nonzero(r)):
            wi = int(colmap[c])
            if wi >= ws0:
                sh.setdefault(wi - ws0, np.zeros(na))[k] += r[k, c]
            elif wi % na == k:
                loc.setdefault(wi // na, np.zeros(na))[k] += r[k, c]
            else:
                cross[i * na + k, wi] += r[k, c]
        for c in sorted(loc):
            lc.append(c)
            lv.append(loc[c])
        for c in sorted(sh):
            sc.append(c)
            sv.append(sh[c])
        lp.append(len(lc))
        sp.append(len(sc))
    i64 = lambda a: np.asarray(a, dtype=np.int64)
    v2 = lambda a: np.ascontiguousarray(np.reshape(a, (-1, na)), dtype=float)
    return LaneOperator(i64(lp), i64(lc), v2(lv), i64(sp), i64(sc), v2(sv), *_csr_arrays(cross))


@dataclass(frozen=True, eq=False)
class LaneLayout:
    """The lane layout (module docstring) of a coupled model with N original states: ``m``
    lane states per block, ``xmap`` (N,) each original state's index in the kernel's state,
    ``colmap`` each original stage-vector column's index in w_s, ``ws0`` S's start, ``nw``
    the length of w_s, ``nx`` the kernel's state length."""

    m: int
    xmap: np.ndarray
    colmap: np.ndarray
    ws0: int
    nw: int
    nx: int


def lane_layout(offsets, nm: int) -> LaneLayout:
    """The layout for blocks at ``offsets`` (n_a + 1,) and ``nm`` modes, over the original
    stage vector [x (N); u; T; e_v; c_q (n_a each); q'' (n_m)], N = offsets[-1] + 2 n_m."""
    off = np.asarray(offsets, dtype=int)
    na = off.size - 1
    nb = int(off[-1])
    m = int(np.max(np.diff(off))) if na else 0
    ws0 = (m + len(L_ROWS)) * na
    N = nb + 2 * nm
    xmap = np.empty(N, dtype=np.int64)
    for k in range(na):
        for i in range(off[k + 1] - off[k]):
            xmap[off[k] + i] = i * na + k
    xmap[nb:] = m * na + np.arange(2 * nm)
    colmap = np.empty(N + len(L_ROWS) * na + nm, dtype=np.int64)
    colmap[:nb] = xmap[:nb]
    colmap[nb:N] = ws0 + np.arange(2 * nm)
    for j in range(len(L_ROWS)):
        colmap[N + j * na:N + (j + 1) * na] = (m + j) * na + np.arange(na)
    colmap[N + len(L_ROWS) * na:] = ws0 + 2 * nm + np.arange(nm)
    return LaneLayout(m, xmap, colmap, ws0, ws0 + 3 * nm, m * na + 2 * nm)


@njit(cache=True, fastmath=_FM, inline="always")
def _csr(p, ix, val, v, out, o0):
    """out[o0 + i] = row i of the CSR (``p``, ``ix``, ``val``) times ``v``."""
    for i in range(p.shape[0] - 1):
        s = 0.0
        for q in range(p[i], p[i + 1]):
            s += val[q] * v[ix[q]]
        out[o0 + i] = s


@njit(cache=True, fastmath=_FM, inline="always")
def _lanes(lp, lc, lv, sp, sc, sv, xp, xc, xv, W, ws0, out):
    """out (rows n_a,) flat = the lane operator (:class:`LaneOperator`) times the stage vector
    ``W`` (S from ``ws0``)."""
    na = lv.shape[1]
    for i in range(lp.shape[0] - 1):
        o = i * na
        for k in range(na):
            out[o + k] = 0.0
        for e in range(lp[i], lp[i + 1]):
            c = lc[e] * na
            for k in range(na):
                out[o + k] += lv[e, k] * W[c + k]
        for e in range(sp[i], sp[i + 1]):
            s = W[ws0 + sc[e]]
            for k in range(na):
                out[o + k] += sv[e, k] * s
    for r in range(xp.shape[0] - 1):
        s = 0.0
        for q in range(xp[r], xp[r + 1]):
            s += xv[q] * W[xc[q]]
        out[r] += s


@njit(cache=True, fastmath=_FM, inline="always")
def _rates(x, z, u, ml, mp, mx, mv, ql, rl, H, fidl, fp, W, ws0, m, aux, dx, dz):
    """dx/dt into ``dx`` (n_x,), dz/dt into ``dz`` (n_a,), for the state ``x`` [x] (lane
    layout), friction states ``z`` (n_a,) [rad], post-avionics commands ``u`` (n_a,) [rad];
    ``ml`` the blocks' lane rows, (``mp``, ``mx``, ``mv``) the modal state rows' CSR over w_s,
    ``ql`` (p, ix, val) the CSR of q'' over w_s, ``rl`` the lane rows of R; ``W`` the stage
    vector (scratch), ``aux`` (6 n_a,) scratch receives R w_s."""
    na = z.shape[0]
    nl = m * na
    nm2 = x.shape[0] - nl
    for i in range(nl):
        W[i] = x[i]
    for j in range(nm2):
        W[ws0 + j] = x[nl + j]
    _lanes(rl[0], rl[1], rl[2], rl[3], rl[4], rl[5], rl[6], rl[7], rl[8], W, ws0, aux)
    fidl(aux[:na], z, aux[na:2 * na], fp, dz, W[nl + na:nl + 2 * na])   # T_f into T's lanes
    for k in range(na):
        w = aux[k]
        h = H[k]
        W[nl + k] = u[k]
        W[nl + na + k] -= _lim.stop_torque(aux[2 * na + k], w, h[_lim.LIM_THMAX], h[_lim.LIM_KS], h[_lim.LIM_CS])
        W[nl + 2 * na + k] = _lim.valve_excess(h, aux[3 * na + k] + h[_lim.LIM_KVR] * u[k])
        W[nl + 3 * na + k] = _lim.pressure_flow_correction(h, aux[4 * na + k], aux[5 * na + k])
    _csr(ql[0], ql[1], ql[2], W, W, ws0 + nm2)
    _lanes(ml[0], ml[1], ml[2], ml[3], ml[4], ml[5], ml[6], ml[7], ml[8], W, ws0, dx)
    _csr(mp, mx, mv, W, dx, nl)


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
def integrate(ml, mp, mx, mv, ql, rl, H, m, nw, ws0, fidl, fp, avp, amap, x0, z0, r, dt, rec_every, x_out, v_out, z_out):
    """RK4 over the command samples ``r`` (n_steps + 1, n_c) [rad] (linear between samples),
    step ``dt`` [s], from ``x0`` (n_x,) (lane layout) and ``z0`` (n_a,) [rad]. ``ml``, ``rl``
    the lane operators of the blocks' rows and of R (:meth:`LaneOperator.arrays`), (``mp``,
    ``mx``, ``mv``) the modal rows' CSR and ``ql`` the CSR of q'', all over w_s (length ``nw``, S from
    ``ws0``, ``m`` lane states); ``H`` (n_a, N_HEAD) the blocks' limit heads
    (:mod:`taos.planar.saturation`, zeros: off); ``fidl`` the friction law's lane form
    ``rates_lanes`` (the actuators as lanes, one call a stage), ``fp`` (n_a, NPARAM) its packs; ``avp`` (n_c, L) the avionics packs: actuator k's
    post-avionics command is that of command column and pack ``amap[k]`` (actuators with the
    same command and avionics share one evaluation). Records every
    ``rec_every`` steps the state into ``x_out`` (n_rec, n_x), [u; T] into ``v_out``
    (n_rec, 2 n_a) [rad, N m] and the friction states into ``z_out`` (n_rec, n_a) [rad].
    Returns -1, or the step at which the state became non-finite."""
    n = x0.shape[0]
    na = z0.shape[0]
    x, z = x0.copy(), z0.copy()
    K, D = np.empty((4, n)), np.empty((4, na))   # the stages' dx/dt and dz/dt
    xt, zt = np.empty(n), np.empty(na)
    nc = r.shape[1]
    u0, um, u1 = np.empty(na), np.empty(na), np.empty(na)
    c0, cm, c1 = np.empty(nc), np.empty(nc), np.empty(nc)
    W = np.zeros(nw)
    aux = np.empty(len(R_ROWS) * na)
    return _steps(ml, mp, mx, mv, ql, rl, H, m, ws0, fidl, fp, avp, amap, r, dt, rec_every, x_out, v_out, z_out,
                  x, z, K, D, xt, zt, u0, um, u1, c0, cm, c1, W, aux)


@njit(cache=True, fastmath=_FM, nogil=True, _nrt=False)
def _steps(ml, mp, mx, mv, ql, rl, H, m, ws0, fidl, fp, avp, amap, r, dt, rec_every, x_out, v_out, z_out,
           x, z, K, D, xt, zt, u0, um, u1, c0, cm, c1, W, aux):
    """The steps of :func:`integrate` (its arguments; ``x`` (n_x,) [x], ``z`` (n_a,) [rad] the
    states, advanced in place; the rest its scratch); returns as it. Compiled without numba's
    reference counting (``_nrt=False``; nothing is allocated here, the caller holds every array):
    every array bound per stage (the operators' rows out of their tuples, ``H[k]``, the slices of
    ``aux`` and ``W``, the parameters of the inlined rates) cost an atomic ``NRT_incref`` and
    ``NRT_decref`` that numba's pruning left in the loop, a third of the run
    (benchmarks/RESULTS.md, lanesnrt)."""
    n = x.shape[0]
    na = z.shape[0]
    nl = m * na
    nc = r.shape[1]
    nsteps = r.shape[0] - 1
    for j in range(nc):
        c1[j] = _av.apply(r[0, j], avp[j])
    for k in range(na):
        u1[k] = c1[amap[k]]
    rec = 0
    for s in range(nsteps + 1):
        s1 = min(s + 1, nsteps)
        for j in range(nc):
            c0[j] = c1[j]   # the avionics of this step's start sample, computed a step ago
            cm[j] = _av.apply(0.5 * (r[s, j] + r[s1, j]), avp[j])
            c1[j] = _av.apply(r[s1, j], avp[j])
        for k in range(na):
            u0[k] = c0[amap[k]]
            um[k] = cm[amap[k]]
            u1[k] = c1[amap[k]]
        # the four stages through ONE inlined copy of _rates: inlined at each stage, the kernel's
        # cold compile typed and lowered four copies; called out of line (one compiled function),
        # its arguments cost 2 % of the kernel's run, this loop 3 % less than the four copies
        # (benchmarks/RESULTS.md, compile2); the same bits
        for st in range(4):
            if st == 0:
                for i in range(n):
                    xt[i] = x[i]
                for k in range(na):
                    zt[k] = z[k]
            else:
                c = dt if st == 3 else 0.5 * dt
                for i in range(n):
                    xt[i] = x[i] + c * K[st - 1, i]
                for k in range(na):
                    zt[k] = z[k] + c * D[st - 1, k]
            _rates(xt, zt, u0 if st == 0 else (u1 if st == 3 else um), ml, mp, mx, mv, ql, rl, H, fidl, fp, W, ws0,
                   m, aux, K[st], D[st])
            if st == 0:
                if s % rec_every == 0:
                    for i in range(n):
                        x_out[rec, i] = x[i]
                    for k in range(2 * na):
                        v_out[rec, k] = W[nl + k]
                    for k in range(na):
                        z_out[rec, k] = z[k]
                    rec += 1
                if s == nsteps:
                    break
        if s == nsteps:
            break
        for i in range(n):
            x[i] += dt * (K[0, i] + 2.0 * K[1, i] + 2.0 * K[2, i] + K[3, i]) / 6.0
        for k in range(na):
            z[k] += dt * (D[0, k] + 2.0 * D[1, k] + 2.0 * D[2, k] + D[3, k]) / 6.0
        if not _all_finite(x, z):
            return s + 1
    return -1
