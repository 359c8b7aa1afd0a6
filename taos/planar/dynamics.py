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

Kernel arguments (the plant's arrays in the order of :class:`taos.planar.simulate.PlantArrays`,
then the outputs, the friction law and the avionics; n states, n_r external inputs, n_y
outputs; [x], [r] and [y] stand for the SI units of the plant's states, inputs and outputs)::

    name  shape        quantity                                     unit
    A     (n, n)       state matrix                                 [x/s per x]
    Br    (n, n_r)     external-input columns                       [x/s per r]
    bc    (n,)         post-avionics command column                 [x/s per rad]
    bf    (n,)         friction-torque column                       [x/s per N m]
    cc    (n,)         pre-avionics command row over x              [rad per x]
    dc    (n_r,)       pre-avionics command row over r              [rad per r]
    cw    (n,)         friction relative-rate row                   [rad/s per x]
    ca    (n,)         applied (non-friction) torque row            [N m per x]
    lim   (k,)         packed actuator/gimbal limits over the       taos.planar.saturation
                       state (empty: no limits)                     (LIM_*, ROW_*)
    Cy    (n_y, n)     recorded outputs                             [y per x]
    fid   function     the law's rates(v, z, t_app, p)              registry RATES_SIG
                       -> (dz/dt [rad/s], T_f [N m])
    fp    (NPARAM,)    the law's packed parameters                  taos.friction._slots (SLOT_*)
    avp   (4 + 2 m,)   packed avionics (m: gain-table length)       taos.planar._avionics_slots (AV_*)

The friction state z is in [rad] (the bristle deflection), the step dt in [s]. Records of
:func:`integrate_samples`: ``y_out`` = Cy x, ``aux_out`` columns ``AUX_*`` (T_f [N m], z [rad],
u [rad]).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _avionics_kernels as _av
from . import saturation as _lim

# reassociation and FMA contraction only: no-NaN/no-Inf flags would remove the stability checks
_FM = {"reassoc", "contract", "arcp", "nsz"}
#: columns of :func:`integrate_samples`' ``aux_out``: friction torque T_f [N m], friction state
#: z [rad], post-avionics command u [rad]
AUX_TF, AUX_Z, AUX_U = 0, 1, 2
N_AUX = 3


@njit(cache=True, fastmath=_FM, inline="always")
def _rates(x, z, r, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, dx):
    """The state equations (module docstring) at the state ``x`` (n,) [x], friction state ``z``
    [rad] and external input ``r`` (n_r,) [r]: writes dx/dt into ``dx`` (n,) [x/s] and returns
    (dz/dt [rad/s], T_f [N m], u [rad]). Plant arrays, ``fid``, ``fp``, ``avp``: module
    docstring."""
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
    _lim.apply_inlined(lim, x, u, dx)  # actuator/gimbal limits (taos.planar.saturation); no-op when none
    return dz, tf, u


@njit(cache=True, fastmath=_FM, inline="always")
def _finite(x, z):
    """True if the friction state ``z`` [rad] and every linear state ``x`` (n,) are finite."""
    ok = math.isfinite(z)
    for i in range(x.shape[0]):
        ok = ok and math.isfinite(x[i])
    return ok


@njit(cache=True, inline="always")
def work_buffers(n, nr):
    """Scratch of one RK4 integration: the stages k1..k4 and the trial state (n,), the input
    at the step start, middle and end (nr,); ``n`` states, ``nr`` external inputs."""
    return np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(nr), np.empty(nr), np.empty(nr)


@njit(cache=True, fastmath=_FM, _nrt=False)
def _rk4_step(x, z, r0, rm, r1, dt, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp,
              k1, k2, k3, k4, xt):
    """Advance (x, z) by one classical RK4 step in place; return (z_new [rad], T_f [N m], u [rad])
    at the step start.

    ``x`` (n,) [x] (in place), ``z`` [rad]; ``r0``, ``rm``, ``r1`` (n_r,) [r] the input at the step's
    start, middle and end (``r0`` holds ``r1`` on return: callers fill all three every step);
    ``dt`` [s]; plant arrays, ``fid``, ``fp``, ``avp``: module docstring; ``k1``..``k4``, ``xt``
    (n,) scratch (k1 receives the derivative at the step start).

    Compiled once, not inlined: :func:`integrate_samples`, :func:`sine_steps` and the shooting
    periods (:mod:`taos.planar.steady`) call this one step. :func:`_rates` is inlined (out of
    line, its ~110 scalar arguments cost 30 % of the step) ONCE: the stages are a loop passing
    the same arrays to every stage (state ``xt``, input ``r0``, derivative ``k4``, copied to
    k1..k3). Compiled without numba's reference counting (``_nrt=False``; it allocates nothing):
    an atomic increment and decrement for each array argument on every call, and for each array
    an inlined callee binds per stage, were 60-70 % of the step (RESULTS.md "nrt"). Same bits as
    the classical step's four copies (benchmarks/planar_step_bits.py; RESULTS "stage4", "nrt")."""
    n = x.shape[0]
    h2 = 0.5 * dt
    dz, dz1, dz2, dzs, tf, u = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for st in range(4):
        # stage 1 at (x, z, r0); 2-4 at x + c k_prev (in k4), z + c dz_prev, mid (c = dt/2) or end (dt)
        c = dt if st == 3 else h2
        for i in range(n):
            xt[i] = x[i] if st == 0 else x[i] + c * k4[i]
        zs = z if st == 0 else z + c * dz
        if st == 1 or st == 3:
            for j in range(r0.shape[0]):
                r0[j] = rm[j] if st == 1 else r1[j]
        dz, tfs, us = _rates(xt, zs, r0, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp, k4)
        if st == 0:
            dz1, tf, u = dz, tfs, us
            for i in range(n):
                k1[i] = k4[i]
        elif st == 1:
            dz2 = dz
            for i in range(n):
                k2[i] = k4[i]
        elif st == 2:
            dzs = 2.0 * (dz + dz2) + dz1   # dz3 = dz
            for i in range(n):
                k3[i] = k4[i]
        else:
            dzs = dzs + dz
    for i in range(n):
        x[i] += dt * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0
    # z's increment (dz1 + 2 dz2 + 2 dz3 + dz4) dt / 6 [rad] as (2 (dz3 + dz2) + dz1) + dz4: the
    # order LLVM's reassociation gave the four-copy step
    z = z + dt * dzs / 6.0
    return z, tf, u


@njit(cache=True, fastmath=_FM, nogil=True)  # nogil: independent runs in threads (taos.planar._parallel)
def integrate_samples(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, x0, z0, r, dt,
                      rec_every, y_out, aux_out):
    """Integrate over the input samples ``r`` taken every ``dt``.

    Parameters: ``A, Br, bc, bf, cc, dc, cw, ca, lim`` the plant, ``fid, fp, avp`` the friction
    law's ``rates`` kernel and packed parameters and the packed avionics (module docstring:
    shapes and units); ``Cy`` (n_y, n) the recorded outputs [y per x]; ``x0`` (n,) the initial
    state [x] (not modified), ``z0`` the initial friction state [rad]; ``r`` (n_steps + 1, n_r)
    the external input samples [r], linearly interpolated between samples; ``dt`` the step [s];
    ``rec_every`` record every that many steps; ``y_out`` (n_steps // rec_every + 1, n_y)
    receives Cy x, ``aux_out`` (n_steps // rec_every + 1, N_AUX) receives (T_f [N m], z [rad],
    u [rad]) (columns ``AUX_*``).

    Returns -1 on success or the index of the step whose state became non-finite.

    Runs without the GIL: independent calls in threads of one process run on all cores, each
    with the same numbers as alone (:mod:`taos.planar._parallel`).
    """
    return _sample_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, x0.copy(), z0, r, dt, rec_every,
                         y_out, aux_out, *work_buffers(x0.shape[0], r.shape[1]))


@njit(cache=True, fastmath=_FM, _nrt=False)
def _sample_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, x, z, r, dt, rec_every, y_out, aux_out,
                  k1, k2, k3, k4, xt, r0, rm, r1):
    """The steps of :func:`integrate_samples` from ``x`` (advanced in place) and ``z``, with its
    scratch (:func:`work_buffers`); compiled without numba's reference counting (as :func:`_rk4_step`)."""
    n = x.shape[0]
    nsteps = r.shape[0] - 1
    nr = r.shape[1]
    rec = 0
    for k in range(nsteps + 1):
        k1n = min(k + 1, nsteps)
        for j in range(nr):
            r0[j] = r[k, j]
            r1[j] = r[k1n, j]
            rm[j] = 0.5 * (r0[j] + r1[j])
        record = k % rec_every == 0
        if record:  # outputs at the step start
            for o in range(Cy.shape[0]):
                s = 0.0
                for i in range(n):
                    s += Cy[o, i] * x[i]
                y_out[rec, o] = s
            aux_out[rec, AUX_Z] = z
        # T_f and u at the step start come from the step's first rate evaluation; after the last
        # sample a step of zero length gives them (x and z are left as they are)
        zn, tf, u = _rk4_step(x, z, r0, rm, r1, dt if k < nsteps else 0.0, A, Br, bc, bf, cc, dc, cw, ca, lim,
                              fid, fp, avp, k1, k2, k3, k4, xt)
        if record:
            aux_out[rec, AUX_TF] = tf
            aux_out[rec, AUX_U] = u
            rec += 1
        if k == nsteps:
            break
        z = zn
        if not _finite(x, z):
            return k + 1
    return -1


@njit(cache=True, fastmath=_FM)
def sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, z, nsteps, meas, out,
               k1, k2, k3, k4, xt, r0, rm, r1):
    """``nsteps`` steps of r = amp sin(2 pi k / n_per_cycle) (step ``dt`` [s], from phase 0) on
    every external input channel, in place on ``x``; returns (z [rad], status, max |z| [rad])
    with status -1 or the failing step. With ``meas`` accumulates the correlation sums of
    y = Cy x into ``out`` (unnormalised: sum y sin, sum y cos, sum y).

    Parameters
    ----------
    A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp
        As :func:`integrate_samples` (module docstring).
    amp : float
        Input amplitude [r].
    n_per_cycle : int
        Steps per cycle.
    dt : float
        Step [s].
    x : (n,) float64
        State [x], advanced in place.
    z : float
        Friction state [rad].
    nsteps : int
        Steps to take.
    meas : bool
        Accumulate the correlation sums.
    out : (n_y, 3) float64
        Correlation sums [y], accumulated in place.
    k1, k2, k3, k4, xt : (n,) float64; r0, rm, r1 : (n_r,) float64
        Scratch (:func:`work_buffers`).
    """
    nr = Br.shape[1]
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
            accumulate_sums(out, Cy, x, s0, math.cos(ph))
        z, _, _ = _rk4_step(x, z, r0, rm, r1, dt, A, Br, bc, bf, cc, dc, cw, ca, lim, fid, fp, avp,
                            k1, k2, k3, k4, xt)
        zmax = max(zmax, abs(z))
        if not _finite(x, z):
            return z, k + 1, zmax
    return z, -1, zmax


@njit(cache=True, fastmath=_FM, inline="always")
def accumulate_sums(out, Cy, x, s0, c0):
    """Add one step's correlation terms of y = Cy x (``x`` (n,) [x]) with the command's sin
    ``s0`` and cos ``c0`` at that step into ``out`` (n_y, 3): (y s0, y c0, y) [y]."""
    for o in range(Cy.shape[0]):
        s = 0.0
        for i in range(x.shape[0]):
            s += Cy[o, i] * x[i]
        out[o, 0] += s * s0
        out[o, 1] += s * c0
        out[o, 2] += s


@njit(cache=True, fastmath=_FM, inline="always")
def normalise_sums(out, n_meas):
    """The correlation sums of :func:`sine_steps` over ``n_meas`` steps (whole cycles) into
    Fourier coefficients in place: out[o] = (2/N sum y sin, 2/N sum y cos, 1/N sum y) [y]."""
    for o in range(out.shape[0]):
        out[o, 0] *= 2.0 / n_meas
        out[o, 1] *= 2.0 / n_meas
        out[o, 2] *= 1.0 / n_meas


@njit(cache=True, fastmath=_FM)
def _sine_dwell_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, freq, n_per_cycle,
                    n_settle, n_meas, out):
    """One sine dwell from rest: r = amp sin(2 pi f t) on every external input channel with a
    nonzero weight, ``n_settle`` steps (whole cycles) of settling, then out[o] = (2/N sum y sin,
    2/N sum y cos, 1/N sum y) over the ``n_meas`` measurement steps (whole cycles). Returns -1 or
    the failing step.

    Plant arrays, ``Cy``, ``fid``, ``fp``, ``avp``: as :func:`integrate_samples`; ``amp`` [r];
    ``freq`` [Hz]; ``n_per_cycle``, ``n_settle``, ``n_meas`` int (steps; dt = 1 / (freq
    n_per_cycle) [s]); ``out`` (n_y, 3) float64 [y]."""
    n = A.shape[0]
    nr = Br.shape[1]
    x = np.zeros(n)
    dt = 1.0 / (freq * n_per_cycle)
    k1, k2, k3, k4, xt, r0, rm, r1 = work_buffers(n, nr)
    out[:, :] = 0.0
    z, st, _ = sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, 0.0,
                          n_settle, bool(False), out, k1, k2, k3, k4, xt, r0, rm, r1)
    if st >= 0:
        return st
    _, st, _ = sine_steps(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amp, n_per_cycle, dt, x, z,
                          n_meas, bool(True), out, k1, k2, k3, k4, xt, r0, rm, r1)
    if st >= 0:
        return st + n_settle
    normalise_sums(out, n_meas)
    return -1


@njit(cache=True, nogil=True, fastmath=_FM)
def sine_dwell_batch(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amps, freqs, n_per_cycle,
                     n_settle, n_meas, out, status, b0, b1):
    """Independent sine dwells b0 <= b < b1, one after the other without the GIL (the callers
    run slices on threads: :func:`taos.planar._parallel.run_each`): :func:`_sine_dwell_one` for
    entry b of ``amps`` (n_b,) [r] and ``freqs`` (n_b,) [Hz], with ``n_per_cycle``, ``n_settle``,
    ``n_meas`` (n_b,) int, into ``out[b]`` (n_b, n_y, 3) and ``status[b]`` (n_b,) int (-1 or
    the failing step); plant arrays, ``Cy``, ``fid``, ``fp``, ``avp`` as
    :func:`integrate_samples`."""
    for b in range(b0, b1):
        status[b] = _sine_dwell_one(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, amps[b], freqs[b],
                                    n_per_cycle[b], n_settle[b], n_meas[b], out[b])


# -- sparse, piecewise-constant plants, many runs in lockstep (Monte Carlo batches) ------------
#: rows of the lockstep kernels' sparse matrix after the n state rows, and columns of v after
#: the state and the external inputs (:func:`_rates_lanes`)
LANE_ROWS = ("command", "friction_rate", "applied_torque", "valve_command", "valve_flow", "load_pressure",
             "engine_angle", "engine_rate")
LANE_COLS = ("u", "friction_torque", "valve_excess", "flow_correction", "stop_torque")


@njit(cache=True, inline="always")
def _rows(ip, ix, mx, V, h0, h1, OUT, o0):
    """OUT[o0 + h - h0, :] = row h of the lanes' sparse matrix times V, for h0 <= h < h1."""
    nl = V.shape[1]
    for h in range(h0, h1):
        o = o0 + h - h0
        for q in range(nl):
            OUT[o, q] = 0.0
        for k in range(ip[h], ip[h + 1]):
            col = ix[k]
            for q in range(nl):
                OUT[o, q] += mx[k, q] * V[col, q]


@njit(cache=True, inline="always")
def _rates_lanes(Z, ip, ix, mx, H, fidl, fp, AVP, V, C, S, U, TF, DZ, DX):
    """The state equations of the module docstring for R independent plants ("lanes") at once,
    every linear part as one sparse matrix with a pattern common to all lanes.

    ``V`` (n + n_r + 5, R) holds the lanes' states [x] in rows 0..n-1 and external inputs [r]
    in rows n..n+n_r-1 on entry; ``Z`` (R,) [rad] the friction states. The CSR matrix (``ip``,
    ``ix``; entries ``mx`` (nnz, R), one column per lane) acts on v = (x, r, u, T_f, e_v, c_q,
    T_stop) (:data:`LANE_COLS`): rows 0..n-1 give dx/dt = [A Br bc bf uv_in flow_in stop_in] v;
    the rows after them (:data:`LANE_ROWS`) the pre-avionics command c = [cc dc] (x, r), the
    friction relative rate w = cw x, the applied torque T_a = ca x, then the limit rows of
    :mod:`taos.planar.saturation` over (x, u): valve command u_v, valve flow q, load pressure
    P_L, engine angle and rate. Per lane: u = avionics(c) (``_avionics_kernels.apply_lanes``
    with ``AVP`` (AV_TABLE + 2 m, R), the lanes' packs by slot), (dz/dt, T_f) = friction(w, z,
    T_a) (``fidl`` the law's lane form ``rates_lanes``, ``fp`` (R, NPARAM) each lane's pack), the valve excess e_v,
    the flow correction c_q and the stop torque T_stop from the lane variants of the laws of
    :mod:`taos.planar.saturation` with ``H`` (N_HEAD, R) the lanes' packed heads by slot (all
    off: zeros). Writes dx/dt into ``DX`` (n, R), u [rad] into ``U``, T_f [N m] into ``TF``,
    dz/dt [rad/s] into ``DZ`` (R,) and rows n+n_r.. of ``V``; ``C`` (8, R), ``S`` (2, R)
    scratch.

    The loops over lanes are element-wise (no sum across lanes), so a lane's result does not
    depend on R or on its position: compiled without fast-math, vector and scalar code give the
    same bits. The avionics and the limit laws are vector loops across the lanes (branches as
    selects); the friction law is its lane form (one callback for all the lanes, the scalar law
    inlined in its loop: lane q's bits are those of ``rates`` at lane q,
    :data:`taos.friction.registry.LANES_SIG`)."""
    n = DX.shape[0]
    iu = V.shape[0] - 5
    nl = V.shape[1]
    _rows(ip, ix, mx, V, n, n + 3, C, 0)
    _av.apply_lanes(C[0], AVP, S, U)
    fidl(C[1], Z, C[2], fp, DZ, TF)
    for q in range(nl):
        V[iu, q] = U[q]
        V[iu + 1, q] = TF[q]
    _rows(ip, ix, mx, V, n + 3, n + 8, C, 3)
    _lim.valve_excess_lanes(H, C[3], V[iu + 2])
    _lim.pressure_flow_correction_lanes(H, C[4], C[5], V[iu + 3])
    _lim.stop_torque_lanes(H, C[6], C[7], V[iu + 4])
    _rows(ip, ix, mx, V, 0, n, DX, 0)


@njit(cache=True, inline="always")
def lanes_by_slot(head):
    """The lanes' packed limit heads (n_seg, R, N_HEAD) by slot, (n_seg, N_HEAD, R): contiguous
    across lanes (vector loads)."""
    nseg, nl, nh = head.shape
    H = np.empty((nseg, nh, nl))
    for s in range(nseg):
        for j in range(nh):
            for q in range(nl):
                H[s, j, q] = head[s, q, j]
    return H


@njit(cache=True, inline="always")
def lanes_jump(X, jdst, jsrc, jcoef, kick, seg):
    """The state jumps at the start of segment ``seg`` (:func:`integrate_segments_lanes`)."""
    n, nl = X.shape
    for j in range(jdst.shape[0]):
        for q in range(nl):
            X[jdst[j], q] += jcoef[seg, j, q] * X[jsrc[j], q]
    for i in range(n):
        for q in range(nl):
            X[i, q] += kick[seg, i, q]


@njit(cache=True, inline="always")
def lanes_record(X, Z, TF, U, x_out, aux_out, rec):
    """Record ``rec``: the states, T_f [N m], z [rad] and u [rad] of every lane."""
    n, nl = X.shape
    for i in range(n):
        for q in range(nl):
            x_out[rec, i, q] = X[i, q]
    for q in range(nl):
        aux_out[rec, AUX_TF, q] = TF[q]
        aux_out[rec, AUX_Z, q] = Z[q]
        aux_out[rec, AUX_U, q] = U[q]


@njit(cache=True, inline="always")
def lanes_failed(X, Z, OK, status, step):
    """Mark ``step`` in ``status`` for every lane whose state has just become non-finite;
    returns how many did. x * 0 is 0 for a finite x and NaN otherwise: one vector pass finds them."""
    n, nl = X.shape
    for q in range(nl):
        OK[q] = Z[q] * 0.0
    for i in range(n):
        for q in range(nl):
            OK[q] += X[i, q] * 0.0
    dead = 0
    for q in range(nl):
        if status[q] < 0 and not OK[q] == 0.0:
            status[q] = step
            dead += 1
    return dead


@njit(cache=True, error_model="numpy")  # x / 0 -> inf or NaN (the selects discard them), no exception
def integrate_segments_lanes(ip, ix, mx, head, fidl, fp, avp, bounds, jdst, jsrc, jcoef, kick, x0, z0, r, dt,
                             rec_every, x_out, aux_out, status):
    """RK4 (as :func:`integrate_samples`) of R independent runs in lockstep ("lanes"), each
    through a sequence of plants held over segments of steps, all in one sparse pattern.

    Parameters
    ----------
    ip, ix : (n + 9,), (nnz,) int64
        CSR row pointers and column indices of the lanes' matrix (:func:`_rates_lanes`: n
        state rows, then :data:`LANE_ROWS`, over v = (x, r, :data:`LANE_COLS`)).
    mx : (n_seg, nnz, R) float64
        The matrix entries of each segment's plant, per lane (units as A, Br, bc, ..., ca and
        the limit rows and columns of :mod:`taos.planar.saturation`).
    head : (n_seg, R, N_HEAD) float64
        The packed limits' head (slots ``LIM_*``; zeros: no limits).
    fidl : friction law lane kernel; fp : (n_seg, R, NPARAM) float64; avp : (R, .) float64
        The law's lane form ``rates_lanes`` (registry ``LANES_SIG``: ``rates`` of the module
        docstring over all the lanes in one call), each segment's and lane's packed friction
        parameters (a level following the thrust: :mod:`taos.flight.friction_env`) and packed
        avionics.
    bounds : (n_seg + 1,) int64
        Segment s covers steps bounds[s] .. bounds[s + 1]; bounds[0] = 0, bounds[-1] = n_steps.
    jdst, jsrc : (m_j,) int64; jcoef : (n_seg, m_j, R) float64; kick : (n_seg, n, R) [x]
        State jumps at the start of segment s: x[jdst[j]] += jcoef[s, j] x[jsrc[j]] (a state
        re-based on a change of plant), then x += kick[s].
    x0 : (n, R) float64; z0 : (R,) float64
        Initial states [x], [rad] (not modified).
    r : (R, n_steps + 1, n_r) float64
        External input samples [r] of each lane, linearly interpolated between samples.
    dt : float
        Step [s].
    rec_every : int
        Record every that many steps.
    x_out : (n_steps // rec_every + 1, n, R) float64
        Receives the states at the records (at a segment start: after its jumps).
    aux_out : (n_steps // rec_every + 1, N_AUX, R) float64
        Receives (T_f [N m], z [rad], u [rad]) (``AUX_*``).
    status : (R,) int64
        Receives -1 or the index of the step at which that lane's state became non-finite (a
        failed lane runs on, its numbers meaningless; all failed: the integration stops).

    No fast-math: a lane's numbers are the same for any R and any position among the lanes.
    """
    n, nl = x0.shape
    nr = r.shape[2]
    X, Z = x0.copy(), z0.copy()
    K, D = np.empty((4, n, nl)), np.empty((4, nl))   # the stages' derivatives k1..k4 [x/s] and dz/dt [rad/s]
    ZT, U, TF = np.empty(nl), np.empty(nl), np.empty(nl)
    R0, RM, R1 = np.empty((nr, nl)), np.empty((nr, nl)), np.empty((nr, nl))
    V = np.zeros((n + nr + 5, nl))  # rows 0..n-1: the stage's state, then its inputs (_rates_lanes)
    C, S, OK = np.empty((8, nl)), np.empty((2, nl)), np.empty(nl)
    # the lanes' limit heads and avionics packs by slot (contiguous across lanes: vector loads)
    H = lanes_by_slot(head)
    AVP = np.ascontiguousarray(avp.T)
    return _lanes_steps(ip, ix, mx, H, fidl, fp, AVP, bounds, jdst, jsrc, jcoef, kick, r, dt, rec_every, x_out, aux_out,
                        status, X, Z, K, D, ZT, U, TF, R0, RM, R1, V, C, S, OK)


@njit(cache=True, _nrt=False)
def _lanes_steps(ip, ix, mx, H, fidl, fp, AVP, bounds, jdst, jsrc, jcoef, kick, r, dt, rec_every, x_out, aux_out,
                 status, X, Z, K, D, ZT, U, TF, R0, RM, R1, V, C, S, OK):
    """The steps of :func:`integrate_segments_lanes` (its arguments, ``H``, ``AVP`` by slot; ``X``
    (n, R) [x], ``Z`` (R,) [rad] the states, advanced in place; the rest its scratch); returns
    the lanes still finite. Without numba's reference counting (``_nrt=False``; no allocation
    here): every array an inlined callee binds per stage cost an atomic ``NRT_incref`` and
    ``NRT_decref`` its pruning left in the loop, 22 % of the run (benchmarks/RESULTS.md, lanesnrt)."""
    n, nl = X.shape
    nseg, nsteps, nr = bounds.shape[0] - 1, r.shape[1] - 1, r.shape[2]
    status[:] = -1
    alive, rec, seg = nl, 0, 0
    M, L, F = mx[0], H[0], fp[0]
    h2 = 0.5 * dt
    for k in range(nsteps + 1):
        if seg < nseg and k == bounds[seg]:
            lanes_jump(X, jdst, jsrc, jcoef, kick, seg)
            M, L, F = mx[seg], H[seg], fp[seg]
            seg += 1
        k1n = min(k + 1, nsteps)
        for j in range(nr):
            for q in range(nl):
                R0[j, q] = r[q, k, j]
                R1[j, q] = r[q, k1n, j]
        for j in range(nr):
            for q in range(nl):
                RM[j, q] = 0.5 * (R0[j, q] + R1[j, q])
        # the four stages through ONE inlined copy of _rates_lanes (not four: the cold compile; not
        # out of line: its ~130 scalar arguments, 6 % of the run; benchmarks/RESULTS.md, compile2)
        for st in range(4):
            if st == 0:   # the derivative at the step start (k1), with T_f and u there for the record
                for j in range(nr):
                    for q in range(nl):
                        V[n + j, q] = R0[j, q]
                for i in range(n):
                    for q in range(nl):
                        V[i, q] = X[i, q]
                for q in range(nl):
                    ZT[q] = Z[q]
            else:
                if st == 1 or st == 3:
                    for j in range(nr):
                        for q in range(nl):
                            V[n + j, q] = RM[j, q] if st == 1 else R1[j, q]
                c = dt if st == 3 else h2
                for i in range(n):
                    for q in range(nl):
                        V[i, q] = X[i, q] + c * K[st - 1, i, q]
                for q in range(nl):
                    ZT[q] = Z[q] + c * D[st - 1, q]
            _rates_lanes(ZT, ip, ix, M, L, fidl, F, AVP, V, C, S, U, TF, D[st], K[st])
            if st == 0:
                if k % rec_every == 0:
                    lanes_record(X, Z, TF, U, x_out, aux_out, rec)
                    rec += 1
                if k == nsteps:
                    break
        if k == nsteps:
            break
        for i in range(n):
            for q in range(nl):
                X[i, q] += dt * (K[0, i, q] + 2.0 * K[1, i, q] + 2.0 * K[2, i, q] + K[3, i, q]) / 6.0
        for q in range(nl):
            Z[q] = Z[q] + dt * (D[0, q] + 2.0 * D[1, q] + 2.0 * D[2, q] + D[3, q]) / 6.0
        alive -= lanes_failed(X, Z, OK, status, k + 1)
        if alive == 0:
            break
    return alive
