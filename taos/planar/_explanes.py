"""Exponential (ETDRK4) integration of the lockstep lanes of :func:`taos.planar.dynamics.integrate_segments_lanes`.

The lanes' plants (a sequence of plants held over segments, one sparse pattern for all lanes:
:func:`taos.planar.dynamics._rates_lanes`) are split into a stiff linear block on the first
``nb`` states and the rest::

    x' = L x + N(x, z, t),     L = [[A_bb, 0], [0, 0]]          (A_bb: rows and columns 0..nb-1)
    z' = g(w, z, T_a)                                            (the friction law's state [rad])

N is the lanes' own right-hand side with the block's entries left out of the sparse matrix: the
same code (:func:`~taos.planar.dynamics._rates_lanes`) evaluates the friction law's lane form,
the avionics, the limit laws of :mod:`taos.planar.saturation`, the couplings to and from the
block (the FCS command into the valve, the engine into the vehicle) and the slow states (vehicle,
FCS filters, booster), so no second copy of the dynamics exists. For the flight loop the block is
the TVC's actuator and engine (valve, oil column, piston, pressure feedback, engine: the
380 Hz load-pressure mode that bounds RK4's step, benchmarks/RESULTS.md, mcfast); it is advanced
exactly through exp(hA_bb) and its phi-functions, the rest by the stages of ETDRK4 (Cox &
Matthews, J. Comput. Phys. 176 (2002) 430, eq. (26)), the scheme and the coefficient matrices
(E, E2, P2, F1, F2, F3) of :mod:`taos.planar._expstep` (its module docstring has the
equations; :func:`taos.planar._expstep.etd_coefficients` computes them per lane and block).
Outside the block (phi_k(0) = 1/k!) the same stages reduce to the explicit update
a = x + (h/2) N(x), b = x + (h/2) N(a), c = a + (h/2) (2 N(b) - N(x)),
x+ = x + h/6 (N(x) + 2 N(a) + 2 N(b) + N(c)), as for the friction state in ``_expstep``.

The external inputs r are given on the half-step grid (sample p at t0 + p h/2), so the stage
inputs are samples, not interpolations. Loops across lanes are element-wise and compiled without
fast-math: a lane's numbers do not depend on the number of lanes or its place among them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import dynamics as _dy


@njit(cache=True, inline="always")
def _block(M, V, OUT, nb, scale):
    """OUT[i, q] += scale * sum_j M[i, j, q] V[j, q] for the block rows i < ``nb``."""
    nl = V.shape[1]
    for i in range(nb):
        for j in range(nb):
            for q in range(nl):
                OUT[i, q] += scale * M[i, j, q] * V[j, q]


@njit(cache=True, inline="always")
def _block_cols(M, V, OUT, nb, cols, scale):
    """As :func:`_block` over the columns ``cols`` only (the block rows where V, an N, can be
    nonzero: the others hold exact zeros, whose terms add nothing)."""
    nl = V.shape[1]
    for i in range(nb):
        for jj in range(cols.shape[0]):
            j = cols[jj]
            for q in range(nl):
                OUT[i, q] += scale * M[i, j, q] * V[j, q]


@njit(cache=True, error_model="numpy", _nrt=False)
def _n_lanes(Z, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D, N):
    """N(x) of every lane (:func:`taos.planar.dynamics._rates_lanes` on N's matrix): one compiled
    copy the four stages call out of line (inlined four times, the kernel's cold compile took
    16.4 s instead of 6.5 s, for the same run time within the noise: the call's arguments are
    amortised over the lanes; the same bits). Without numba's reference counting, as
    :func:`_exp_steps` (each array argument and callee parameter cost an atomic increment and
    decrement a call)."""
    _dy._rates_lanes(Z, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D, N)


@njit(cache=True, error_model="numpy")  # x / 0 -> inf or NaN (the selects discard them), no exception
def integrate_segments_lanes_exp(ip, ix, mx, head, fidl, fp, avp, bounds, jdst, jsrc, jcoef, kick, x0, z0, r, h, nb,
                                 co, rec_every, x_out, aux_out, status):
    """ETDRK4 (module docstring) of R independent runs in lockstep through their segment plants,
    step ``h`` [s]; returns the number of lanes still finite. The arguments as
    :func:`taos.planar.dynamics.integrate_segments_lanes` except:

    mx : (n_seg, nnz, R) float64
        The sparse entries of N: the lanes' matrix without the block's entries (rows and columns
        0..``nb``-1 of A).
    r : (R, 2 n_steps + 1, n_r) float64
        External inputs [r] on the half-step grid: step k reads samples 2k, 2k + 1, 2k + 2.
    bounds : (n_seg + 1,) int64
        Segment s covers half-step samples bounds[s] .. bounds[s + 1] (even numbers).
    nb : int
        The block's size: states 0..nb-1.
    co : (n_seg, 6, nb, nb, R) float64
        Per segment and lane, E, E2, P2, F1, F2, F3 of its block A_bb for the step ``h``
        (:func:`taos.planar._expstep.etd_coefficients`).
    rec_every : int
        Record every that many half-step samples (even); records as ``integrate_segments_lanes``
        (x_out (n_rec, n, R), aux_out (n_rec, N_AUX, R)).
    status : (R,) int64
        Receives -1 or the half-step sample at whose step that lane's state became non-finite.
    """
    n, nl = x0.shape
    nr = r.shape[2]
    X, Z = x0.copy(), z0.copy()
    NU, NA, NB, NC = np.empty((n, nl)), np.empty((n, nl)), np.empty((n, nl)), np.empty((n, nl))
    XA, XB, XC, T = np.empty((n, nl)), np.empty((n, nl)), np.empty((n, nl)), np.empty((n, nl))
    D1, D2, D3, D4 = np.empty(nl), np.empty(nl), np.empty(nl), np.empty(nl)
    ZA, ZB, ZC = np.empty(nl), np.empty(nl), np.empty(nl)
    U, TF = np.empty(nl), np.empty(nl)
    V = np.zeros((n + nr + 5, nl))
    C = np.empty((8, nl))
    S = np.empty((2, nl))
    OK = np.empty(nl)
    H = _dy.lanes_by_slot(head)
    AVP = np.ascontiguousarray(avp.T)
    # the block rows N reaches (rows of the sparse matrix with entries): the products with N need
    # only those columns of P2, F1, F2, F3 (in the flight loop 3 of 8: the command and the valve
    # limit on q', the flow correction on P_L, friction and the stops on the engine rate)
    cnt = 0
    for i in range(nb):
        if ip[i + 1] > ip[i]:
            cnt += 1
    cols = np.empty(cnt, np.int64)
    cnt = 0
    for i in range(nb):
        if ip[i + 1] > ip[i]:
            cols[cnt] = i
            cnt += 1
    return _exp_steps(ip, ix, mx, H, fidl, fp, AVP, bounds, jdst, jsrc, jcoef, kick, r, h, nb, co, rec_every, x_out,
                      aux_out, status, cols, X, Z, NU, NA, NB, NC, XA, XB, XC, T, D1, D2, D3, D4, ZA, ZB, ZC, U, TF, V, C,
                      S, OK)


@njit(cache=True, error_model="numpy", _nrt=False)
def _exp_steps(ip, ix, mx, H, fidl, fp, AVP, bounds, jdst, jsrc, jcoef, kick, r, h, nb, co, rec_every, x_out,
               aux_out, status, cols, X, Z, NU, NA, NB, NC, XA, XB, XC, T, D1, D2, D3, D4, ZA, ZB, ZC, U, TF, V, C,
               S, OK):
    """The steps of :func:`integrate_segments_lanes_exp` (its arguments, ``H``, ``AVP`` by slot,
    ``cols`` (m,) int64 the block rows N reaches; ``X`` (n, R) [x], ``Z`` (R,) [rad] the states,
    advanced in place; the rest its scratch); returns the lanes still finite. Without numba's
    reference counting (``_nrt=False``; no allocation here), as
    :func:`taos.planar.dynamics._lanes_steps`: every array bound per step (``CO[1]``, ...) or by
    an inlined callee cost an atomic ``NRT_incref`` and ``NRT_decref`` (benchmarks/RESULTS.md,
    lanesnrt)."""
    n, nl = X.shape
    nseg, nsamp, nr = bounds.shape[0] - 1, r.shape[1] - 1, r.shape[2]
    status[:] = -1
    alive, rec, seg = nl, 0, 0
    M, L, F, CO = mx[0], H[0], fp[0], co[0]
    h2 = 0.5 * h
    h6 = h / 6.0
    for p in range(0, nsamp + 1, 2):
        if seg < nseg and p == bounds[seg]:
            _dy.lanes_jump(X, jdst, jsrc, jcoef, kick, seg)
            M, L, F, CO = mx[seg], H[seg], fp[seg], co[seg]
            seg += 1
        pm = min(p + 1, nsamp)
        p1 = min(p + 2, nsamp)
        for i in range(n):
            for q in range(nl):
                V[i, q] = X[i, q]
        for j in range(nr):
            for q in range(nl):
                V[n + j, q] = r[q, p, j]
        # N at the step start (with T_f and u there for the record)
        _n_lanes(Z, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D1, NU)
        if p % rec_every == 0:
            _dy.lanes_record(X, Z, TF, U, x_out, aux_out, rec)
            rec += 1
        if p == nsamp:
            break
        # T = E2 x (block), x (rest); a = T + P2 N(x) (block), T + h/2 N(x) (rest)
        for i in range(n):
            for q in range(nl):
                T[i, q] = X[i, q] if i >= nb else 0.0
        _block(CO[1], X, T, nb, 1.0)
        for i in range(n):
            for q in range(nl):
                XA[i, q] = T[i, q] + (h2 * NU[i, q] if i >= nb else 0.0)
        _block_cols(CO[2], NU, XA, nb, cols, 1.0)
        for q in range(nl):
            ZA[q] = Z[q] + h2 * D1[q]
        for j in range(nr):
            for q in range(nl):
                V[n + j, q] = r[q, pm, j]
        for i in range(n):
            for q in range(nl):
                V[i, q] = XA[i, q]
        _n_lanes(ZA, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D2, NA)
        # b = T + P2 N(a)
        for i in range(n):
            for q in range(nl):
                XB[i, q] = T[i, q] + (h2 * NA[i, q] if i >= nb else 0.0)
        _block_cols(CO[2], NA, XB, nb, cols, 1.0)
        for q in range(nl):
            ZB[q] = Z[q] + h2 * D2[q]
        for i in range(n):
            for q in range(nl):
                V[i, q] = XB[i, q]
        _n_lanes(ZB, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D3, NB)
        # c = E2 a + P2 (2 N(b) - N(x))
        for i in range(n):
            for q in range(nl):
                T[i, q] = 2.0 * NB[i, q] - NU[i, q]
                XC[i, q] = (XA[i, q] + h2 * T[i, q]) if i >= nb else 0.0
        _block(CO[1], XA, XC, nb, 1.0)
        _block_cols(CO[2], T, XC, nb, cols, 1.0)
        for q in range(nl):
            ZC[q] = ZA[q] + h2 * (2.0 * D3[q] - D1[q])
        for j in range(nr):
            for q in range(nl):
                V[n + j, q] = r[q, p1, j]
        for i in range(n):
            for q in range(nl):
                V[i, q] = XC[i, q]
        _n_lanes(ZC, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D4, NC)
        # x+ = E x + F1 N(x) + 2 F2 (N(a) + N(b)) + F3 N(c) (block); the explicit update (rest)
        for i in range(n):
            for q in range(nl):
                T[i, q] = NA[i, q] + NB[i, q]
                XB[i, q] = (X[i, q] + h6 * (NU[i, q] + 2.0 * T[i, q] + NC[i, q])) if i >= nb else 0.0
        _block(CO[0], X, XB, nb, 1.0)
        _block_cols(CO[3], NU, XB, nb, cols, 1.0)
        _block_cols(CO[4], T, XB, nb, cols, 2.0)
        _block_cols(CO[5], NC, XB, nb, cols, 1.0)
        for i in range(n):
            for q in range(nl):
                X[i, q] = XB[i, q]
        for q in range(nl):
            Z[q] = Z[q] + h6 * (D1[q] + 2.0 * D2[q] + 2.0 * D3[q] + D4[q])
        alive -= _dy.lanes_failed(X, Z, OK, status, p1)
        if alive == 0:
            break
    return alive
