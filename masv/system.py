"""The coupled MASV model: four engines, eight actuators, the thrust-structure modes.

Pieces (SI)::

    actuator k        taos.actuator.actuator_state_space (inputs x_c, F_L; output x_p)
    command           x_c,k = R_k theta_c,k                                  [m]
    load path k       F_L,k = K_L,k (x_p,k - R_k theta_k - e_k)              [N]
    engine axis k     J_k theta_k'' = R_k F_L,k - K_n,k (theta_k - r_k)      [N m]
    structure         q'' + 2 Z Om q' + Om^2 q = Phi_c^T f_c                 (modal, M = I)
    coupling coords   e_k = n_k . (u(gimbal_k) - u(attach_k)) = Phi_e,k q   [m]
                      r_k = a_k . rot(gimbal_k)               = Phi_r,k q   [rad]
    coupling forces   f_c = [F_L,k ; K_n,k (theta_k - r_k)]

n_k is the actuator's unit line of action (structure attach -> engine attach) and a_k the engine
rotation axis of that actuator (rotation about a_k extends it). K_L is the taos model's
``[structure] load_stiffness``: the compliance outside the modal structure (gimbal, engine,
actuator case and attachments), in series with the modal structure. The actuator pushes the
engine (hence, through the gimbal, the gimbal node) along +n_k and the attach node along -n_k;
the feedline/gravity spring K_n acts between the engine and the structure's gimbal rotation.
Both follow from the potential 1/2 K_L delta_k^2 + 1/2 K_n (theta_k - r_k)^2, so the
interconnection is energy-consistent. Each actuator drives one engine axis (pitch and yaw lines
of action taken orthogonal, as in the simplex model); axis-to-axis and engine-to-engine coupling
arise only through the structure. Engine translational inertia (tail-wags-dog) is taken to be in
the modal model (engine mass lumped at the gimbal); the coupling of engine rotation to gimbal
translation through the engine's centre-of-mass offset is not modelled.

With no modes the eight engine-axis blocks are independent and each is the planar simplex model
(taos.simplex), the reduction checked by the tests.

Two views of the one model: :meth:`MasvSystem.state_space` assembles the whole as one
:class:`taos.linear.StateSpace` (eigenvalues, the naive reference response) and
:meth:`MasvSystem.frf` computes the same frequency response by block elimination: the
structure's receptance at the coupling coordinates, R(s) = Phi_c diag(1/(s^2 + 2 zeta w s +
w^2)) Phi_c^T, costs O(n m^2) per frequency because the modal part is diagonal, and the engine
blocks are small and independent; closing f_c = G_fu u + G_fc u_c, u_c = R f_c leaves an m x m
solve per frequency (m = 2 x actuators). Modes dropped by truncation may leave their static
flexibility g_res (a massless compliance in series, "static correction"): u_c = Phi_c q + g_res f_c,
i.e. R(s) + g_res in the frequency domain.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from taos.actuator import actuator_state_space
from taos.linear import StateSpace
from taos.model import TvcModel

from .config import MasvConfig
from .structure import ModalStructure

BLOCK_INPUTS = ("command_rad", "elongation_m", "gimbal_rotation_rad")
BLOCK_OUTPUTS = ("x_p_m", "theta_rad", "f_load_N", "spring_torque_Nm")


def engine_axis_block(model: TvcModel, axis: str) -> StateSpace:
    """One actuator driving one engine axis, with the structure's motion as inputs.

    Inputs: ``command_rad`` theta_c [rad] (x_c = R theta_c), ``elongation_m`` e [m] (structure
    motion along the line of action, gimbal minus attach point), ``gimbal_rotation_rad`` r [rad].
    Outputs: ``x_p_m``, ``theta_rad``, ``f_load_N`` = K_L (x_p - R theta - e),
    ``spring_torque_Nm`` = K_n (theta - r). States: the actuator's, ``theta_rad``, ``omega_rad_s``.
    With e = r = 0 it is taos.simplex.simplex_state_space (the friction input left at zero) with
    the taos load-path damping ``[structure] load_damping_ratio`` off: MASV's damping is modal.
    """
    act = actuator_state_space(model.actuator)
    R = model.actuator.moment_arm_m
    KL = model.structure.load_stiffness_N_per_m
    Kn = model.engine.rotational_stiffness_Nm_per_rad
    J = model.engine.inertia(axis)
    na = len(act.states)
    n = na + 2
    ith, iom = na, na + 1
    bf = act.B[:, act.input_index("f_load_N")]
    bx = act.B[:, act.input_index("x_c_m")]
    cxp = act.C[act.output_index("x_p_m")]
    fl = np.zeros(n)                     # F_L row over the state (e enters through D)
    fl[:na] = KL * cxp
    fl[ith] = -KL * R
    tq = R * fl                          # torque on the engine about its axis
    tq[ith] -= Kn
    A = np.zeros((n, n))
    A[:na, :na] = act.A
    A[:na, :] += np.outer(bf, fl)
    A[ith, iom] = 1.0
    A[iom, :] = tq / J
    B = np.zeros((n, 3))
    B[:na, 0] = bx * R
    B[:na, 1] = -KL * bf
    B[iom, 1] = -R * KL / J
    B[iom, 2] = Kn / J
    C = np.zeros((4, n))
    C[0, :na] = cxp
    C[1, ith] = 1.0
    C[2] = fl
    C[3, ith] = Kn
    D = np.zeros((4, 3))
    D[2, 1] = -KL
    D[3, 2] = -Kn
    return StateSpace(A, B, C, D, tuple(act.states) + ("theta_rad", "omega_rad_s"), BLOCK_INPUTS, BLOCK_OUTPUTS)


def coupling_shapes(cfg: MasvConfig, phi: np.ndarray | None = None) -> np.ndarray:
    """Phi_c (2 n_act, n_modes): rows e_k = n_k . (phi(gimbal) - phi(attach)) [m/sqrt(kg)], then
    r_k = a_k . rot(gimbal) [rad/sqrt(kg)], in actuator order (``phi`` defaults to the
    structure's mode shapes)."""
    st = cfg.structure
    phi = st.phi if phi is None else phi
    n = phi.shape[0]
    na = len(cfg.actuators)
    phi_c = np.zeros((2 * na, n))
    if n == 0:
        return phi_c
    for k, a in enumerate(cfg.actuators):
        g = st.node_index(cfg.engine(a.engine).gimbal_node)
        at = st.node_index(a.attach_node)
        phi_c[k] = (phi[:, g, 0:3] - phi[:, at, 0:3]) @ np.asarray(a.direction)
        phi_c[na + k] = phi[:, g, 3:6] @ np.asarray(a.rotation_axis)
    return phi_c


def residual_flexibility(cfg: MasvConfig) -> np.ndarray:
    """Static flexibility of the modes dropped by truncation at the coupling coordinates,
    sum Phi_c,i Phi_c,i^T / w_i^2, (m, m) [m/N, rad/(N m)] (zeros without static correction)."""
    st = cfg.structure
    m = 2 * len(cfg.actuators)
    if st.residual_phi is None or st.residual_phi.shape[0] == 0:
        return np.zeros((m, m))
    P = coupling_shapes(cfg, st.residual_phi)
    w = 2.0 * np.pi * st.residual_freq_hz
    return (P / w[None] ** 2) @ P.T


def _balanced(ss: StateSpace):
    A, (sc, _p) = scipy.linalg.matrix_balance(ss.A, permute=False, separate=True)
    return A, ss.B / sc[:, None], ss.C * sc[None, :], ss.D


def _block_frd(ss: StateSpace, s: np.ndarray) -> np.ndarray:
    """Batched exact response (F, n_out, n_in) of a small balanced block at s = j w."""
    A, B, C, D = _balanced(ss)
    n = A.shape[0]
    M = s[:, None, None] * np.eye(n)[None] - A[None]
    X = np.linalg.solve(M, np.broadcast_to(B.astype(complex), (s.size,) + B.shape))
    return C[None] @ X + D[None]


@dataclass(frozen=True, eq=False)
class MasvSystem:
    """The assembled MASV model (see the module docstring for the equations).

    ``blocks[k]`` is actuator k's engine-axis block (:func:`engine_axis_block`), ``moment_arms_m``
    R_k [m], ``phi_c`` the coupling shapes (:func:`coupling_shapes`), ``omega_rad_s`` and
    ``zeta`` the modal frequencies [rad/s] and damping ratios [-], ``g_res`` the residual
    flexibility of truncated modes at the coupling coordinates (:func:`residual_flexibility`),
    a massless compliance in series: u_c = Phi_c q + g_res f_c.
    """

    config: MasvConfig
    blocks: tuple[StateSpace, ...]
    moment_arms_m: np.ndarray
    phi_c: np.ndarray
    omega_rad_s: np.ndarray
    zeta: np.ndarray
    g_res: np.ndarray
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        return self.config.actuator_names

    @property
    def n_actuators(self) -> int:
        return len(self.blocks)

    # -- the whole as one state space ---------------------------------------------------------
    def state_space(self) -> StateSpace:
        """One StateSpace of the whole: states [each block's states, q, q'], inputs the eight
        commands ``<actuator>.command_rad``, outputs ``<actuator>.x_p_m`` then
        ``<actuator>.theta_rad`` (all eight position loops closed)."""
        if "ss" in self._cache:
            return self._cache["ss"]
        na, nm = self.n_actuators, self.omega_rad_s.size
        m = 2 * na
        sizes = [b.A.shape[0] for b in self.blocks]
        off = np.concatenate([[0], np.cumsum(sizes)])
        nb = int(off[-1])
        N = nb + 2 * nm
        A = np.zeros((N, N))
        B = np.zeros((N, na))
        C = np.zeros((2 * na, N))
        Bc = np.zeros((nb, m))        # block state rates per coupling coordinate
        Cf = np.zeros((m, nb))        # coupling forces from block states
        Dfc = np.zeros((m, m))        # coupling forces directly from coupling coordinates
        ie, ir = BLOCK_INPUTS.index("elongation_m"), BLOCK_INPUTS.index("gimbal_rotation_rad")
        of, ot = BLOCK_OUTPUTS.index("f_load_N"), BLOCK_OUTPUTS.index("spring_torque_Nm")
        for k, b in enumerate(self.blocks):
            sl = slice(off[k], off[k + 1])
            A[sl, sl] = b.A
            B[sl, k] = b.B[:, 0]
            C[k, sl] = b.C[0]
            C[na + k, sl] = b.C[1]
            Bc[sl, k] = b.B[:, ie]
            Bc[sl, na + k] = b.B[:, ir]
            Cf[k, sl] = b.C[of]
            Cf[na + k, sl] = b.C[ot]
            Dfc[k, k] = b.D[of, ie]
            Dfc[na + k, na + k] = b.D[ot, ir]
        # coupling coordinates as a row map over the state: u_c = Phi_c q + g_res f_c with
        # f_c = Cf x_b + Dfc u_c, i.e. u_c = W (Phi_c q + g_res Cf x_b), W = (I - g_res Dfc)^-1
        U = np.zeros((m, N))
        W = np.linalg.inv(np.eye(m) - self.g_res @ Dfc)
        U[:, :nb] = W @ self.g_res @ Cf
        if nm:
            U[:, nb:nb + nm] = W @ self.phi_c
        Fc = np.zeros((m, N))
        Fc[:, :nb] = Cf
        Fc += Dfc @ U
        A[:nb] += Bc @ U
        if nm:
            iq = slice(nb, nb + nm)
            iv = slice(nb + nm, N)
            A[iq, iv] = np.eye(nm)
            A[iv] += self.phi_c.T @ Fc
            A[iv, iq] -= np.diag(self.omega_rad_s ** 2)
            A[iv, iv] -= np.diag(2.0 * self.zeta * self.omega_rad_s)
        names = self.actuator_names
        states = tuple(f"{names[k]}.{s}" for k, b in enumerate(self.blocks) for s in b.states) + tuple(
            f"mode_{i + 1}.q" for i in range(nm)) + tuple(f"mode_{i + 1}.qdot" for i in range(nm))
        ss = StateSpace(A, B, C, np.zeros((2 * na, na)), states, tuple(f"{a}.command_rad" for a in names),
                        tuple(f"{a}.x_p_m" for a in names) + tuple(f"{a}.theta_rad" for a in names))
        self._cache["ss"] = ss
        return ss

    # -- fast exact frequency response --------------------------------------------------------
    def receptance(self, freq_hz) -> np.ndarray:
        """Structure receptance at the coupling coordinates, (F, m, m): u_c = R(j w) f_c."""
        f = np.atleast_1d(np.asarray(freq_hz, float))
        w = 2.0 * np.pi * f
        om = self.omega_rad_s
        h = 1.0 / (om[None] ** 2 - w[:, None] ** 2 + 2j * self.zeta[None] * om[None] * w[:, None])
        P = self.phi_c
        return (P[None] * h[:, None, :]) @ P.T + self.g_res[None]

    def frf(self, freq_hz) -> tuple[np.ndarray, np.ndarray]:
        """Exact responses by block elimination (module docstring): returns
        ``x_p`` (F, n_act, n_act) [m/rad] and ``theta`` (F, n_act, n_act) [rad/rad],
        element [f, i, j] from command j to output i."""
        f = np.atleast_1d(np.asarray(freq_hz, float))
        s = 2j * np.pi * f
        na = self.n_actuators
        m = 2 * na
        F = f.size
        Gyu = np.zeros((F, 2 * na, na), complex)
        Gyc = np.zeros((F, 2 * na, m), complex)
        Gfu = np.zeros((F, m, na), complex)
        Gfc = np.zeros((F, m, m), complex)
        for k, b in enumerate(self.blocks):
            g = _block_frd(b, s)               # (F, 4 outputs, 3 inputs)
            rows_y, rows_f, cols_c = (k, na + k), (k, na + k), (k, na + k)
            for a, ry in enumerate(rows_y):
                Gyu[:, ry, k] = g[:, a, 0]
                Gyc[:, ry, cols_c[0]] = g[:, a, 1]
                Gyc[:, ry, cols_c[1]] = g[:, a, 2]
            for a, rf in enumerate(rows_f):
                Gfu[:, rf, k] = g[:, 2 + a, 0]
                Gfc[:, rf, cols_c[0]] = g[:, 2 + a, 1]
                Gfc[:, rf, cols_c[1]] = g[:, 2 + a, 2]
        if self.omega_rad_s.size or np.any(self.g_res):
            R = self.receptance(f)
            fc = np.linalg.solve(np.eye(m)[None] - Gfc @ R, Gfu)
            Y = Gyu + Gyc @ (R @ fc)
        else:
            Y = Gyu
        return Y[:, :na, :], Y[:, na:, :]

    def frf_dense(self, freq_hz) -> tuple[np.ndarray, np.ndarray]:
        """The same responses by a naive dense solve of (j w I - A) per frequency on the whole
        state space (the reference the block elimination is checked and timed against)."""
        ss = self.state_space()
        f = np.atleast_1d(np.asarray(freq_hz, float))
        A, B, C, _D = _balanced(ss)
        n = A.shape[0]
        out = np.empty((f.size, C.shape[0], B.shape[1]), complex)
        eye = np.eye(n)
        for i, fk in enumerate(f):
            out[i] = C @ scipy.linalg.solve(2j * np.pi * fk * eye - A, B)
        na = self.n_actuators
        return out[:, :na, :], out[:, na:, :]


def build_system(cfg: MasvConfig, structure: ModalStructure | None = None) -> MasvSystem:
    """Assemble the MASV model of ``cfg`` (optionally with another ``structure``, e.g. rigid or
    truncated, for comparisons)."""
    if structure is not None:
        from dataclasses import replace
        cfg = replace(cfg, structure=structure)
    blocks = []
    arms = []
    for a in cfg.actuators:
        model = cfg.engine(a.engine).model
        blocks.append(engine_axis_block(model, a.axis))
        arms.append(model.actuator.moment_arm_m)
    st = cfg.structure
    return MasvSystem(cfg, tuple(blocks), np.asarray(arms), coupling_shapes(cfg), st.omega_rad_s.copy(),
                      st.damping_ratio.copy(), residual_flexibility(cfg))
