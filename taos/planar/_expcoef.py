"""The Python side of the exponential (ETDRK4) dwells, numba-free: the coefficient matrices
(the phi-functions, the command table) and the step plan of each dwell, with the compiled work
done by a kernel set (:class:`KernelSet`): numba's kernels (:data:`taos.planar._expplan.NUMBA`)
or their C translation loaded with ctypes (:mod:`taos.planar._cdwell`), so that a dwell command
on the C path imports no numba. The equations are in :mod:`taos.planar._expstep` (the scheme)
and :mod:`taos.planar._expplan` (the step), which re-export these functions bound to numba's
kernels.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from . import _limits_pack as _lp

#: friction-loop step criterion: h max |lambda(M)| <= KAPPA (module docstring)
KAPPA = 0.5
#: largest step of an exponential dwell [s] (the measurement's sampling; module docstring)
H_MAX_S = 0.01
#: orbit samples per cycle for the friction-loop rates
N_ORBIT = 1024
#: a stencil side whose one half changes the law more than this many times the other holds a
#: jump (:func:`_jumps`); a smooth law's halves agree to ~1e-3 at these stencils
JUMP_RATIO = 8.0

#: the environment variable that makes a dwell command print, on stderr, the wall-clock time
#: (``time.time()``, s since the epoch) of its first kernel call and of that call's return (a
#: dwell's first kernel is the step plan's :func:`taos.friction._kernels.prescribed_rate_fill`):
#: ``benchmarks/bench_expstep.py --first-kernel`` subtracts the time it started the process
STAMP_ENV = "TAOS_STARTUP_STAMP"
_STAMPED: set = set()


def stamp(label: str) -> None:
    """Print ``taos-stamp LABEL TIME`` on stderr once a process when :data:`STAMP_ENV` is set."""
    import os

    if label not in _STAMPED and os.environ.get(STAMP_ENV):
        import sys
        import time

        _STAMPED.add(label)
        print(f"taos-stamp {label} {time.time():.6f}", file=sys.stderr, flush=True)


class KernelSet(Protocol):
    """The compiled kernels a dwell needs (one implementation per engine). ``name``: ``"numba"``
    or ``"c"`` (the results' ``solver.kernels`` provenance says which and how)."""

    name: str
    provenance: dict

    def expm(self, W: np.ndarray) -> np.ndarray:
        """exp(W) (:func:`taos.planar._expstep.expm_small`)."""

    def law(self, model):
        """The friction kernel to pass as ``fid`` (None where the kernels have it bound)."""

    def rate_response_z(self, fid, fp, v, dt, z0) -> np.ndarray:
        """The bristle state of :func:`taos.friction._kernels.prescribed_rate_response`."""

    def friction_rate(self, fid, fp, w, ta, z, cwbf, cabf) -> float:
        """:func:`taos.planar._expplan._friction_rate`."""

    def dwell_batch(self, *args) -> None:
        """:func:`taos.planar._expstep.dwell_batch` (its arguments)."""


#: cubic-Hermite table of the command response g: nodes so that dtau |A| <= this
TABLE_DTAU_NORM = 0.1


def _balance(L: np.ndarray) -> np.ndarray:
    """Diagonal scaling s (powers of 2) with S^-1 L S balanced: LAPACK's dgebal, job 'S' (no
    permutation), as scipy.linalg.matrix_balance(L, permute=False) calls it (LAPACK 3.5 and
    later: 2-norms of the rows and columns, the diagonal included; Parlett & Reinsch,
    Numer. Math. 13 (1969) 293), written out so that no scipy is imported on the C dwell path;
    tests/test_cdwell.py checks it against scipy on every shipped model."""
    A = np.array(L, float)
    n = A.shape[0]
    sfmin1 = np.finfo(float).tiny / (np.finfo(float).eps * 0.5)
    sfmax1 = 1.0 / sfmin1
    sfmin2 = sfmin1 * 2.0
    sfmax2 = 1.0 / sfmin2
    scale = np.ones(n)
    noconv = True
    while noconv:
        noconv = False
        for i in range(n):
            c = float(np.linalg.norm(A[:, i]))
            r = float(np.linalg.norm(A[i, :]))
            ca = float(np.max(np.abs(A[:, i])))
            ra = float(np.max(np.abs(A[i, :])))
            if c == 0.0 or r == 0.0:
                continue
            g = r / 2.0
            f = 1.0
            s = c + r
            while c < g and max(f, c, ca) < sfmax2 and min(r, g, ra) > sfmin2:
                f, c, ca, r, g, ra = f * 2.0, c * 2.0, ca * 2.0, r / 2.0, g / 2.0, ra / 2.0
            g = c / 2.0
            while g >= r and max(r, ra) < sfmax2 and min(f, c, g, ca) > sfmin2:
                f, c, g, ca, r, ra = f / 2.0, c / 2.0, g / 2.0, ca / 2.0, r * 2.0, ra * 2.0
            if c + r >= 0.95 * s:
                continue
            if f < 1.0 and scale[i] < 1.0 and f * scale[i] <= sfmin1:
                continue
            if f > 1.0 and scale[i] > 1.0 and scale[i] >= sfmax1 / f:
                continue
            scale[i] *= f
            noconv = True
            A[i, :] *= 1.0 / f
            A[:, i] *= f
    return scale


def phi_functions(L: np.ndarray, h: float, expm) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """exp(hL), phi_1(hL), phi_2(hL), phi_3(hL) for a square ``L`` [1/s] and step ``h`` [s], from
    one exponential of the augmented block matrix (:mod:`taos.planar._expstep`, part 1) by
    ``expm`` (:func:`taos.planar._expstep.expm_small` or its C translation)."""
    n = L.shape[0]
    # diagonal balancing B = S^-1 L S (states in Pa beside states in m: entries 1e-5 ... 1e10)
    # keeps the scaling-and-squaring short; f(L) = S f(B) S^-1 for every phi_k
    sc = _balance(L)
    B = L * (1.0 / sc)[:, None] * sc[None, :]
    W = np.zeros((4 * n, 4 * n))
    W[:n, :n] = h * B
    for k in range(3):
        W[k * n:(k + 1) * n, (k + 1) * n:(k + 2) * n] = np.eye(n)
    X = expm(W)
    back = lambda F: F * sc[:, None] * (1.0 / sc)[None, :]  # noqa: E731
    return back(X[:n, :n]), back(X[:n, n:2 * n]), back(X[:n, 2 * n:3 * n]), back(X[:n, 3 * n:])


def table_nodes(A: np.ndarray, H: float) -> int:
    """Intervals M of the command table on [0, ``H``] [s] so that (H / M) |lambda(A)|max <=
    :data:`TABLE_DTAU_NORM` (at least 8)."""
    lam = float(np.max(np.abs(np.linalg.eigvals(A)))) if A.size else 0.0
    return max(8, int(math.ceil(H * lam / TABLE_DTAU_NORM)))


def command_table(A: np.ndarray, bc: np.ndarray, H: float, M: int, expm) -> tuple[np.ndarray, np.ndarray]:
    """Values g(tau_i) and derivatives e^{tau_i A} b_c on tau_i = i H / M, i = 0..M (M:
    :func:`table_nodes`), g(tau) = int_0^tau e^{sA} b_c ds [x per rad] (:mod:`taos.planar._expstep`,
    part 2); ``H`` [s] the half step, ``A`` [1/s], ``bc`` [x/s per rad]."""
    n = A.shape[0]
    sc = np.append(_balance(A), 1.0)
    W = np.zeros((n + 1, n + 1))
    W[:n, :n] = A * (H / M)
    W[:n, n] = bc * (H / M)
    W = W * (1.0 / sc)[:, None] * sc[None, :]
    step = expm(W) * sc[:, None] * (1.0 / sc)[None, :]   # one interval: [[e^{dA}, g(d)], [0, 1]]
    G = np.zeros((M + 1, n))
    D = np.zeros((M + 1, n))
    P = np.eye(n + 1)
    for i in range(M + 1):
        G[i] = P[:n, n]
        D[i] = P[:n, :n] @ bc
        P = step @ P
    return G, D


def etd_coefficients(A: np.ndarray, h: float, expm):
    """The ETDRK4 matrices (E, E2, P2, F1, F2, F3) of :mod:`taos.planar._expstep` for the linear block
    ``A`` [1/s] and step ``h`` [s]."""
    E, p1, p2, p3 = phi_functions(A, h, expm)
    E2, q1, _, _ = phi_functions(A, 0.5 * h, expm)
    c = lambda a: np.ascontiguousarray(a)  # noqa: E731
    return (c(E), c(E2), c(0.5 * h * q1), c(h * (p1 - 3 * p2 + 4 * p3)), c(h * (p2 - 2 * p3)),
            c(h * (4 * p3 - p2)))


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
    m = _lp.n_limit_states(lim)
    vmax, ps, thmax = lim[_lp.LIM_VMAX], lim[_lp.LIM_PS], lim[_lp.LIM_THMAX]
    if vmax > 0 and np.any(uv >= vmax):
        return None
    if thmax > 0 and np.any(theta >= thmax):
        return None
    if not ps > 0:
        return np.zeros_like(np.asarray(q, float))
    d = np.maximum(1.0 - p / ps, lim[_lp.LIM_EPS])
    flow_in = lim[_lp.row_start(_lp.ROW_FLOW_IN, m):_lp.row_start(_lp.ROW_FLOW_IN + 1, m)]
    return float(np.max(np.abs(flow_in))) * q / (2.0 * np.sqrt(d) * ps)


def dwell_step_s(args, model, amp: float, freq: float, fixed_dt_s: float, ks) -> tuple[float, str]:
    """The ETDRK4 step [s] for one dwell of ``amp`` [r] at ``freq`` [Hz] (module docstring) and
    what set it (``"friction"``, ``"pressure"``, ``"limits"``, ``"sampling"``). ``args``: the
    plant arrays of :func:`taos.planar.simulate.kernel_args`; ``fixed_dt_s`` the fixed step
    kept where the limits are reached [s]; ``ks`` the kernel set (:class:`KernelSet`)."""

    A, Br, bc, bf, cc, dc, cw, ca, lim = (args.A, args.Br, args.bc, args.bf, args.cc, args.dc, args.cw, args.ca,
                                          args.lim)
    X = orbit(A + np.outer(bc, cc), Br.sum(axis=1) + bc * dc.sum(), amp, freq)
    ph = 2 * math.pi * np.arange(2 * N_ORBIT) / N_ORBIT
    xs = np.imag(X[None, :] * np.exp(1j * ph)[:, None])       # (2 N, n) over two cycles
    w = xs @ cw
    ta = xs @ ca
    fp, fid = model.friction.pack(), ks.law(model)
    stamp("first-kernel-call")
    z = ks.rate_response_z(fid, fp, np.ascontiguousarray(w), 1.0 / (freq * N_ORBIT), 0.0)
    stamp("first-kernel-return")
    sl = np.arange(N_ORBIT, 2 * N_ORBIT, N_ORBIT // 64)
    # and the rate reversals, where a regularised law is stiffest (a smooth Coulomb law's slope
    # T_c / v_eps at w = 0 is a spike far narrower than the 64 samples' spacing)
    c2 = w[N_ORBIT:2 * N_ORBIT]
    rev = N_ORBIT + np.flatnonzero(np.signbit(c2[:-1]) != np.signbit(c2[1:]))
    ws = np.concatenate([w[sl], np.zeros(rev.size)])
    rho = ks.friction_rate(fid, fp, np.ascontiguousarray(ws), np.ascontiguousarray(ta[np.r_[sl, rev]]),
                         np.ascontiguousarray(z[np.r_[sl, rev]]), float(cw @ bf), float(ca @ bf))
    why = "friction"
    if lim.size:
        m = _lp.n_limit_states(lim)
        row = lambda r: lim[_lp.row_start(r, m):_lp.row_start(r + 1, m)]  # noqa: E731
        rp = limits_rate(lim, np.abs(row(_lp.ROW_UV) @ X + lim[_lp.LIM_KVR] * amp * dc.sum()),
                         np.abs(row(_lp.ROW_THETA) @ X), np.abs(row(_lp.ROW_Q) @ X), np.abs(row(_lp.ROW_P) @ X))
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


def step_tables(A: np.ndarray, bc: np.ndarray, dts: np.ndarray, expm):
    """Coefficients for the steps ``dts`` [s] (one entry per dwell): the ETDRK4 matrices
    (:func:`etd_coefficients`, by ``expm``) and command tables, each built once per
    distinct step and stacked. Returns ((E, E2, P2, F1, F2, F3) stacks (k, n, n), G, D
    (k, M + 1, n), tab_m (k,) int64, idx (len(dts),) int64: the stack entry of each dwell)."""
    uniq, inv = np.unique(dts, return_inverse=True)
    ms = np.array([table_nodes(A, 0.5 * h) for h in uniq], np.int64)  # each step's own table
    co = [etd_coefficients(A, float(h), expm) for h in uniq]
    stack = tuple(np.ascontiguousarray(np.stack([c[i] for c in co])) for i in range(6))
    G = np.zeros((uniq.size, ms.max() + 1, A.shape[0]))
    D = np.zeros_like(G)
    for i, h in enumerate(uniq):
        G[i, :ms[i] + 1], D[i, :ms[i] + 1] = command_table(A, bc, 0.5 * float(h), int(ms[i]), expm)
    return stack, G, D, ms, inv.astype(np.int64).ravel()


def run_dwells(args, Cy, kern, amps, freqs, npc, n_settle, n_meas, out, status, ks):
    """ETDRK4 dwells (:func:`taos.planar._expstep.dwell_batch`, by the kernel set ``ks``) for
    ``npc`` steps a cycle each (coefficients from :func:`step_tables`), one per task on the
    threads, the longest first (:func:`taos.planar._parallel.run_each`)."""
    from ._parallel import run_each

    stack, G, D, ms, idx = step_tables(args.A, args.bc, 1.0 / (freqs * npc), ks.expm)
    run_each(lambda b: ks.dwell_batch(*args, Cy, *kern, *stack, G, D, ms, idx, idx, amps, freqs, npc, n_settle,
                                      n_meas, out, status, b, b + 1), n_settle + n_meas)


def exp_steps_per_cycle(args, model, inertia_kgm2: float, amps, freqs, fixed_dt_s: float,
                        min_steps_per_cycle: int, ks) -> np.ndarray:
    """Steps a cycle (int64, multiples of 4) of ETDRK4 dwells at ``amps`` [r] x ``freqs`` [Hz]
    (paired): the step of :func:`dwell_step_s` (``fixed_dt_s`` [s] where the limits are
    reached), halved until the friction law's own explicit-step rule accepts it
    (:meth:`taos.friction.FrictionLaw.check_step`: the switching Coulomb law's stick band)."""
    from ..errors import InputError

    out = np.empty(len(amps), np.int64)
    memo: dict[float, float] = {}
    for i, (a, f) in enumerate(zip(amps, freqs)):
        h, _ = dwell_step_s(args, model, float(a), float(f), fixed_dt_s, ks)
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
