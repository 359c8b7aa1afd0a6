"""Exponential (ETDRK4) time-domain runs of arbitrary command profiles on the planar plant.

The scheme is the one of :mod:`taos.planar._expstep` (its module docstring has the equations:
the linear block exactly through phi-functions, the quantised command's staircase exactly
through the tabulated g(tau), the friction and limits by the ETDRK4 stages of Cox & Matthews,
J. Comput. Phys. 176 (2002) 430, eq. (26)); this module only changes what drives it and how
the step is chosen:

* **The command.** ``taos.planar.simulate.simulate`` samples the profile every ``dt_s``
  (the RK4 kernel's step) and the RK4 kernel interpolates the samples linearly; here the
  command c(t) [rad] IS that piecewise-linear function of the same samples, so both
  integrators solve the same problem. With a quantiser the avionics output u = avionics(c)
  is a staircase whose level-crossing times are solved exactly on each linear piece,
  tau = t_k + (level - c_k) dt_s / (c_{k+1} - c_k) (:func:`stair_pwl`), and its response
  u0 g(H) + sum du_j g(H - tau_j) is exact whatever the command does inside the step. Without
  one, b_c u(t) is carried in the ETDRK4 stages (fourth order for a smooth command), and the
  samples next to each profile breakpoint (a step edge, a ramp corner, a segment's end:
  :func:`breakpoints`) are made step boundaries, so no kink of the command lies inside a step.
* **The step** h = j dt_s (an integer j) from the physics that needs it (the rules of
  :mod:`taos.planar._expplan`, applied along the run instead of along a dwell's orbit): the
  linear block's response to the profile (friction off, an upper bound on the engine rate:
  friction only slows the engine) is computed exactly every :data:`PLAN_DT_S`
  (:func:`linear_orbit`, first-order hold); along it the friction loop's rate
  max |lambda(M)| (:func:`taos.planar._expplan._friction_rate`, the friction state from the
  law driven by that rate) and the supply-pressure law's rate give, per record interval (and
  its neighbours), h <= :data:`taos.planar._expplan.KAPPA` / rate; h <= H_MAX_S; h within the
  friction law's own explicit-step rule (halved until
  :meth:`taos.friction.FrictionLaw.check_step` accepts it); h <= the record interval
  ``record_every`` dt_s, every record time a step boundary, so the records land on the grid
  t = k dt_s record_every of the RK4 path (same TimeHistory, same contracts; a record is the
  state at the boundary, and T_f, z and u = avionics(c) there).
* **Reversals.** Where the engine rate w = c_w . x or the valve flow q changes sign, N is only
  continuous (the friction law's |w|, the supply-pressure law's sgn(q)) and the scheme's
  order drops; with friction the reversals (stick-slip) are not where the linear orbit has
  them. So a step across which w or q changes sign is retaken sample by sample (step dt_s,
  the RK4 path's; :data:`RETAKE_REVERSALS`). On the hot-fire Green Run (modified LuGre,
  records every 2 ms) this took the engine error against RK4 at 2.5e-5 s from 1.3e-4 / 1.7e-4
  deg (pitch / yaw) to 6.2e-5 / 6.6e-5, below the RK4 kernel's 6.8e-5 / 1.8e-4 at 2e-4 s
  (``benchmarks/bench_exptime_accuracy.py``).
* **Where it does not apply** (:func:`plan_run` returns the reason, and
  :func:`integrate_plant_exp` runs the RK4 kernel of :mod:`taos.planar.dynamics` instead):
  a command that depends on the state (c_c != 0: it is then not known in advance), more than
  one external input, a linear orbit that reaches the valve's rate limit or the hard stops
  (the clipped valve loop and the contact are then the fast physics, as for dwells in
  :mod:`taos.planar._expplan`), and, without a quantiser, a profile whose breakpoints are not
  known (:func:`breakpoints` returns None).

An unstable run raises :class:`taos.errors.SimulationUnstable` with the end time of the step
whose state became non-finite.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from . import _avionics_kernels as _av
from . import _expplan as _pl
from . import _expstep as _ex
from ._avionics_slots import AV_LSB

_FM = _ex._FM
#: spacing of the planning samples along the linear orbit [s] (rounded to whole samples):
#: resolves the 100 Hz valve's rise and the load mode
PLAN_DT_S = 1e-3
#: what bounds a run's steps (:class:`RunPlan`): the friction loop's rate, the supply-pressure
#: law's, H_MAX_S (the measurement's sampling), the friction law's explicit-step rule, a
#: breakpoint of the command, the record interval
SET_BY = ("friction", "pressure", "sampling", "friction step rule", "breakpoints", "record")
#: retake a step across which the engine rate or the valve flow changes sign sample by sample
#: (:func:`profile_steps_exp`)
RETAKE_REVERSALS = True


@njit(cache=True, fastmath=_FM)
def stair_pwl(G, D, H, M, cs, p0, p1, dt, avp, out):
    """out = the staircase's response over one half step (:mod:`taos.planar._expstep`, part 2)
    for the command c (rad) linear between the samples ``cs`` (n,) taken every ``dt`` [s], from
    position ``p0`` to ``p1`` [samples] (p1 - p0 = H / dt); ``G``, ``D``, ``M``: the command
    table of :func:`taos.planar._expstep.command_table` on [0, ``H``]. Returns the avionics
    output u [rad] at the end."""
    for k in range(out.shape[0]):
        out[k] = 0.0
    lsb2 = 0.5 * avp[AV_LSB]
    last = cs.shape[0] - 2
    i = min(int(math.floor(p0)), last)
    pa = p0
    u = 0.0
    first = True
    while True:
        pb = min(p1, i + 1.0) if i < last else p1
        dcs = cs[i + 1] - cs[i]
        ca = cs[i] + (pa - i) * dcs
        cb = cs[i] + (pb - i) * dcs
        up = cb > ca
        dj = 1 if up else -1
        q = ca / lsb2
        j = math.floor(q) if up else math.ceil(q)
        # the band the piece starts in (in its direction of motion) and its output
        ub = _av.apply(ca, avp) if cb == ca else _av.apply((j + 0.5 * dj) * lsb2, avp)
        ta = (pa - p0) * dt
        if first:
            u = ub
            _ex._g_at(G, D, H, M, H, out, u)
            first = False
        elif ub != u:
            _ex._g_at(G, D, H, M, H - ta, out, ub - u)
            u = ub
        if cb != ca:
            tpc = (pb - pa) * dt / (cb - ca)      # time per unit command on this piece
            while True:
                j += dj
                lev = j * lsb2
                if (up and lev >= cb) or ((not up) and lev <= cb):
                    break
                un = _av.apply(lev + 0.5 * dj * lsb2, avp)
                if un != u:
                    _ex._g_at(G, D, H, M, H - (ta + (lev - ca) * tpc), out, un - u)
                    u = un
        if pb >= p1:
            break
        pa = pb
        i += 1
    return u


@njit(cache=True, fastmath=_FM, inline="always")
def _at(cs, p):
    """The command samples ``cs`` linearly interpolated at position ``p`` [samples]."""
    i = min(int(math.floor(p)), cs.shape[0] - 2)
    return cs[i] + (p - i) * (cs[i + 1] - cs[i])


@njit(cache=True, fastmath=_FM, nogil=True)
def profile_steps_exp(A, Br, bc, bf, cc, dc, cw, ca, lim, Cy, fid, fp, avp, E, E2, P2, F1, F2, F3, G, D, tab_m, slot,
                      pos, r, dt, rec_every, x0, z0, y_out, aux_out, qrow, one):
    """ETDRK4 steps (:func:`taos.planar._expstep.etdrk4_step`) between the sample positions
    ``pos`` (n_steps + 1,) int64 (pos[0] = 0, every multiple of ``rec_every`` among them) of
    the external input ``r`` (n_samples,) [r] sampled every ``dt`` [s] and linear between
    samples (one channel; c = dc . r). Step k uses the coefficients ``E[slot[k]]`` ..
    ``F3[slot[k]]`` and the command table ``G[slot[k]]``, ``D[slot[k]]`` (its first
    ``tab_m[slot[k]]`` + 1 rows) of the step (pos[k + 1] - pos[k]) dt
    (:func:`taos.planar._expplan.step_tables`). Records at every sample multiple of
    ``rec_every`` as :func:`taos.planar.dynamics.integrate_samples` (``y_out`` = Cy x,
    ``aux_out`` T_f, z, u). From ``x0`` (n,) [x], ``z0`` [rad]. Returns -1 or the sample
    index at the end of the step whose state became non-finite. A step across which the
    engine rate cw . x or the valve flow ``qrow`` . x (zeros: none) changes sign is retaken
    sample by sample with the coefficient set ``one`` (the step dt; -1: not retaken).
    Plant arrays: as :mod:`taos.planar.dynamics`."""
    n = x0.shape[0]
    dcs = 0.0
    for j in range(dc.shape[0]):
        dcs += dc[j]
    stair = avp[AV_LSB] > 0.0
    x = x0.copy()
    z = z0
    Nu, Na, Nb, Nc = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    a, b, c, xn, tmp = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    g1 = np.zeros(n)
    g2 = np.zeros(n)
    xs = np.empty(n)
    cmd = r * dcs
    u0 = _av.apply(cmd[0], avp)
    rec = 0
    nst = pos.shape[0] - 1
    for k in range(nst + 1):
        p = pos[k]
        if p % rec_every == 0:
            w = 0.0
            ta = 0.0
            for i in range(n):
                w += cw[i] * x[i]
                ta += ca[i] * x[i]
            _, tf = fid(w, z, ta, fp)
            for o in range(Cy.shape[0]):
                s = 0.0
                for i in range(n):
                    s += Cy[o, i] * x[i]
                y_out[rec, o] = s
            aux_out[rec, 0] = tf
            aux_out[rec, 1] = z
            aux_out[rec, 2] = _av.apply(cmd[p], avp)
            rec += 1
        if k == nst:
            break
        p1 = pos[k + 1]
        w0 = _dot(cw, x)
        q0 = _dot(qrow, x)
        for i in range(n):
            xs[i] = x[i]
        zs, us = z, u0
        z, u1, ok = _step(p, p1, slot[k], x, z, u0, stair, cmd, r, dt, avp, A, Br, bc, bf, cw, ca, lim, fid, fp,
                          E, E2, P2, F1, F2, F3, G, D, tab_m, g1, g2, Nu, Na, Nb, Nc, a, b, c, xn, tmp)
        if ok and one >= 0 and p1 - p > 1 and ((w0 < 0.0) != (_dot(cw, x) < 0.0) or (q0 < 0.0) != (_dot(qrow, x) < 0.0)):
            # the engine rate or the valve flow reversed inside the step: N is only continuous
            # there; retake the step sample by sample
            for i in range(n):
                x[i] = xs[i]
            z, u1 = zs, us
            for pp in range(p, p1):
                z, u1, ok = _step(pp, pp + 1, one, x, z, u1, stair, cmd, r, dt, avp, A, Br, bc, bf, cw, ca, lim, fid,
                                  fp, E, E2, P2, F1, F2, F3, G, D, tab_m, g1, g2, Nu, Na, Nb, Nc, a, b, c, xn, tmp)
                if not ok:
                    return pp + 1
        u0 = u1
        if not ok:
            return p1
    return -1


@njit(cache=True, fastmath=_FM, inline="always")
def _dot(v, x):
    s = 0.0
    for i in range(v.shape[0]):
        s += v[i] * x[i]
    return s


@njit(cache=True, fastmath=_FM)
def _step(p, p1, o, x, z, u0, stair, cmd, r, dt, avp, A, Br, bc, bf, cw, ca, lim, fid, fp, E, E2, P2, F1, F2, F3, G, D,
          tab_m, g1, g2, Nu, Na, Nb, Nc, a, b, c, xn, tmp):
    """One ETDRK4 step from sample ``p`` to ``p1`` with the coefficient set ``o`` (as
    :func:`profile_steps_exp`), in place on ``x``; returns (z [rad], u at the end [rad], all
    finite)."""
    h = (p1 - p) * dt
    H = 0.5 * h
    M = tab_m[o]
    pm = p + 0.5 * (p1 - p)
    if stair:
        um = stair_pwl(G[o], D[o], H, M, cmd, float(p), pm, dt, avp, g1)
        u1 = stair_pwl(G[o], D[o], H, M, cmd, pm, float(p1), dt, avp, g2)
    else:
        u0 = _av.apply(cmd[p], avp)
        um = _av.apply(_at(cmd, pm), avp)
        u1 = _av.apply(cmd[p1], avp)
    z, ok = _ex.etdrk4_step(x, z, r[p], _at(r, pm), r[p1], u0, um, u1, stair, g1, g2, A, Br, bc, bf, cw, ca, lim, fid,
                            fp, E[o], E2[o], P2[o], F1[o], F2[o], F3[o], h, Nu, Na, Nb, Nc, a, b, c, xn, tmp)
    return z, u1, ok


@njit(cache=True)
def linear_orbit(E, P1, P2, cs, every, xs):
    """The linear block's exact response x' = A x + b c(t) from rest to the command ``cs``
    (n_samples,) linear between samples (first-order hold: x+ = E x + h phi_1 b c_k + h phi_2
    b (c_{k+1} - c_k) with ``E`` = e^{hA}, ``P1`` = h phi_1(hA) b, ``P2`` = h phi_2(hA) b), its
    state every ``every`` samples into ``xs`` (n_samples // every + 1, n)."""
    # element loops, no array-to-array slice assignment (its shape check's exception message
    # costs 5 s of compile)
    n = E.shape[0]
    x = np.zeros(n)
    xn = np.empty(n)
    for i in range(n):
        xs[0, i] = 0.0
    for k in range(cs.shape[0] - 1):
        for i in range(n):
            s = P1[i] * cs[k] + P2[i] * (cs[k + 1] - cs[k])
            for j in range(n):
                s += E[i, j] * x[j]
            xn[i] = s
        for i in range(n):
            x[i] = xn[i]
        if (k + 1) % every == 0:
            for i in range(n):
                xs[(k + 1) // every, i] = x[i]


@njit(cache=True)
def point_rates(fid, fp, w, ta, z, cwbf, cabf, out):
    """The friction loop's rate max |lambda(M)| [1/s] (:func:`taos.planar._expplan._friction_rate`)
    at every sample of ``w`` [rad/s], ``ta`` [N m], ``z`` [rad] into ``out``, and at a rate
    reversal between samples k and k + 1 (w = 0, the stiffest point of a regularised law)
    also into ``out[k]``."""
    for k in range(w.shape[0]):
        out[k] = _pl._friction_rate(fid, fp, w[k:k + 1], ta[k:k + 1], z[k:k + 1], cwbf, cabf)
        if k + 1 < w.shape[0] and (w[k] < 0.0) != (w[k + 1] < 0.0):
            zero = np.zeros(1)
            out[k] = max(out[k], _pl._friction_rate(fid, fp, zero, ta[k:k + 1], z[k:k + 1], cwbf, cabf))


def breakpoints(profile, axis: int = 0) -> np.ndarray | None:
    """Times [s] where the ``axis``-th command of ``profile`` (:mod:`taos.profiles`) is not
    smooth (step edges, ramp corners, segment ends, record samples); None for a profile type
    this function does not know."""
    from .. import profiles as P

    if isinstance(profile, P.TwoAxis):
        return breakpoints(profile.yaw if axis else profile.pitch)
    if isinstance(profile, P.Circular):
        return np.array([1.0 / profile.frequency_hz, profile.duration_s])
    if isinstance(profile, P.Step):
        return np.array([profile.t0_s])
    if isinstance(profile, P.MultiRamp):
        return profile._knots()[0]
    if isinstance(profile, (P.SineDwell, P.SineSweep, P.Multisine)):
        return np.array([0.0, profile.duration_s])
    if isinstance(profile, P.Recorded):
        return np.asarray(profile.t_s, float)
    if isinstance(profile, P.Sequence):
        out, t0 = [], 0.0
        for part in profile.parts:
            b = breakpoints(part)
            if b is None:
                return None
            out += [b + t0, [t0, t0 + part.duration_s]]
            t0 += part.duration_s
        return np.concatenate(out)
    return None


@dataclass(frozen=True)
class RunPlan:
    """The steps of one exponential run: ``pos`` (n_steps + 1,) sample positions of the step
    boundaries, ``sizes`` the distinct step lengths [samples], ``slot`` (n_steps,) each step's
    index into ``sizes``; ``h_max_s`` the longest step [s] and ``set_by`` what bounds the
    most steps (one of :data:`SET_BY`)."""

    pos: np.ndarray
    sizes: np.ndarray
    slot: np.ndarray
    h_max_s: float
    set_by: str


def plan_run(args, model, inertia_kgm2: float, r: np.ndarray, dt_s: float, record_every: int,
             breaks: np.ndarray | None, max_step_s: float = math.inf, avp: np.ndarray | None = None) -> RunPlan | str:
    """The :class:`RunPlan` of an exponential run of the samples ``r`` (n,) [r] every ``dt_s``
    [s] with records every ``record_every`` samples (module docstring), or the reason it does
    not apply (a str). ``args``: :func:`taos.planar.simulate.kernel_args`; ``breaks``
    (:func:`breakpoints`) [s]; ``max_step_s`` [s] a further bound on the step (the
    step-refinement studies); ``avp`` the packed avionics (default the model's)."""
    with np.errstate(over="ignore", invalid="ignore"):    # an unstable plant: its orbit overflows
        return _plan(args, model, inertia_kgm2, r, dt_s, record_every, breaks, max_step_s, avp)


def _plan(args, model, inertia_kgm2, r, dt_s, record_every, breaks, max_step_s, avp):
    """:func:`plan_run`'s work."""
    from ..errors import InputError
    from . import saturation as _lim

    A, Br, bc, bf, cc, dc, cw, ca, lim = (args.A, args.Br, args.bc, args.bf, args.cc, args.dc, args.cw, args.ca,
                                          args.lim)
    stair = (model.avionics.pack() if avp is None else avp)[AV_LSB] > 0.0
    if np.any(cc != 0.0) or Br.shape[1] != 1:
        return "the command depends on the state or on several inputs"
    if not stair and breaks is None:
        return "no quantiser and a profile of unknown breakpoints"
    ns = r.shape[0] - 1
    # planning samples every q steps (PLAN_DT_S) along the linear orbit, first-order hold
    q = max(1, min(ns, int(round(PLAN_DT_S / dt_s))))
    rq = r[::q] if ns % q == 0 else np.append(r[::q], r[-1])
    hq = q * dt_s
    E, p1, p2, _ = _ex.phi_functions(A, hq)
    b = Br[:, 0] + bc * dc.sum()
    xs = np.empty((rq.size, A.shape[0]))
    linear_orbit(E, np.ascontiguousarray(hq * p1 @ b), np.ascontiguousarray(hq * p2 @ b),
                 np.ascontiguousarray(rq, float), 1, xs)
    w, ta = np.ascontiguousarray(xs @ cw), np.ascontiguousarray(xs @ ca)
    fid, fp = model.friction.entry.rates, model.friction.pack()
    from ..friction._kernels import prescribed_rate_response

    _, z = prescribed_rate_response(fid, fp, w, hq, 0.0)
    rho = np.empty(w.size)
    point_rates(fid, fp, w, ta, np.ascontiguousarray(z), float(cw @ bf), float(ca @ bf), rho)
    rho[~np.isfinite(z)] = np.inf      # the law diverged on the planning grid: its own rate is faster
    why = np.zeros(w.size, np.int64)               # what bounds each sample: an index into SET_BY
    if lim.size:
        m = _lim.n_limit_states(lim)
        row = lambda k: lim[_lim.row_start(k, m):_lim.row_start(k + 1, m)]  # noqa: E731
        cq = np.abs(rq * dc.sum())
        rp = _pl.limits_rate(lim, np.abs(xs @ row(_lim.ROW_UV) + lim[_lim.LIM_KVR] * cq), np.abs(xs @ row(_lim.ROW_THETA)),
                             np.abs(xs @ row(_lim.ROW_Q)), np.abs(xs @ row(_lim.ROW_P)))
        if rp is None:
            return "the linear orbit reaches the valve's rate limit or the hard stops"
        why[rp > rho] = 1
        rho = np.maximum(rho, rp)
    # per record interval: the planning samples in it and one either side
    nw = ns // record_every + (ns % record_every > 0)
    rho3 = np.maximum(rho, np.maximum(np.append(rho[1:], rho[-1]), np.insert(rho[:-1], 0, rho[0])))
    rw = np.maximum.reduceat(rho3, np.minimum(np.arange(nw) * record_every // q, rho3.size - 1))
    hmax = min(_pl.H_MAX_S, record_every * dt_s, max(max_step_s, dt_s))
    jmax = max(1, int(math.floor(hmax / dt_s + 1e-9)))
    for _ in range(60):
        try:
            model.friction.check_step(inertia_kgm2, jmax * dt_s, model.source)
            break
        except InputError:
            jmax = max(1, jmax // 2)
            if jmax == 1:
                break
    with np.errstate(divide="ignore"):
        jw = np.floor(_pl.KAPPA / (rw * dt_s))
    jw = np.clip(np.nan_to_num(jw, posinf=jmax), 1, jmax).astype(np.int64)
    # jmax halved as often as needed: a handful of distinct steps (each its own coefficients)
    jw = np.maximum(jmax >> np.ceil(np.log2(jmax / jw)).astype(np.int64), 1)
    # step boundaries: every record, and the samples either side of each breakpoint
    stops = [np.arange(0, ns + 1, record_every), [ns]]
    if not stair and breaks is not None:
        kb = np.floor(np.asarray(breaks, float) / dt_s).astype(np.int64)
        stops.append((kb[:, None] + np.arange(-1, 3)[None, :]).ravel())
    st = np.unique(np.clip(np.concatenate(stops), 0, ns))
    s0, L = st[:-1], np.diff(st)
    jm = jw[s0 // record_every]
    p = -(-L // jm)
    base, extra = L // p, L % p
    seg = np.repeat(np.arange(s0.size), p)
    i = np.arange(seg.size) - np.repeat(np.cumsum(p) - p, p)
    pos = np.append(s0[seg] + i * base[seg] + np.minimum(i, extra[seg]), ns).astype(np.int64)
    sizes, slot = np.unique(np.diff(pos), return_inverse=True)
    top = 3 if jmax * dt_s < hmax - 1e-12 else (5 if record_every * dt_s <= _pl.H_MAX_S else 2)
    code = np.where(jm == jmax, top, why[np.minimum(s0 // q, why.size - 1)])
    code = np.where((jm >= L) & (L < jmax), 4, code)       # a segment cut short by a breakpoint
    set_by = SET_BY[int(np.argmax(np.bincount(code, weights=p, minlength=len(SET_BY))))]
    return RunPlan(pos, sizes.astype(np.int64), slot.astype(np.int64).ravel(), float(sizes.max() * dt_s), set_by)


def integrate_plant_exp(plant, model, args, r: np.ndarray, dt_s: float, record_every: int, breaks, fallback,
                        max_step_s: float = math.inf):
    """:func:`taos.planar.simulate.integrate_plant` by ETDRK4 (module docstring) from rest, for
    the kernel arrays ``args`` of ``plant`` (:func:`taos.planar.simulate.kernel_args`) and the
    one-channel input samples ``r`` (n_steps + 1,) [r] every ``dt_s`` [s]; ``breaks`` [s]:
    :func:`breakpoints`; ``max_step_s``: :func:`plan_run`. Returns (y, aux, how): the records
    as ``integrate_plant``'s and a dict for the provenance (the longest step, what set most
    steps); where the scheme does not apply, ``fallback()`` (the RK4 run: (y, aux)) and the
    reason in ``how``."""
    r = np.ascontiguousarray(r, dtype=np.float64)
    out = run_exp(args, plant.ss.C, model, model.avionics.pack(), plant.inertia_kgm2, r, dt_s, record_every, breaks,
                  max_step_s)
    if isinstance(out, str):
        y, aux = fallback()
        return y, aux, {"method": "rk4-fixed-step", "exp_fallback": out}
    return out


def run_exp(args, Cy, model, avp, inertia_kgm2: float, r, dt_s: float, record_every: int, breaks=None,
            max_step_s: float = math.inf):
    """The ETDRK4 run of :func:`integrate_plant_exp` on the kernel arrays ``args``
    (:func:`taos.planar.simulate.kernel_args`), outputs ``Cy`` (n_y, n), the friction law of
    ``model`` and the packed avionics ``avp``; returns (y, aux, how), or the reason it does not
    apply (a str: nothing ran). Raises :class:`taos.errors.SimulationUnstable`."""
    from ..errors import SimulationUnstable
    from . import dynamics as _dy

    plan = plan_run(args, model, inertia_kgm2, r, dt_s, record_every, breaks, max_step_s, avp)
    if isinstance(plan, str):
        return plan
    model.friction.check_step(inertia_kgm2, plan.h_max_s, model.source)
    sizes = np.unique(np.append(plan.sizes, 1))          # and one sample: the retaken steps
    stack, G, D, ms, _ = _pl.step_tables(args.A, args.bc, sizes * dt_s)
    slot = np.searchsorted(sizes, plan.sizes)[plan.slot].astype(np.int64)
    lim = args.lim
    qrow = np.zeros(args.A.shape[0])
    if lim.size:
        from . import saturation as _lim

        m = _lim.n_limit_states(lim)
        qrow = np.ascontiguousarray(lim[_lim.row_start(_lim.ROW_Q, m):_lim.row_start(_lim.ROW_Q + 1, m)])
    n = r.shape[0] - 1
    nrec = n // record_every + 1
    y = np.empty((nrec, Cy.shape[0]))
    aux = np.empty((nrec, _dy.N_AUX))
    st = profile_steps_exp(*args, np.ascontiguousarray(Cy), model.friction.entry.rates, model.friction.pack(), avp,
                           *stack, G, D, ms, slot, plan.pos, r, dt_s, record_every, np.zeros(args.A.shape[0]),
                           0.0, y, aux, qrow, int(np.searchsorted(sizes, 1) if RETAKE_REVERSALS else -1))
    if st >= 0:
        raise SimulationUnstable(st * dt_s, f"{model.friction.name} friction, ETDRK4 step <= {plan.h_max_s:g} s")
    return y, aux, {"method": "etdrk4", "exp_max_step_s": plan.h_max_s, "exp_step_set_by": plan.set_by,
                    "exp_steps": int(plan.pos.size - 1)}
