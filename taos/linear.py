"""Named linear state-space systems and their exact frequency responses.

x' = A x + B u,  y = C x + D u, with named states, inputs and outputs so that models are
assembled from pieces (actuator, load path, engine, vehicle) by name rather than by index.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np


@dataclass(frozen=True, eq=False)
class StateSpace:
    """A continuous-time LTI system with named signals (SI units in the names).

    The matrices are float arrays, or CasADi SX matrices when the builder was given symbolic
    parameters (then only the symbolic helpers, e.g. :func:`freqresp_symbolic`, apply)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    def __post_init__(self):
        n, m, p = len(self.states), len(self.inputs), len(self.outputs)
        for name, M, shape in (("A", self.A, (n, n)), ("B", self.B, (n, m)),
                               ("C", self.C, (p, n)), ("D", self.D, (p, m))):
            if tuple(M.shape) != shape:
                raise ValueError(f"{name} has shape {M.shape}, expected {shape}")

    def input_index(self, name: str) -> int:
        return self.inputs.index(name)

    def output_index(self, name: str) -> int:
        return self.outputs.index(name)

    def state_index(self, name: str) -> int:
        return self.states.index(name)

    @cached_property
    def _forms(self) -> tuple[np.ndarray, np.ndarray]:
        """(s, diag(s)^-1 A diag(s)) of :func:`balancing_scale`, read-only; shared by the
        systems with an equal A of at most :data:`SHARED_FORMS_MAX_N` states."""
        A = np.ascontiguousarray(self.A, float)
        n = A.shape[0]
        return (_balanced_form if n <= SHARED_FORMS_MAX_N else _balanced_form.__wrapped__)(A.tobytes(), n)

    @property
    def balance_scale(self) -> np.ndarray:
        """The diagonal scaling of :func:`balancing_scale` (read-only), computed once per system."""
        return self._forms[0]

    @property
    def _balanced(self) -> np.ndarray:
        """diag(s)^-1 A diag(s), s = :attr:`balance_scale` (exact: s holds powers of two)."""
        return self._forms[1]

    @cached_property
    def _hessenberg(self) -> tuple[np.ndarray, np.ndarray]:
        """(H, Q): the balanced A (:attr:`_balanced`) = Q H Q^T with H upper Hessenberg and Q
        orthogonal (:func:`hessenberg`), read-only, computed once per system (shared as
        :attr:`_forms`)."""
        Ab = self._balanced
        n = Ab.shape[0]
        return (_hessenberg_form if n <= SHARED_FORMS_MAX_N else _hessenberg_form.__wrapped__)(Ab.tobytes(), n)

    def poles(self) -> np.ndarray:
        """Eigenvalues of A [1/s]."""
        return np.linalg.eigvals(self.A)

    def freqresp(self, freq_hz, inputs: str | list[str] | None = None,
                 outputs: str | list[str] | None = None) -> np.ndarray:
        """Exact frequency response H(j w) = C (j w I - A)^-1 B + D.

        Returns an array of shape (n_freq, n_out, n_in) for the selected signals (all by
        default); a single name selects a single signal and drops that axis. Balances A first
        (the states mix Pa and m). Few frequencies (n_freq n^2 below
        :data:`HESSENBERG_MIN_WORK`) are solved by LAPACK's LU with partial pivoting, one j w I - A
        at a time; many by the method of Laub (IEEE Trans. Automat. Control 26 (1981) 407): A is
        reduced once per system to Hessenberg form by orthogonal similarity (:func:`hessenberg`),
        then every frequency's Hessenberg system is solved at once by Gaussian elimination with
        partial pivoting (:func:`hessenberg_solve`, O(n^2) a frequency instead of O(n^3)). On
        either path a frequency's response does not depend on the other frequencies of the call
        (bit for bit). Both are backward stable and agree to round-off relative to the
        response's largest value (a response many decades below its own peak, e.g. far above a
        high relative degree's roll-off, keeps fewer correct digits on the Hessenberg path).
        Raises ``numpy.linalg.LinAlgError`` where j w I - A is exactly singular.
        """
        f = np.atleast_1d(np.asarray(freq_hz, float))
        ii = self._sel(inputs, self.inputs)
        oo = self._sel(outputs, self.outputs)
        sc = self.balance_scale
        n = len(self.states)
        D = self.D[np.ix_(oo, ii)][None]
        if f.size * n * n < HESSENBERG_MIN_WORK:
            # few frequencies: LAPACK's LU solve of each j w I - A (the smaller call overhead)
            Ab = self._balanced
            M = (2j * np.pi * f)[:, None, None] * np.eye(n)[None] - Ab[None]
            X = np.linalg.solve(M, np.broadcast_to((self.B[:, ii] / sc[:, None]).astype(complex), (f.size, n, len(ii))))
            out = (self.C[oo, :] * sc[None, :])[None] @ X + D
        else:
            H, Q = self._hessenberg
            Bh = Q.T @ (self.B[:, ii] / sc[:, None])
            Ch = (self.C[oo, :] * sc[None, :]) @ Q
            X = hessenberg_solve(H, 2j * np.pi * f, Bh)           # (n, n_in, n_freq)
            # C X summed state by state in order, each frequency on its own
            out = (Ch.T[:, :, None, None] * X[:, None]).sum(axis=0).transpose(2, 0, 1) + D
        if isinstance(outputs, str):
            out = out[:, 0, :]
        if isinstance(inputs, str):
            out = out[..., 0]
        return out

    @staticmethod
    def _sel(sel, names) -> list[int]:
        if sel is None:
            return list(range(len(names)))
        if isinstance(sel, str):
            return [names.index(sel)]
        return [names.index(s) for s in sel]


#: n_freq * n^2 from which :meth:`StateSpace.freqresp` solves on the Hessenberg form: below it
#: LAPACK's per-frequency LU costs less (measured for n = 8: equal near 190 frequencies)
HESSENBERG_MIN_WORK = 12_000


def is_symbolic(*values) -> bool:
    """True if any value is a CasADi symbol/expression (SX or MX)."""
    import sys

    ca = sys.modules.get("casadi")
    if ca is None:  # no CasADi expression exists before casadi is imported (keeps start-up light)
        return False
    return any(isinstance(v, (ca.SX, ca.MX)) for v in values)


def zeros(shape, symbolic: bool) -> np.ndarray:
    """A float array, or an object array that can hold CasADi expressions."""
    return np.zeros(shape, dtype=object if symbolic else float)


def finish(M: np.ndarray, symbolic: bool):
    """Turn a matrix built by :func:`zeros` into a float ndarray or a CasADi SX matrix.

    This is how the model builders (actuator, simplex) serve both numeric analysis and
    CasADi fits from one definition of the equations."""
    if not symbolic:
        return M
    import casadi as ca
    M2 = M if M.ndim == 2 else M.reshape(-1, 1)
    return ca.blockcat([[ca.SX(v) if not isinstance(v, (ca.SX, ca.MX)) else v for v in row] for row in M2.tolist()])


def gain_db(h, floor: float = 1e-300) -> np.ndarray:
    """20 log10 |h| [dB], with |h| floored at ``floor`` (same unit as h) so that an exact zero
    gives a finite level (-6000 dB by default) instead of -inf. The one gain-in-dB helper."""
    return 20.0 * np.log10(np.maximum(np.abs(h), floor))


def phase_deg(h, unwrap: bool = True, axis: int = 0) -> np.ndarray:
    """Phase of h [deg], unwrapped along ``axis`` (the first by default) in the order given.
    The one plain-unwrap phase helper; :func:`phase_deg_continuous` is the one for responses
    sampled at (possibly unsorted, possibly sparse) frequencies."""
    ph = np.angle(h)
    if unwrap:
        ph = np.unwrap(ph, axis=axis)
    return np.degrees(ph)


def notch_hz(abs_gain, f_lo_hz: float, f_hi_hz: float, n_grid: int = 400, xatol: float = 1e-9,
             n_section: int = 16):
    """Frequency [Hz] of the minimum of a gain |H(f)| over [f_lo_hz, f_hi_hz] (the notch).

    ``abs_gain`` maps an array of F frequencies [Hz] to |H| (any unit), shape (F,) for one
    response (the result is then a float) or (F, m) for m responses evaluated together (an (m,)
    array). The minimum of a log grid of ``n_grid`` points is refined in log10 f between the
    grid's neighbours by a section search, all responses at once: each step evaluates
    ``n_section`` equally spaced interior points of every response's bracket in one call and
    keeps the two intervals around the least (the bracket shrinks (n_section + 1) / 2 times a
    step; for a unimodal gain the minimum stays inside), until every bracket is at most
    ``xatol`` wide in log10 f; the midpoint is returned. The one notch finder for responses
    that can be evaluated at any frequency; :func:`sampled_notch_hz` is the one for sampled
    responses."""
    grid = np.linspace(np.log10(f_lo_hz), np.log10(f_hi_hz), n_grid)
    g = np.asarray(abs_gain(10 ** grid), float)
    cols = g.reshape(grid.size, -1)
    m = cols.shape[1]
    k = np.argmin(cols, axis=0)
    a = grid[np.maximum(k - 1, 0)]
    b = grid[np.minimum(k + 1, grid.size - 1)]
    jj = np.arange(m)
    frac = np.arange(1, n_section + 1)[:, None] / (n_section + 1)
    while np.max(b - a) > xatol:
        x = a + frac * (b - a)                                      # (n_section, m) interior points
        gx = np.asarray(abs_gain(10 ** x.ravel()), float).reshape(n_section, m, m)[:, jj, jj]
        i = np.argmin(gx, axis=0)                                   # the least of each response
        lo = np.where(i > 0, x[np.maximum(i - 1, 0), jj], a)
        b = np.where(i < n_section - 1, x[np.minimum(i + 1, n_section - 1), jj], b)
        a = lo
    out = 10 ** (0.5 * (a + b))
    return float(out[0]) if g.ndim == 1 else out


def sampled_notch_hz(freq_hz, h) -> float:
    """Frequency [Hz] of the deepest interior local minimum of |h| on its own frequency grid
    (a measured or sine-dwell response), refined by a parabola in log10 f through the three
    points around it; NaN when |h| has no interior minimum (no notch in the band)."""
    f = np.asarray(freq_hz, float)
    g = gain_db(h)
    if f.size < 3:
        return float("nan")
    inner = np.flatnonzero((g[1:-1] < g[:-2]) & (g[1:-1] < g[2:])) + 1
    if inner.size == 0:
        return float("nan")
    k = int(inner[np.argmin(g[inner])])
    x = np.log10(f[k - 1:k + 2])
    a, b, _ = np.polyfit(x, g[k - 1:k + 2], 2)
    return float(10 ** np.clip(-b / (2 * a), x[0], x[2])) if a > 0 else float(f[k])


def phase_deg_continuous(freq_hz, h, reference_deg=None, reference_freq_hz=None) -> np.ndarray:
    """Phase of h [deg] continuous from low frequency: the project's one phase convention.

    Without ``reference_deg`` the points are sorted by frequency, unwrapped in that order
    and the lowest-frequency point lies in (-180, 180] (right for measured points that start
    at low frequency). With ``reference_deg`` (the continuous phase of a reference response at
    the same frequencies, e.g. the linear model's from :func:`taos.planar.freqresp.linear_phase_reference`)
    each point takes the 360-deg branch nearest the reference, so sparse points far from low
    frequency (a single 7 Hz point, a cross-axis response) read as on the continuous curve.
    With ``reference_freq_hz`` too, ``reference_deg`` is a dense reference curve sampled there
    (increasing [Hz]), interpolated linearly in log10 f to ``freq_hz`` first; a reference of
    fewer than two points is ignored."""
    f = np.atleast_1d(np.asarray(freq_hz, float))
    hh = np.atleast_1d(np.asarray(h, complex))
    ph = np.angle(hh)
    if reference_freq_hz is not None and reference_deg is not None:
        rf = np.atleast_1d(np.asarray(reference_freq_hz, float))
        reference_deg = (np.interp(np.log10(f), np.log10(rf), np.asarray(reference_deg, float))
                         if rf.size > 1 else None)
    if reference_deg is not None:
        ref = np.radians(np.atleast_1d(np.asarray(reference_deg, float)))
        return np.degrees(ph + 2 * np.pi * np.round((ref - ph) / (2 * np.pi)))
    order = np.argsort(f, kind="stable")
    out = np.empty_like(ph)
    out[order] = np.unwrap(ph[order])
    return np.degrees(out)


def _read_only(*arrays):
    for a in arrays:
        a.flags.writeable = False
    return arrays


#: systems of at most this many states share the forms :meth:`StateSpace.freqresp` solves with
SHARED_FORMS_MAX_N = 64


# The forms of a numeric A that :meth:`StateSpace.freqresp` solves with, remembered per A (its
# bytes): a sweep's figures build the same block several times (the merit, the notch, the loop
# margins), and each form is a pure function of A, so a remembered one is the recomputed one.
@lru_cache(maxsize=32)
def _balanced_form(a_bytes: bytes, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(s, diag(s)^-1 A diag(s)) of :func:`balancing_scale` for A given by its bytes, read-only."""
    A = np.frombuffer(a_bytes).reshape(n, n)
    sc = _balancing_scale(A)
    return _read_only(sc, A / sc[:, None] * sc[None, :])


@lru_cache(maxsize=32)
def _hessenberg_form(ab_bytes: bytes, n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`hessenberg` of a (balanced) A given by its bytes, read-only."""
    return _read_only(*hessenberg(np.frombuffer(ab_bytes).reshape(n, n)))


def balancing_scale(ss: StateSpace) -> np.ndarray:
    """Diagonal state scaling s (x = diag(s) x') that balances a numeric A: powers of two
    making each state's off-diagonal row and column 1-norms of diag(s)^-1 A diag(s) comparable
    (Parlett & Reinsch, "Balancing a matrix for calculation of eigenvalues and eigenvectors",
    Numer. Math. 13 (1969); the scaling iteration of LAPACK xGEBAL without permutation)."""
    return _balancing_scale(ss.A)


def _balancing_scale(A) -> np.ndarray:
    M = np.abs(np.asarray(A, float))
    n = M.shape[0]
    np.fill_diagonal(M, 0.0)
    s = np.ones(n)
    for _ in range(100):
        done = True
        for i in range(n):
            c = M[:, i].sum()
            r = M[i, :].sum()
            if c == 0.0 or r == 0.0:
                continue
            tot, f = c + r, 1.0
            while c < r / 2.0:
                c, r, f = c * 2.0, r / 2.0, f * 2.0
            while c >= r * 2.0:
                c, r, f = c / 2.0, r * 2.0, f / 2.0
            if c + r < 0.95 * tot:
                done = False
                s[i] *= f
                M[:, i] *= f
                M[i, :] /= f
        if done:
            break
    return s


def hessenberg(A) -> tuple[np.ndarray, np.ndarray]:
    """(H, Q) with A = Q H Q^T, H upper Hessenberg and Q orthogonal, for a real square A (any
    unit), by Householder reflections (Golub & Van Loan, "Matrix Computations", 4th ed.,
    algorithm 7.4.2): backward stable, the reduction LAPACK's xGEHRD makes. Numpy only, so the
    linear analysis needs no scipy."""
    H = np.array(A, float)
    n = H.shape[0]
    Q = np.eye(n)
    for k in range(n - 2):
        x = H[k + 1:, k]
        if not np.any(x[1:]):
            continue   # already zero below the subdiagonal
        v = x.copy()
        v[0] += math.copysign(np.linalg.norm(x), x[0])   # no cancellation in v[0]
        v /= np.linalg.norm(v)
        H[k + 1:, :] -= 2.0 * np.outer(v, v @ H[k + 1:, :])
        H[:, k + 1:] -= 2.0 * np.outer(H[:, k + 1:] @ v, v)
        Q[:, k + 1:] -= 2.0 * np.outer(Q[:, k + 1:] @ v, v)
        H[k + 2:, k] = 0.0
    return H, Q


def hessenberg_solve(H: np.ndarray, s: np.ndarray, B: np.ndarray) -> np.ndarray:
    """X[k] solving (s[k] I - H) X[k] = B for every complex s[k] at once: H (n, n) upper
    Hessenberg (real), s (F,), B (n, m) (any units, X in B's over s's). Gaussian elimination
    with partial pivoting, which on a Hessenberg matrix only ever compares and combines the
    carried row with the next one: n - 1 steps, each vectorised over the F shifts, O(n^2)
    work per shift (a general LU solve costs O(n^3)); every shift is computed on its own
    (elementwise), so its X does not depend on the other shifts. Returns X of shape
    (n, m, F); raises ``numpy.linalg.LinAlgError`` if a pivot is exactly zero (s[k] I - H
    singular)."""
    n, m = B.shape
    s = np.asarray(s, complex)
    F = s.size
    diag, tail, Y = [], [], []       # the triangular factor: pivots (F,), rows right of them (n-k-1, F); rhs (m, F)
    cur = np.empty((n, F), complex)  # the carried row k of the partly eliminated matrix, columns k.. n-1
    cur[:] = -H[0][:, None]
    cur[0] += s
    rc = np.empty((m, F), complex)   # and its right-hand side
    rc[:] = B[0][:, None]
    # a zero pivot (0 / 0 on the way) is singular: raised below, once the factor is complete
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(n - 1):
            h = -H[k + 1, k]            # row k + 1 in column k: the same for every shift
            nxt = np.empty((n - k - 1, F), complex)   # row k + 1 right of column k
            nxt[:] = -H[k + 1, k + 1:][:, None]
            nxt[0] += s
            rn = B[k + 1][:, None]
            c0 = cur[0]
            swap = np.abs(c0) < abs(h)  # the pivot: the larger of the two (the first on a tie)
            if not swap.any():
                l = h / c0
                diag.append(c0)
                tail.append(cur[1:])
                Y.append(rc)
                cur, rc = nxt - l * cur[1:], rn - l * rc
            elif swap.all():
                l = c0 / h
                diag.append(np.full(F, h, complex))
                tail.append(nxt)
                Y.append(np.broadcast_to(rn, (m, F)))
                cur, rc = cur[1:] - l * nxt, rc - l * rn
            else:
                l = np.where(swap, c0 / h, h / c0)
                ct = cur[1:]
                diag.append(np.where(swap, h, c0))
                tail.append(np.where(swap, nxt, ct))
                Y.append(np.where(swap, rn, rc))
                cur = np.where(swap, ct, nxt) - l * tail[-1]
                rc = np.where(swap, rc, rn) - l * Y[-1]
    diag.append(cur[0])
    Y.append(rc)
    if not all(np.all(d) for d in diag):
        raise np.linalg.LinAlgError("Singular matrix")
    X = np.empty((n, m, F), complex)
    X[n - 1] = Y[n - 1] / diag[n - 1]
    for k in range(n - 2, -1, -1):
        X[k] = (Y[k] - (tail[k][:, None, :] * X[k + 1:]).sum(axis=0)) / diag[k]
    return X


def freqresp_symbolic(ss: StateSpace, w_rad_s: float, inputs, outputs, scale: np.ndarray | None = None):
    """Real and imaginary parts of H(j w) for a (possibly CasADi-symbolic) state space.

    Solves the real 2n system [[-A, -w I], [w I, -A]] [X_r; X_i] = [B; 0] once for all the
    selected inputs, so CasADi (which has no complex type) can differentiate the response
    exactly. ``inputs``/``outputs`` are a name (the result is then a scalar in that direction)
    or a list of names (an n_out x n_in SX matrix). ``scale`` (from :func:`balancing_scale` of a
    nominal numeric model) rescales the states first: states in Pa and m otherwise cost the
    solve several digits. Returns (re, im)."""
    import casadi as ca

    ii = [ss.input_index(inputs)] if isinstance(inputs, str) else [ss.input_index(n) for n in inputs]
    oo = [ss.output_index(outputs)] if isinstance(outputs, str) else [ss.output_index(n) for n in outputs]
    A = ca.SX(ss.A) if not isinstance(ss.A, (ca.SX, ca.MX)) else ss.A
    B = ca.horzcat(*[ss.B[:, i] for i in ii])
    C = ca.vertcat(*[ss.C[o:o + 1, :] for o in oo])  # rows stay rows (numeric C: a free set of friction only)
    D = ca.SX(len(oo), len(ii))
    for a, o in enumerate(oo):
        for b, i in enumerate(ii):
            D[a, b] = ss.D[o, i]
    if scale is not None:
        S = ca.diag(ca.DM(scale))
        Si = ca.diag(ca.DM(1.0 / np.asarray(scale)))
        A = Si @ A @ S
        B = Si @ B
        C = C @ S
    n = len(ss.states)
    eye = ca.SX.eye(n)
    M = ca.vertcat(ca.horzcat(-A, -w_rad_s * eye), ca.horzcat(w_rad_s * eye, -A))
    x = ca.solve(M, ca.vertcat(B, ca.SX.zeros(n, len(ii))))
    return C @ x[:n, :] + D, C @ x[n:, :]
