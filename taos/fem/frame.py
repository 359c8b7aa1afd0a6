"""3-D Euler-Bernoulli frame elements, assembly and normal modes.

Element (12 DOFs: u, v, w, rx, ry, rz at each end; local x along the member): the classic
stiffness of Przemieniecki, *Theory of Matrix Structural Analysis* (1968), sec. 5.6, with
axial EA/L, torsion GJ/L and bending 12EI/L^3, 6EI/L^2, 4EI/L, 2EI/L about both principal
axes, and the consistent mass matrix (rho A L / 420 cubic-Hermite bending terms, rho A L/6
axial, rho J L / 6 torsional with J = Iy + Iz). Members are split into elements no longer
than ``max_element_m``. Modes solve K phi = w^2 M phi (scipy.sparse.linalg.eigsh in
shift-invert about w^2 = -1, sparse matrices; the test suite checks it against beam theory
and the modal orthogonality), mass-normalised phi^T M phi = I, so phi is in m/sqrt(kg) (translations) and rad/sqrt(kg) (rotations).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh


@dataclass(frozen=True)
class Section:
    """Beam cross-section and material.

    E_Pa, G_Pa : moduli [Pa]; rho_kg_m3 : density [kg/m^3]; A_m2 : area [m^2];
    Iy_m4, Iz_m4 : second moments about local y, z [m^4]; J_m4 : torsion constant [m^4];
    extra_mass_kg_per_m : non-structural mass per length [kg/m].
    """

    name: str
    E_Pa: float
    G_Pa: float
    rho_kg_m3: float
    A_m2: float
    Iy_m4: float
    Iz_m4: float
    J_m4: float
    extra_mass_kg_per_m: float = 0.0


def box_section(name: str, depth: float, width: float, wall: float, E: float, G: float, rho: float,
                extra_mass_kg_per_m: float = 0.0) -> Section:
    """Thin-walled rectangular box (depth along local z, width along local y) [m].

    A = 2 t (d + b); Iy = t d^3 / 6 + t b d^2 / 2; Iz = t b^3 / 6 + t d b^2 / 2;
    J = 2 t (b d)^2 / (b + d) (Bredt), thin-wall approximations.
    """
    d, b, t = depth, width, wall
    return Section(name, E, G, rho, 2 * t * (d + b), t * d ** 3 / 6 + t * b * d ** 2 / 2,
                   t * b ** 3 / 6 + t * d * b ** 2 / 2, 2 * t * (b * d) ** 2 / (b + d), extra_mass_kg_per_m)


def tube_section(name: str, diameter: float, wall: float, E: float, G: float, rho: float) -> Section:
    """Thin circular tube of mean diameter D and wall t: A = pi D t, I = pi D^3 t / 8, J = 2 I."""
    A = np.pi * diameter * wall
    Ib = np.pi * diameter ** 3 * wall / 8
    return Section(name, E, G, rho, A, Ib, Ib, 2 * Ib)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of two 3-vectors (the products and differences of np.cross, without its overhead)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


# element-matrix index blocks: axial, torsion, and bending (v, rz) and (w, ry) at both ends
_AXIAL, _TORSION = np.ix_([0, 6], [0, 6]), np.ix_([3, 9], [3, 9])
_BEND = {(1, 5): np.ix_([1, 5, 7, 11], [1, 5, 7, 11]), (2, 4): np.ix_([2, 4, 8, 10], [2, 4, 8, 10])}


def element_matrices(x1: np.ndarray, x2: np.ndarray, sec: Section, up: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Global (12, 12) stiffness [SI] and consistent mass [kg, kg m, kg m^2] of one element.

    ``up`` is a vector not parallel to the member that fixes the local z axis.
    """
    d = x2 - x1
    L = float(np.linalg.norm(d))
    ex = d / L
    ey = _cross(up, ex)
    if np.linalg.norm(ey) < 1e-8:
        ey = _cross(np.array([0.0, 1.0, 0.0]) if abs(ex[1]) < 0.9 else np.array([1.0, 0.0, 0.0]), ex)
    ey /= np.linalg.norm(ey)
    ez = _cross(ex, ey)
    E, G, A, Iy, Iz, J = sec.E_Pa, sec.G_Pa, sec.A_m2, sec.Iy_m4, sec.Iz_m4, sec.J_m4
    k = np.zeros((12, 12))
    ea, gj = E * A / L, G * J / L
    k[_AXIAL] = ea * np.array([[1, -1], [-1, 1]])
    k[_TORSION] = gj * np.array([[1, -1], [-1, 1]])

    def bend(I, iv, ir, sgn):
        c = E * I / L ** 3
        kb = c * np.array([[12, sgn * 6 * L, -12, sgn * 6 * L],
                           [sgn * 6 * L, 4 * L * L, -sgn * 6 * L, 2 * L * L],
                           [-12, -sgn * 6 * L, 12, -sgn * 6 * L],
                           [sgn * 6 * L, 2 * L * L, -sgn * 6 * L, 4 * L * L]])
        k[_BEND[iv, ir]] += kb

    bend(Iz, 1, 5, +1)   # v with rz
    bend(Iy, 2, 4, -1)   # w with ry
    mu = sec.rho_kg_m3 * A + sec.extra_mass_kg_per_m
    m = np.zeros((12, 12))
    m[_AXIAL] = mu * L / 6 * np.array([[2, 1], [1, 2]])
    m[_TORSION] = sec.rho_kg_m3 * (Iy + Iz) * L / 6 * np.array([[2, 1], [1, 2]])

    def bmass(iv, ir, sgn):
        c = mu * L / 420
        mb = c * np.array([[156, sgn * 22 * L, 54, -sgn * 13 * L],
                           [sgn * 22 * L, 4 * L * L, sgn * 13 * L, -3 * L * L],
                           [54, sgn * 13 * L, 156, -sgn * 22 * L],
                           [-sgn * 13 * L, -3 * L * L, -sgn * 22 * L, 4 * L * L]])
        m[_BEND[iv, ir]] += mb

    bmass(1, 5, +1)
    bmass(2, 4, -1)
    Rm = np.array([ex, ey, ez])
    T = np.kron(np.eye(4), Rm)
    return T.T @ k @ T, T.T @ m @ T


@dataclass
class Frame:
    """A frame under construction: nodes [m], elements, lumped masses, named and fixed nodes."""

    nodes: list = field(default_factory=list)
    elements: list = field(default_factory=list)   # (i, j, Section, up)
    lumped: dict = field(default_factory=dict)     # node -> kg
    names: dict = field(default_factory=dict)      # name -> node
    fixed: set = field(default_factory=set)
    _xyz: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)), repr=False, compare=False)

    def node(self, xyz, tol: float = 1e-6) -> int:
        """Index of the first node within ``tol`` [m] of ``xyz`` [m]; a new node if none is."""
        p = np.asarray(xyz, float)
        X = self._coords()
        hit = np.flatnonzero(np.sqrt(np.sum((X - p) ** 2, axis=1)) < tol)
        if hit.size:
            return int(hit[0])
        self.nodes.append(p)
        return len(self.nodes) - 1

    def _coords(self) -> np.ndarray:
        """(n, 3) array of ``nodes`` [m], extended by the nodes appended since the last call."""
        k = self._xyz.shape[0]
        if k != len(self.nodes):
            new = np.array(self.nodes[k:], float).reshape(-1, 3) if k < len(self.nodes) else None
            self._xyz = np.vstack([self._xyz, new]) if new is not None else np.array(self.nodes, float).reshape(-1, 3)
        return self._xyz

    def member(self, a: int, b: int, sec: Section, max_element_m: float, up=(1.0, 0.0, 0.0)) -> None:
        """Member from node a to node b split into equal elements <= max_element_m."""
        pa, pb = self.nodes[a], self.nodes[b]
        n = max(1, int(np.ceil(np.linalg.norm(pb - pa) / max_element_m - 1e-9)))
        ids = [a] + [self.node(pa + (pb - pa) * s) for s in np.arange(1, n) / n] + [b]
        for i, j in zip(ids[:-1], ids[1:]):
            self.elements.append((i, j, sec, np.asarray(up, float)))

    def assemble(self) -> tuple[sp.csr_matrix, sp.csr_matrix, np.ndarray]:
        """(K, M, free DOF indices) with 6 DOFs per node, sparse [SI]."""
        n = 6 * len(self.nodes)
        X = np.array(self.nodes)
        rows, cols, kv, mv = [], [], [], []
        for i, j, sec, up in self.elements:
            ke, me = element_matrices(X[i], X[j], sec, up)
            d = np.r_[6 * i:6 * i + 6, 6 * j:6 * j + 6]
            rows.append(np.repeat(d, 12))
            cols.append(np.tile(d, 12))
            kv.append(ke.ravel())
            mv.append(me.ravel())
        for i, mass in self.lumped.items():
            d = np.arange(6 * i, 6 * i + 3)
            rows.append(d)
            cols.append(d)
            kv.append(np.zeros(3))
            mv.append(np.full(3, mass))
        r, c = np.concatenate(rows), np.concatenate(cols)
        K = sp.csr_matrix((np.concatenate(kv), (r, c)), shape=(n, n))
        M = sp.csr_matrix((np.concatenate(mv), (r, c)), shape=(n, n))
        fixed = np.array(sorted(6 * i + c for i in self.fixed for c in range(6)), int)
        free = np.setdiff1d(np.arange(n), fixed)
        return K, M, free


@dataclass(frozen=True)
class Modes:
    """Normal modes: freq_hz (n,), phi (n, nnodes, 6) mass-normalised, node coordinates."""

    freq_hz: np.ndarray
    phi: np.ndarray
    nodes_m: np.ndarray
    total_mass_kg: float
    n_elements: int
    n_dofs: int


def frame_modes(frame: Frame, f_max_hz: float) -> Modes:
    """Modes of ``frame`` up to ``f_max_hz`` (fixed nodes held), mass-normalised."""
    K, M, free = frame.assemble()
    Kf, Mf = K[free][:, free].tocsc(), M[free][:, free].tocsc()
    w2max = (2 * np.pi * f_max_hz) ** 2
    k = 12
    while True:
        k = min(k, Kf.shape[0] - 2)
        lam, V = eigsh(Kf, k=k, M=Mf, sigma=-1.0, which="LM")
        order = np.argsort(lam)
        lam, V = lam[order], V[:, order]
        if lam[-1] > w2max or k >= Kf.shape[0] - 2:
            break
        k *= 2
    keep = lam <= w2max
    lam, V = lam[keep], V[:, keep]
    # M-orthonormalise (eigsh vectors are M-orthogonal; renormalise to phi^T M phi = 1)
    V = V / np.sqrt(np.einsum("ik,ik->k", V, Mf @ V))
    full = np.zeros((K.shape[0], lam.size))
    full[free] = V
    phi = full.T.reshape(lam.size, len(frame.nodes), 6)
    # deterministic sign: largest-magnitude entry positive
    for k in range(lam.size):
        flat = phi[k].ravel()
        if flat[np.argmax(np.abs(flat))] < 0:
            phi[k] *= -1
    rx = np.zeros(K.shape[0])
    rx[0::6] = 1.0
    mass = float(rx @ M @ rx)
    return Modes(np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi), phi, np.array(frame.nodes),
                 mass, len(frame.elements), int(free.size))
