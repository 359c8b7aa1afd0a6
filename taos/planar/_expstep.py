"""Exponential Runge-Kutta (ETDRK4) integration of a sine-driven Lur'e plant.

The plant of :mod:`taos.planar.dynamics` (its module docstring has the arrays, shapes and units)
is split into its linear block and the rest::

    x' = A x + b_c u(t)  +  N(x, z, t),        N = b_f T_f(w, z, T_a) + B_r r(t) + (limits)
    z' = g(w, z, T_a)                          (the friction law's bristle state [rad])

with w = c_w . x [rad/s], T_a = c_a . x [N m] and the limit corrections of
:mod:`taos.planar.saturation`. Three parts, each at the accuracy its physics needs:

1. **The linear block exactly.** The valve (100 Hz) and the oil column (380 Hz) are in A; they
   no longer set the step. exp(h A) and the phi-functions phi_k(h A) = int_0^1 e^{(1-s)hA}
   s^{k-1}/(k-1)! ds are computed once per (plant, step) as the top block row of the
   exponential of the augmented matrix [[hA, I, 0, 0], [0, 0, I, 0], [0, 0, 0, I], 0]
   (Higham, *Functions of Matrices*, SIAM 2008, sec. 10.7.4; Al-Mohy & Higham, SIAM J. Sci.
   Comput. 33 (2011) 488: no cancellation, unlike the series 1/x (e^x - 1) that Kassam &
   Trefethen, SIAM J. Sci. Comput. 26 (2005) 1214, evaluate by contour integrals).
2. **The quantised command exactly.** With c = d_c . r (the command does not depend on the
   state, c_c = 0) and r = a sin(w t), the avionics output u(t) = avionics(c(t)) is a
   staircase: constant between the times c crosses a quantiser level (multiples of LSB / 2
   cover rounding and truncation alike; the crossover gain table acts on the quantised value
   so it keeps u constant between them). Over [t0, t1] the staircase's exact response is::

       int_{t0}^{t1} e^{(t1 - s) A} b_c u(s) ds = u0 g(t1 - t0) + sum_j du_j g(t1 - tau_j),
       g(tau) = int_0^tau e^{s A} b_c ds = tau phi_1(tau A) b_c          [x per rad]

   with the crossing times tau_j = asin(level / a) / w on the monotone quarter-wave (the step
   count per cycle is a multiple of 4, so every step lies in one quarter). g is tabulated on
   [0, h/2] (values and derivative e^{tau A} b_c from the same augmented exponential) and
   read by cubic Hermite interpolation (error (dtau |A|)^4 / 384 relative, dtau |A| <= 0.1).
   Without a quantiser u is smooth and is carried in N instead.
3. **The friction and limits to fourth order.** ETDRK4 of Cox & Matthews, J. Comput. Phys. 176
   (2002) 430, eq. (26) (their a, b, c stages), on (x, z) with the staircase added to every
   stage (superposition: the scheme is exact for a known forcing)::

       a  = E2 x + g1 + P2 N(x, t)               E2 = e^{hA/2}, P2 = (h/2) phi_1(hA/2)
       b  = E2 x + g1 + P2 N(a, t + h/2)          g1, g2: the staircase over each half step
       c  = E2 a + g2 + P2 (2 N(b, t + h/2) - N(x, t))
       x+ = E x + E2 g1 + g2 + F1 N(x) + 2 F2 (N(a) + N(b)) + F3 N(c)
       F1 = h (phi_1 - 3 phi_2 + 4 phi_3), F2 = h (phi_2 - 2 phi_3), F3 = h (4 phi_3 - phi_2)

   (phi_k of hA). The bristle state has no linear part (phi_k(0) = 1/k!), so its update is the
   classical RK4 one on the same stages.

The step h is chosen from the friction loop's own rates (:func:`friction_loop_rate`) and the
measurement's sampling (:mod:`taos.planar.freqresp`), never from the linear block's.
Work per step: ten 8 x 8 matrix-vector products, four friction-kernel calls and the
command's level crossings (a few RK4 steps' worth).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _avionics_kernels as _av
from . import _expcoef as _xc
from . import dynamics as _dy
from . import saturation as _lim
from ._avionics_slots import AV_LSB

_FM = {"reassoc", "contract", "arcp", "nsz"}
#: the command table's node rule and its bound, numba-free in :mod:`taos.planar._expcoef` (re-exported)
table_nodes = _xc.table_nodes
TABLE_DTAU_NORM = _xc.TABLE_DTAU_NORM


@njit(cache=True)
def expm_small(W):
    """exp(W) of a small square matrix (:func:`expm_into`)."""
    n = W.shape[0]
    R = np.empty((n, n))
    expm_into(W, np.empty((n, n)), R, np.empty((n, n)), np.empty((n, n)))
    return R


@njit(cache=True)
def expm_into(W, X, R, T, tmp):
    """exp(W) into ``R`` (n, n) of a small square matrix ``W`` by Taylor's series with scaling
    and squaring (Moler & Van Loan, SIAM Review 45 (2003) 3, method 3): W / 2^s with
    |W / 2^s|_1 <= 1/4, 14 terms (remainder below (1/4)^15 / 15! ~ 1e-21 relative), then s
    squarings; ``X``, ``T``, ``tmp`` (n, n) scratch. Plain loops, no BLAS threads (a threaded
    BLAS on a busy machine took 20 ms for a 32 x 32 exponential), no allocation (so that it is
    translated to C as it is: :mod:`taos.planar._cdwell`)."""
    n = W.shape[0]
    nrm = 0.0
    for j in range(n):
        c = 0.0
        for i in range(n):
            c += abs(W[i, j])
        nrm = max(nrm, c)
    s = 0
    while nrm > 0.25:
        nrm *= 0.5
        s += 1
    f = 0.5 ** s
    for i in range(n):
        for j in range(n):
            X[i, j] = W[i, j] * f
            R[i, j] = 1.0 if i == j else 0.0
            T[i, j] = R[i, j]
    for k in range(1, 15):
        for i in range(n):
            for j in range(n):
                acc = 0.0
                for q in range(n):
                    acc += T[i, q] * X[q, j]
                tmp[i, j] = acc / k
        for i in range(n):
            for j in range(n):
                T[i, j] = tmp[i, j]
                R[i, j] += T[i, j]
    for _ in range(s):
        for i in range(n):
            for j in range(n):
                acc = 0.0
                for q in range(n):
                    acc += R[i, q] * R[q, j]
                tmp[i, j] = acc
        for i in range(n):
            for j in range(n):
                R[i, j] = tmp[i, j]


def phi_functions(L: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """exp(hL), phi_1(hL), phi_2(hL), phi_3(hL) (:func:`taos.planar._expcoef.phi_functions`,
    part 1 of the module docstring) by :func:`expm_small`."""
    return _xc.phi_functions(L, h, expm_small)


def command_table(A: np.ndarray, bc: np.ndarray, H: float, M: int) -> tuple[np.ndarray, np.ndarray]:
    """The command table of part 2 (:func:`taos.planar._expcoef.command_table`) by :func:`expm_small`."""
    return _xc.command_table(A, bc, H, M, expm_small)


def etd_coefficients(A: np.ndarray, h: float):
    """The ETDRK4 matrices (E, E2, P2, F1, F2, F3) of part 3 (:func:`taos.planar._expcoef.etd_coefficients`)
    by :func:`expm_small`."""
    return _xc.etd_coefficients(A, h, expm_small)


@njit(cache=True, fastmath=_FM, _nrt=False)
def _matvec_add(M, v, out, scale):
    """out += scale * M v. (Not inlined, as :func:`_nonlin`: compiled once per process and cache;
    LLVM still inlines it into its callers when it links them, so the warm step is unchanged.)
    This function, :func:`_stair`, :func:`_nonlin` and :func:`etdrk4_step`, called every step and
    allocating nothing, are compiled without numba's reference counting (``_nrt=False``): an
    atomic increment and decrement per array argument and call (benchmarks/RESULTS.md "nrt")."""
    n = out.shape[0]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += M[i, j] * v[j]
        out[i] += scale * s


@njit(cache=True, fastmath=_FM, inline="always")
def _g_at(G, D, H, M, tau, out, scale):
    """out += scale * g(tau) by cubic Hermite interpolation of the table (G, D) (its first
    M + 1 rows) on [0, H]."""
    d = H / M
    s = tau / d
    i = int(s)
    if i >= M:
        i = M - 1
    if i < 0:
        i = 0
    t = s - i
    t2 = t * t
    t3 = t2 * t
    h00 = 2 * t3 - 3 * t2 + 1.0
    h10 = t3 - 2 * t2 + t
    h01 = -2 * t3 + 3 * t2
    h11 = t3 - t2
    for k in range(out.shape[0]):
        out[k] += scale * (h00 * G[i, k] + h10 * d * D[i, k] + h01 * G[i + 1, k] + h11 * d * D[i + 1, k])


@njit(cache=True, fastmath=_FM, _nrt=False)
def _stair(G, D, H, M, cmax, w, ph0, ph1, avp, out):
    """out = the staircase's response over one half step (module docstring, part 2): the
    command c = cmax sin(phase) [rad] from phase ``ph0`` to ``ph1`` [rad] (one monotone
    quarter-wave), ``w`` [rad/s]; returns the avionics output u [rad] at its end."""
    for k in range(out.shape[0]):
        out[k] = 0.0
    lsb2 = 0.5 * avp[AV_LSB]
    c0 = cmax * math.sin(ph0)
    c1 = cmax * math.sin(ph1)
    if c1 == c0:
        u = _av.apply(c0, avp)
        _g_at(G, D, H, M, H, out, u)
        return u
    up = c1 > c0
    # band of the start in the direction of motion, its level index j and its output u
    q = c0 / lsb2
    j = math.floor(q) if up else math.ceil(q)
    dj = 1 if up else -1
    u = _av.apply((j + 0.5 * dj) * lsb2, avp)
    _g_at(G, D, H, M, H, out, u)
    # quarter-wave of the half step: crossing phase of sin(phase) = s
    qm = math.floor((0.5 * (ph0 + ph1)) / (0.5 * math.pi))
    base = 2.0 * math.pi * math.floor(qm / 4.0)
    qq = qm - 4.0 * math.floor(qm / 4.0)
    while True:
        j += dj
        lev = j * lsb2
        if (up and lev >= c1) or ((not up) and lev <= c1):
            break
        s = min(1.0, max(-1.0, lev / cmax))
        a = math.asin(s)
        if qq == 0.0:
            ph = base + a
        elif qq == 3.0:
            ph = base + 2.0 * math.pi + a
        else:
            ph = base + math.pi - a
        un = _av.apply(lev + 0.5 * dj * lsb2, avp)
        if un != u:
            _g_at(G, D, H, M, H - (ph - ph0) / w, out, un - u)
            u = un
    return u


@njit(cache=True, fastmath=_FM, _nrt=False)
def _nonlin(x, z, r, u, stair, A, Br, bc, bf, cw, ca, lim, fid, fp, N):
    """N(x, z, t) of the module docstring into ``N`` (n,) [x/s]; returns dz/dt [rad/s]. ``r``
    the external input [r], ``u`` the avionics output [rad]; with ``stair`` false the command
    term b_c u is carried here (no quantiser). Not inlined: :func:`etdrk4_step`'s four calls
    share one compile (LLVM inlines it at link time)."""
    n = x.shape[0]
    w = 0.0
    ta = 0.0
    for i in range(n):
        w += cw[i] * x[i]
        ta += ca[i] * x[i]
    dz, tf = fid(w, z, ta, fp)
    nr = Br.shape[1]
    for i in range(n):
        s = bf[i] * tf
        for j in range(nr):
            s += Br[i, j] * r
        if not stair:
            s += bc[i] * u
        N[i] = s
    _lim.apply(lim, x, u, N)
    return dz


@njit(cache=True, fastmath=_FM, _nrt=False)
def etdrk4_step(x, z, r0, rm, r1, u0, um, u1, stair, g1, g2, A, Br, bc, bf, cw, ca, lim, fid, fp, E, E2, P2, F1, F2,
                F3, dt, Nu, Na, Nb, Nc, a, b, c, xn, tmp):
    """One ETDRK4 step of length ``dt`` [s] (module docstring, part 3) in place on ``x`` (n,)
    [x]; returns (z [rad], all finite). ``r0``, ``rm``, ``r1`` [r] and ``u0``, ``um``, ``u1``
    [rad] the external input and the avionics output at the step's start, middle and end;
    with ``stair`` the staircase's responses ``g1``, ``g2`` (n,) over the two half steps
    (:func:`_stair`), otherwise b_c u rides in N; ``E`` .. ``F3``: :func:`etd_coefficients`
    for ``dt``; ``Nu`` .. ``tmp`` (n,) scratch. Plant arrays: :mod:`taos.planar.dynamics`."""
    n = x.shape[0]
    H = 0.5 * dt
    dzu = _nonlin(x, z, r0, u0, stair, A, Br, bc, bf, cw, ca, lim, fid, fp, Nu)
    for i in range(n):
        tmp[i] = g1[i]
    _matvec_add(E2, x, tmp, 1.0)          # tmp = E2 x + g1
    for i in range(n):
        a[i] = tmp[i]
    _matvec_add(P2, Nu, a, 1.0)
    za = z + H * dzu
    dza = _nonlin(a, za, rm, um, stair, A, Br, bc, bf, cw, ca, lim, fid, fp, Na)
    for i in range(n):
        b[i] = tmp[i]
    _matvec_add(P2, Na, b, 1.0)
    zb = z + H * dza
    dzb = _nonlin(b, zb, rm, um, stair, A, Br, bc, bf, cw, ca, lim, fid, fp, Nb)
    for i in range(n):
        c[i] = g2[i]
        tmp[i] = 2.0 * Nb[i] - Nu[i]
    _matvec_add(E2, a, c, 1.0)
    _matvec_add(P2, tmp, c, 1.0)
    zc = za + H * (2.0 * dzb - dzu)
    dzc = _nonlin(c, zc, r1, u1, stair, A, Br, bc, bf, cw, ca, lim, fid, fp, Nc)
    for i in range(n):
        xn[i] = g2[i]
        tmp[i] = Na[i] + Nb[i]
    _matvec_add(E2, g1, xn, 1.0)
    _matvec_add(E, x, xn, 1.0)
    _matvec_add(F1, Nu, xn, 1.0)
    _matvec_add(F2, tmp, xn, 2.0)
    _matvec_add(F3, Nc, xn, 1.0)
    ok = True
    for i in range(n):
        x[i] = xn[i]
        ok = ok and math.isfinite(xn[i])
    z = z + dt * (dzu + 2.0 * dza + 2.0 * dzb + dzc) / 6.0
    ok = ok and math.isfinite(z)
    return z, ok


@njit(cache=True, fastmath=_FM)
def sine_steps_exp(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D, tab_m, amp,
                   n_per_cycle, dt, x, z, k0, nsteps, meas, out):
    """``nsteps`` ETDRK4 steps (module docstring) of r = amp sin(2 pi k / n_per_cycle) on every
    external input channel, from step index ``k0`` (phase), in place on ``x`` (n,) [x]; returns
    (z [rad], status -1 or the failing step, max |z| [rad]). With ``meas`` accumulates the
    correlation sums of y = Cy x at the step starts into ``out`` (n_y, 3) (as
    :func:`taos.planar.dynamics.sine_steps`). ``E`` .. ``F3``: :func:`etd_coefficients` for
    ``dt`` [s]; ``G``, ``D``: :func:`command_table` for dt / 2, its first ``tab_m`` + 1 rows
    (``tab_m`` <= 0: all); ``n_per_cycle`` a multiple of 4.
    Plant arrays and kernels: :mod:`taos.planar.dynamics`."""
    n = x.shape[0]
    dcs = 0.0
    for j in range(dc.shape[0]):
        dcs += dc[j]
    cmax = amp * dcs
    stair = avp[AV_LSB] > 0.0
    wdt = 2.0 * math.pi / n_per_cycle
    w = wdt / dt
    H = 0.5 * dt
    M = G.shape[0] - 1 if tab_m <= 0 else tab_m
    Nu = np.empty(n)
    Na = np.empty(n)
    Nb = np.empty(n)
    Nc = np.empty(n)
    g1 = np.zeros(n)
    g2 = np.zeros(n)
    a = np.empty(n)
    b = np.empty(n)
    c = np.empty(n)
    xn = np.empty(n)
    tmp = np.empty(n)
    zmax = abs(z)
    u0 = _av.apply(cmax * math.sin(wdt * (k0 % n_per_cycle)), avp)
    for k in range(k0, k0 + nsteps):
        ph = wdt * (k % n_per_cycle)
        s0 = math.sin(ph)
        if meas:
            _dy.accumulate_sums(out, Cy, x, s0, math.cos(ph))
        r0 = amp * s0
        rm = amp * math.sin(ph + 0.5 * wdt)
        r1 = amp * math.sin(ph + wdt)
        if stair:
            um = _stair(G, D, H, M, cmax, w, ph, ph + 0.5 * wdt, avp, g1)
            u1 = _stair(G, D, H, M, cmax, w, ph + 0.5 * wdt, ph + wdt, avp, g2)
        else:
            um = _av.apply(dcs * rm, avp)
            u1 = _av.apply(dcs * r1, avp)
        z, ok = etdrk4_step(x, z, r0, rm, r1, u0, um, u1, stair, g1, g2, A, Br, bc, bf, cw, ca, lim, fid, fp, E, E2, P2,
                            F1, F2, F3, dt, Nu, Na, Nb, Nc, a, b, c, xn, tmp)
        u0 = u1
        zmax = max(zmax, abs(z))
        if not ok:
            return z, k - k0 + 1, zmax
    return z, -1, zmax


@njit(cache=True, fastmath=_FM)
def _dwell_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D, tab_m, amp, freq,
               n_per_cycle, n_settle, n_meas, out):
    """One sine dwell from rest by ETDRK4 (as :func:`taos.planar.dynamics._sine_dwell_one`:
    ``n_settle`` settling steps, then the normalised correlations over ``n_meas`` steps into
    ``out`` (n_y, 3)); returns -1 or the failing step."""
    n = A.shape[0]
    x = np.zeros(n)
    dt = 1.0 / (freq * n_per_cycle)
    out[:, :] = 0.0
    z, st, _ = sine_steps_exp(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D,
                              tab_m, amp, n_per_cycle, dt, x, 0.0, int(0), n_settle, bool(False), out)
    if st >= 0:
        return st
    _, st, _ = sine_steps_exp(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D,
                              tab_m, amp, n_per_cycle, dt, x, z, n_settle, n_meas, bool(True), out)
    if st >= 0:
        return st + n_settle
    _dy.normalise_sums(out, n_meas)
    return -1


@njit(cache=True, nogil=True, fastmath=_FM)
def dwell_batch(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D, tab_m, offs,
                tab, amps, freqs, n_per_cycle, n_settle, n_meas, out, status, b0, b1):
    """Independent ETDRK4 sine dwells b0 <= b < b1, one after the other without the GIL (each as
    :func:`_dwell_one`; the callers run slices on threads: :func:`taos.planar._parallel.run_each`). Dwell b uses
    the step coefficients ``E[offs[b]]`` .. ``F3[offs[b]]`` ((k, n, n) stacks, one per
    distinct step) and the command table ``G[tab[b]]``, ``D[tab[b]]`` ((k, M + 1, n), the
    first ``tab_m[tab[b]]`` + 1 rows: each step's table has its own size); the
    rest per entry as :func:`taos.planar.dynamics.sine_dwell_batch`. A dwell's result does not
    depend on the other dwells (bit for bit)."""
    for b in range(b0, b1):
        o = offs[b]
        t = tab[b]
        status[b] = _dwell_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E[o], E2[o], P2[o], F1[o],
                               F2[o], F3[o], G[t], D[t], tab_m[t], amps[b], freqs[b], n_per_cycle[b], n_settle[b],
                               n_meas[b], out[b])
