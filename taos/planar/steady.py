"""Periodic steady state of a sine-driven Lur'e plant by shooting (instead of settling).

A sine dwell wants the periodic orbit y*(t) = y*(t + T) of the plant driven by
r(t) = A sin(w t), T = 2 pi / w [s], with y = (x, z) the linear states (SI, as
:class:`taos.planar.simplex.LurePlant`) and the friction law's state z [rad]. Settling finds it by
integrating from rest through the slowest transient (seconds of the lightly damped load mode).
Shooting solves the fixed-point problem of the one-period map P (``n_per_cycle`` steps of
the dwell's integrator: the ETDRK4 step of :mod:`taos.planar._expstep` by default, or the
compiled RK4 step of :func:`taos.planar.dynamics._rk4_step`)::

    G(y0) = P(y0) - y0 = 0

1. Start from the exact steady-state orbit of the linear block (friction torque off, unity
   avionics): with A_c = A + b_c c_c^T and b = B_r 1 + b_c (d_c . 1) the command's input
   vector, x(t) = Im(X e^{j w t}), X = (j w I - A_c)^-1 b A_cmd, so x0 = Im X; z0 = 0. This
   removes the linear transient, the slow lightly damped part of settling.
2. Iterate the map k + 1 times (y_0 ... y_{k+1}) and extrapolate to its fixed point by reduced
   rank extrapolation (RRE): with u_i = y_{i+1} - y_i, minimise |sum g_i u_i| subject to
   sum g_i = 1 and restart from sum g_i y_i. RRE is a multi-secant (Broyden-class) solver of
   G(y) = 0 built from the map's own differences: it needs no sensitivities and is exact in
   k cycles for a linear map with k slow Floquet modes (the simplex orbits have about four
   multipliers above 1e-3 per period; the rest die within one period). A Newton step with a
   forward-difference Jacobian stalls at scaled residuals of 1e-1 ... 1e-5 on the friction
   laws' kinks (stick-slip switching); RRE does not.
3. Converged when the scaled residual max_i |G_i| / s_i <= ``tol`` (s_i: the linear orbit's
   amplitude of state i; for the friction state the largest |z| seen over the first period).
   Otherwise (no finite extrapolation, or ``max_cycles`` spent) fall back to integration:
   plain periods from the last point until the periods integrated in all reach the settled
   dwell's budget (so a dwell that does not converge costs what settling costs).

The response is then measured over ``n_meas`` steps (whole cycles) from the periodic start,
with the same correlation as the settled dwell, and the final scaled residual is reported.
Every period is correlated as it is integrated, so a one-period measurement is the period
that proved the orbit periodic (the same steps from the same state), not a second run of it.

References: Aprille & Trick, "Steady-state analysis of nonlinear circuits with periodic
inputs", Proc. IEEE 60 (1972) (shooting); Skelboe, "Computation of the periodic steady-state
response of nonlinear networks by extrapolation methods", IEEE Trans. Circuits Syst. 27 (1980);
Smith, Ford & Sidi, "Extrapolation methods for vector sequences", SIAM Review 29 (1987) (RRE).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.core import types as _nbtypes

from . import _expstep as _ex
from . import dynamics as _ig

#: numba's LAPACK driver of ``np.linalg.lstsq`` (``numba_ez_gelsd`` in numba's helper library,
#: the signature of ``numba.np.linalg._LAPACK.numba_ez_gelsd`` for float64, Fortran integers
#: int32): kind, m, n, nrhs, a, lda, b, ldb, s, rcond, rank -> status
_F_INT = np.int32
_P = _nbtypes.CPointer
_GELSD = _nbtypes.ExternalFunction("numba_ez_gelsd", _nbtypes.intc(
    _nbtypes.char, _nbtypes.intp, _nbtypes.intp, _nbtypes.intp, _P(_nbtypes.float64), _nbtypes.intp,
    _P(_nbtypes.float64), _nbtypes.intp, _P(_nbtypes.float64), _nbtypes.float64, _P(_nbtypes.int32)))
_KIND_D = ord("d")

_FM = _ig._FM

#: columns of the ``info`` array of :func:`shoot_batch`
INFO = ("residual", "periods", "extrapolations", "converged")
#: their indices: final scaled residual [-], periods integrated, extrapolation cycles, 1.0 if
#: converged else 0.0
INFO_RESIDUAL, INFO_PERIODS, INFO_EXTRAPOLATIONS, INFO_CONVERGED = range(len(INFO))


@njit(cache=True, fastmath=_FM)
def _steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, n_per_cycle, dt, x, z, nsteps,
           meas, out, k1, k2, k3, k4, xt, r0, rm, r1):
    """``nsteps`` steps from phase 0 (whole cycles) by the ETDRK4 kernel
    (:func:`taos.planar._expstep.sine_steps_exp`, coefficients ``ex`` = (E, E2, P2, F1, F2, F3,
    G, D, tab_m)) when ``use_exp``, else by the RK4 kernel (:func:`taos.planar.dynamics.sine_steps`);
    returns (z, status, max |z|) as they do."""
    if use_exp:
        E, E2, P2, F1, F2, F3, G, D, tab_m = ex
        return _ex.sine_steps_exp(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D,
                                  tab_m, amp, n_per_cycle, dt, x, z, int(0), nsteps, meas, out)
    return _ig.sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, z, nsteps,
                          meas, out, k1, k2, k3, k4, xt, r0, rm, r1)


@njit(cache=True, fastmath=_FM)
def _period(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, n_per_cycle, dt, src, dst, s, nz,
            set_zscale, x, corr, k1, k2, k3, k4, xt, r0, rm, r1):
    """One period of the map: dst = P(src), src/dst = (x, z) (n + 1,) [x, rad]; ``corr``
    (n_y, 3) receives the period's correlation sums (:func:`taos.planar.dynamics.sine_steps`).
    With ``set_zscale`` the friction state's scale s[n] becomes the largest |z| of the period
    first. Returns (status, scaled residual max_i |dst_i - src_i| / s_i [-]).

    Plant arrays, ``Cy``, ``fid``, ``fp``, ``avp``: as :func:`taos.planar.dynamics.integrate_samples`
    (shapes and units in :mod:`taos.planar.dynamics`); ``amp`` [r]; ``n_per_cycle`` steps
    per period of ``dt`` [s]; ``s`` (n + 1,) the scales [x, rad]; ``nz`` 1 if the law has a
    state; ``x`` (n,) and the rest scratch (:func:`taos.planar.dynamics.work_buffers`)."""
    n = x.shape[0]
    for j in range(n):
        x[j] = src[j]
    corr[:, :] = 0.0
    z0 = src[n] if nz else 0.0
    z, st, zmax = _steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, n_per_cycle, dt, x,
                         z0, n_per_cycle, bool(True), corr, k1, k2, k3, k4, xt, r0, rm, r1)
    if set_zscale and nz:
        s[n] = max(zmax, 1e-300)
    d = 0.0
    for j in range(n):
        dst[j] = x[j]
        d = max(d, abs(x[j] - src[j]) / s[j])
    if nz:
        dst[n] = z
        d = max(d, abs(z - src[n]) / s[n])
    return st, d


@njit(cache=True)
def _lstsq_ones(M):
    """np.linalg.lstsq(M, ones)[0] for a square ``M`` (q, q): the minimum-norm least-squares
    solution by the same LAPACK call as numba's ``np.linalg.lstsq`` (``dgelsd`` through
    numba's ``numba_ez_gelsd``, rcond -1: singular values below machine precision times the
    largest dropped), so the same bits, without its wrapper's shape and finiteness checks whose
    exception messages cost 5-10 s of compile (``M`` is finite here: finite periods). NaNs if
    the SVD does not converge (the caller then falls back to integrating on)."""
    q = M.shape[0]
    a = np.empty(q * q)       # Fortran order
    for j in range(q):
        for i in range(q):
            a[i + q * j] = M[i, j]
    b = np.ones(q)
    s = np.empty(q)
    rank = np.empty(1, _F_INT)
    if _GELSD(_KIND_D, q, q, 1, a.ctypes, q, b.ctypes, q, s.ctypes, -1.0, rank.ctypes) != 0:
        b[:] = np.nan
    return b


@njit(cache=True, inline="always")
def _copy(src, dst, m):
    """dst[:m] = src[:m] as an element loop (an array-to-array slice assignment's shape check
    compiles an exception message: seconds of compile for nothing)."""
    for i in range(m):
        dst[i] = src[i]


@njit(cache=True, fastmath=_FM)
def _shoot_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, freq, n_per_cycle, n_budget,
               n_meas, y0, scale, nz, tol, k_rre, max_cycles, out, info):
    """Periodic steady state of one dwell (module docstring). ``y0`` (n + 1): the start
    (x0, z0); ``scale`` (n + 1): s_i (its last entry is replaced by the friction state's scale
    after the first period); ``nz`` 1 if the law has a state; ``k_rre`` + 1 periods per
    extrapolation cycle; ``n_budget`` periods in all before the fallback stops. Writes the
    correlations to ``out`` (as :func:`taos.planar.dynamics._sine_dwell_one`) and ``info``
    (:data:`INFO`, indices ``INFO_*``). Returns -1 or the failing step.

    Plant arrays, ``Cy``, ``fid``, ``fp``, ``avp``: as :func:`taos.planar.dynamics.integrate_samples`
    (shapes and units in :mod:`taos.planar.dynamics`); ``amp`` [r]; ``freq`` [Hz];
    ``n_per_cycle`` steps per period; ``n_meas`` measured steps; ``tol`` the scaled residual
    [-]; ``max_cycles`` extrapolation cycles at most."""
    n = A.shape[0]
    m = n + nz
    nr = Br.shape[1]
    dt = 1.0 / (freq * n_per_cycle)
    k1, k2, k3, k4, xt, r0, rm, r1 = _ig.work_buffers(n, nr)
    x = np.empty(n)
    corr = np.zeros((Cy.shape[0], 3))   # correlation sums of the period just integrated
    s = scale.copy()
    kk = k_rre + 2
    Y = np.zeros((kk, n + 1))  # iterates of one extrapolation cycle (unscaled; entry n unused if nz = 0)
    _copy(y0, Y[0], n + 1)
    ystar = Y[0].copy()       # the start the response is measured from (corr holds its period)
    res = np.inf
    periods = 0
    cycles = 0
    converged = False
    nxt = np.zeros(n + 1)
    while not converged:
        used = kk
        for i in range(1, kk):
            st, d = _period(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, n_per_cycle, dt,
                            Y[i - 1], Y[i], s, nz, periods == 0, x, corr, k1, k2, k3, k4, xt, r0, rm, r1)
            periods += 1
            if st >= 0:
                return st + (periods - 1) * n_per_cycle
            if d <= tol:
                res = d
                _copy(Y[i - 1], ystar, n + 1)
                converged = True
                used = i + 1
                break
        if converged or cycles >= max_cycles:
            break
        # reduced rank extrapolation in scaled variables: min |sum g_a u_a|, sum g_a = 1
        q = used - 1
        M = np.empty((q, q))
        for a in range(q):
            for b in range(q):
                acc = 0.0
                for i in range(m):
                    acc += (Y[a + 1, i] - Y[a, i]) * (Y[b + 1, i] - Y[b, i]) / (s[i] * s[i])
                M[a, b] = acc
        tr = 0.0
        for a in range(q):
            tr += M[a, a]
        for a in range(q):
            M[a, a] += 1e-15 * tr
        gam = _lstsq_ones(M)
        sg = gam.sum()
        ok = math.isfinite(sg) and sg != 0.0
        cycles += 1
        if ok:
            for i in range(m):
                acc = 0.0
                for a in range(q):
                    acc += gam[a] * Y[a, i]
                nxt[i] = acc / sg
                ok = ok and math.isfinite(nxt[i])
        if not ok:
            _copy(Y[kk - 1], Y[0], n + 1)
            break
        _copy(nxt, Y[0], m)
    if not converged:
        # fallback: integrate on from the last point until the settled dwell's budget is spent
        cur = Y[0].copy()
        for _ in range(max(n_budget - periods, 1)):
            st, d = _period(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, n_per_cycle, dt,
                            cur, nxt, s, nz, periods == 0, x, corr, k1, k2, k3, k4, xt, r0, rm, r1)
            periods += 1
            if st >= 0:
                return st + (periods - 1) * n_per_cycle
            _copy(cur, ystar, n + 1)
            res = d
            _copy(nxt, cur, n + 1)
            if d <= tol:
                converged = True
                break
    # measure from the periodic start: one measured period is the one already integrated from it
    # (the same steps from the same state); more periods are integrated again from it
    if n_meas == n_per_cycle:
        for o in range(out.shape[0]):
            _copy(corr[o], out[o], 3)
    else:
        out[:, :] = 0.0
        _copy(ystar, x, n)
        z0 = ystar[n] if nz else 0.0
        _, st, _ = _steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amp, n_per_cycle, dt, x,
                          z0, n_meas, bool(True), out, k1, k2, k3, k4, xt, r0, rm, r1)
        if st >= 0:
            return st + periods * n_per_cycle
    _ig.normalise_sums(out, n_meas)
    info[INFO_RESIDUAL] = res
    info[INFO_PERIODS] = periods
    info[INFO_EXTRAPOLATIONS] = cycles
    info[INFO_CONVERGED] = 1.0 if converged else 0.0
    return -1


@njit(cache=True, nogil=True, fastmath=_FM)
def shoot_batch(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D, tab_m, idx, use_exp,
                amps, freqs, n_per_cycle, n_budget, n_meas, y0, scale, nz, tol, k_rre, max_cycles, out, info, status,
                b0, b1):
    """Independent shooting dwells b0 <= b < b1, one after the other without the GIL (the callers
    run slices on threads: :func:`taos.planar._parallel.run_each`): :func:`_shoot_one` for entry b of ``amps``
    (n_b,) [r] and ``freqs`` (n_b,) [Hz] with its ``n_per_cycle``, ``n_budget``, ``n_meas``
    (n_b,), start ``y0`` and scales ``scale`` (n_b, n + 1), into ``out[b]`` (n_b, n_y, 3),
    ``info[b]`` (n_b, len(INFO)) and ``status[b]`` (n_b,) int; the rest as :func:`_shoot_one`.
    With ``use_exp`` the periods are ETDRK4 steps with the coefficient stacks ``E`` .. ``D``,
    ``tab_m`` at ``idx[b]`` (as :func:`taos.planar._expstep.dwell_batch`), else RK4 steps (the
    stacks unused)."""
    for b in range(b0, b1):
        i = idx[b]
        ex = (E[i], E2[i], P2[i], F1[i], F2[i], F3[i], G[i], D[i], tab_m[i])
        status[b] = _shoot_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, ex, use_exp, amps[b], freqs[b],
                               n_per_cycle[b], n_budget[b], n_meas[b], y0[b], scale[b], nz, tol, k_rre,
                               max_cycles, out[b], info[b])


def linear_orbit_start(A: np.ndarray, b_cmd: np.ndarray, amps: np.ndarray, freqs: np.ndarray):
    """Exact linear steady-state orbit at phase 0 of x' = A x + b_cmd r, r = amp sin(2 pi f t)
    (``amps`` [rad], ``freqs`` [Hz]): x0 = Im((j w I - A)^-1 b_cmd) amp. Returns
    (x0 (k, n), |X| (k, n)), the start and the orbit's amplitude per state (SI)."""
    n = A.shape[0]
    w = 2.0 * math.pi * np.asarray(freqs, float)
    M = 1j * w[:, None, None] * np.eye(n)[None] - A[None]
    X = np.linalg.solve(M, np.broadcast_to(b_cmd, (w.size, n))[..., None])[..., 0] * np.asarray(amps, float)[:, None]
    return X.imag, np.abs(X)
