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

from . import _expstep as _ex
from . import saturation as _lim

#: friction-loop step criterion: h max |lambda(M)| <= KAPPA (module docstring)
KAPPA = 0.5
#: largest step of an exponential dwell [s] (the measurement's sampling; module docstring)
H_MAX_S = 0.01
#: orbit samples per cycle for the friction-loop rates
N_ORBIT = 1024
#: a stencil side whose one half changes the law more than this many times the other holds a
#: jump (:func:`_jumps`); a smooth law's halves agree to ~1e-3 at these stencils
JUMP_RATIO = 8.0


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


def orbit(A: np.ndarray, b_cmd: np.ndarray, amp: float, freq: float) -> np.ndarray:
    """Complex amplitude X (n,) of the linear steady orbit x = Im(X e^{j w t}) of x' = A x +
    b_cmd r, r = amp sin(2 pi freq t) (``amp`` [r], ``freq`` [Hz])."""
    w = 2 * math.pi * freq
    return np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, b_cmd) * amp


def limits_rate(lim: np.ndarray, uv, theta, q, p):
    """The supply-pressure law's rate (4 beta / V_t) |q| g'(d) / P_s [1/s] (module docstring)
    at the peak magnitudes (or samples) of the valve command ``uv`` [m/s], engine angle
    ``theta`` [rad], valve flow ``q`` [m/s] and load pressure ``p`` [Pa] of a linear orbit
    (scalars or arrays; 0 without a pressure limit), or None where the orbit reaches the
    valve's rate limit or the hard stops (packed limits ``lim``:
    :mod:`taos.planar.saturation`)."""
    m = _lim.n_limit_states(lim)
    vmax, ps, thmax = lim[_lim.LIM_VMAX], lim[_lim.LIM_PS], lim[_lim.LIM_THMAX]
    if vmax > 0 and np.any(uv >= vmax):
        return None
    if thmax > 0 and np.any(theta >= thmax):
        return None
    if not ps > 0:
        return np.zeros_like(np.asarray(q, float))
    d = np.maximum(1.0 - p / ps, lim[_lim.LIM_EPS])
    flow_in = lim[_lim.row_start(_lim.ROW_FLOW_IN, m):_lim.row_start(_lim.ROW_FLOW_IN + 1, m)]
    return float(np.max(np.abs(flow_in))) * q / (2.0 * np.sqrt(d) * ps)


def dwell_step_s(args, model, amp: float, freq: float, fixed_dt_s: float) -> tuple[float, str]:
    """The ETDRK4 step [s] for one dwell of ``amp`` [r] at ``freq`` [Hz] (module docstring) and
    what set it (``"friction"``, ``"pressure"``, ``"limits"``, ``"sampling"``). ``args``: the
    plant arrays of :func:`taos.planar.simulate.kernel_args`; ``fixed_dt_s`` the fixed step
    kept where the limits are reached [s]."""
    from ..friction._kernels import prescribed_rate_response

    A, Br, bc, bf, cc, dc, cw, ca, lim = (args.A, args.Br, args.bc, args.bf, args.cc, args.dc, args.cw, args.ca,
                                          args.lim)
    X = orbit(A + np.outer(bc, cc), Br.sum(axis=1) + bc * dc.sum(), amp, freq)
    ph = 2 * math.pi * np.arange(2 * N_ORBIT) / N_ORBIT
    xs = np.imag(X[None, :] * np.exp(1j * ph)[:, None])       # (2 N, n) over two cycles
    w = xs @ cw
    ta = xs @ ca
    fp, fid = model.friction.pack(), model.friction.entry.rates
    _, z = prescribed_rate_response(fid, fp, np.ascontiguousarray(w), 1.0 / (freq * N_ORBIT), 0.0)
    sl = np.arange(N_ORBIT, 2 * N_ORBIT, N_ORBIT // 64)
    # and the rate reversals, where a regularised law is stiffest (a smooth Coulomb law's slope
    # T_c / v_eps at w = 0 is a spike far narrower than the 64 samples' spacing)
    c2 = w[N_ORBIT:2 * N_ORBIT]
    rev = N_ORBIT + np.flatnonzero(np.signbit(c2[:-1]) != np.signbit(c2[1:]))
    ws = np.concatenate([w[sl], np.zeros(rev.size)])
    rho = _friction_rate(fid, fp, np.ascontiguousarray(ws), np.ascontiguousarray(ta[np.r_[sl, rev]]),
                         np.ascontiguousarray(z[np.r_[sl, rev]]), float(cw @ bf), float(ca @ bf))
    why = "friction"
    if lim.size:
        m = _lim.n_limit_states(lim)
        row = lambda r: lim[_lim.row_start(r, m):_lim.row_start(r + 1, m)]  # noqa: E731
        rp = limits_rate(lim, np.abs(row(_lim.ROW_UV) @ X + lim[_lim.LIM_KVR] * amp * dc.sum()),
                         np.abs(row(_lim.ROW_THETA) @ X), np.abs(row(_lim.ROW_Q) @ X), np.abs(row(_lim.ROW_P) @ X))
        if rp is None:
            return fixed_dt_s, "limits"
        if rp > rho:
            rho, why = rp, "pressure"
    h = KAPPA / rho if rho > 0 else math.inf
    if h >= H_MAX_S:
        return H_MAX_S, "sampling"
    return h, why


def steps_per_cycle(h_s: float, freq: float, min_steps_per_cycle: int) -> int:
    """Steps a cycle for a step of at most ``h_s`` [s] at ``freq`` [Hz]: at least
    ``min_steps_per_cycle``, a multiple of 4."""
    n = max(int(math.ceil(1.0 / (freq * h_s))), min_steps_per_cycle)
    return int(4 * math.ceil(n / 4))


def step_tables(A: np.ndarray, bc: np.ndarray, dts: np.ndarray):
    """Coefficients for the steps ``dts`` [s] (one entry per dwell): the ETDRK4 matrices
    (:func:`taos.planar._expstep.etd_coefficients`) and command tables, each built once per
    distinct step and stacked. Returns ((E, E2, P2, F1, F2, F3) stacks (k, n, n), G, D
    (k, M + 1, n), tab_m (k,) int64, idx (len(dts),) int64: the stack entry of each dwell)."""
    uniq, inv = np.unique(dts, return_inverse=True)
    ms = np.array([_ex.table_nodes(A, 0.5 * h) for h in uniq], np.int64)  # each step's own table
    co = [_ex.etd_coefficients(A, float(h)) for h in uniq]
    stack = tuple(np.ascontiguousarray(np.stack([c[i] for c in co])) for i in range(6))
    G = np.zeros((uniq.size, ms.max() + 1, A.shape[0]))
    D = np.zeros_like(G)
    for i, h in enumerate(uniq):
        G[i, :ms[i] + 1], D[i, :ms[i] + 1] = _ex.command_table(A, bc, 0.5 * float(h), int(ms[i]))
    return stack, G, D, ms, inv.astype(np.int64).ravel()


def run_dwells(args, Cy, kern, amps, freqs, npc, n_settle, n_meas, out, status):
    """ETDRK4 dwells (:func:`taos.planar._expstep.dwell_batch`) for ``npc`` steps a cycle each
    (coefficients from :func:`step_tables`), one per task on the threads, the longest first
    (:func:`taos.planar._parallel.run_each`)."""
    from ._parallel import run_each

    stack, G, D, ms, idx = step_tables(args.A, args.bc, 1.0 / (freqs * npc))
    run_each(lambda b: _ex.dwell_batch(*args, Cy, *kern, *stack, G, D, ms, idx, idx, amps, freqs, npc, n_settle,
                                       n_meas, out, status, b, b + 1), n_settle + n_meas)


def exp_steps_per_cycle(args, model, inertia_kgm2: float, amps, freqs, fixed_dt_s: float,
                        min_steps_per_cycle: int) -> np.ndarray:
    """Steps a cycle (int64, multiples of 4) of ETDRK4 dwells at ``amps`` [r] x ``freqs`` [Hz]
    (paired): the step of :func:`dwell_step_s` (``fixed_dt_s`` [s] where the limits are
    reached), halved until the friction law's own explicit-step rule accepts it
    (:meth:`taos.friction.FrictionLaw.check_step`: the switching Coulomb law's stick band)."""
    from ..errors import InputError

    out = np.empty(len(amps), np.int64)
    memo: dict[float, float] = {}
    for i, (a, f) in enumerate(zip(amps, freqs)):
        h, _ = dwell_step_s(args, model, float(a), float(f), fixed_dt_s)
        if h not in memo:
            hh = h
            for _ in range(60):
                try:
                    model.friction.check_step(inertia_kgm2, hh, model.source)
                    break
                except InputError:
                    hh *= 0.5
            memo[h] = hh
        out[i] = steps_per_cycle(memo[h], float(f), min_steps_per_cycle)
    return out
