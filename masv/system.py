"""The coupled MASV model: four engines, eight actuators, the thrust-structure modes
(paper sec. 1, "MASV"; the inertial servo-elastic coupling of sec. 3.3).

Pieces (SI)::

    engine axis k     taos.planar.simplex.simplex_state_space(structure_inputs=True): the one simplex
                      block (actuator, load path, engine axis) with the structure's motion as
                      inputs and its reactions on the structure as outputs:
      load path       F_L,k = K_L,k (x_p,k - R_k theta_k - e_k)                          [N]
      engine axis     J_k theta_k'' = R_k F_L,k - K_n,k (theta_k - r_k) - m_e l_k a_k      [N m]
      TWD force       f_twd,k = -m_e l_k theta_k''   on the gimbal along d_k               [N]
    command           x_c,k = R_k theta_c,k                                                [m]
    structure         q'' + 2 Z Om q' + Om^2 q = Phi_c^T f_c + Phi_G^T f_G     (modal, M = I)
    coupling coords   e_k = n_k . (u(gimbal_k) - u(attach_k)) = Phi_e,k q                  [m]
                      r_k = a_k . rot(gimbal_k)               = Phi_r,k q                  [rad]
                      g_j = u''(gimbal_j)                     = Phi_G,j q''  (3 per engine) [m/s^2]
                      a_k = d_k . g_j(k)                                                   [m/s^2]
    coupling forces   f_c = [F_L,k ; K_n,k (theta_k - r_k)],
                      f_G,j = -m_e,j g_j + sum_{k on j} d_k f_twd,k                        [N]

n_k is the actuator's unit line of action (structure attach -> engine attach) and a_k the engine
rotation axis of that actuator (rotation about a_k extends it). K_L is the taos model's
``[structure] load_stiffness``: the compliance outside the modal structure (gimbal, engine,
actuator case and attachments), in series with the modal structure. The actuator pushes the
engine (hence, through the gimbal, the gimbal node) along +n_k and the attach node along -n_k;
the feedline/gravity spring K_n acts between the engine and the structure's gimbal rotation.
Both follow from the potential 1/2 K_L delta_k^2 + 1/2 K_n (theta_k - r_k)^2, so the
interconnection is energy-consistent.

Engine inertia (tail wags dog / dog wags tail): engine j, mass m_e, has its centre of mass at
c_j from the gimbal (:attr:`masv.config.EngineSpec.cg_vector_m`). Turning it by theta_k about
a_k moves the c.g. by theta_k v_k, v_k = a_k x c_j = l_k d_k (l_k = |v_k| [m], d_k unit). Its
kinetic energy 1/2 m_e |u_g' + sum_k theta_k' v_k|^2 + 1/2 omega^T I_c omega (axes a_k
orthogonal to each other and to c_j; J_k = a_k^T (I_c + m_e (|c|^2 - c c^T)) a_k is the model's
J_n) gives the engine equation above and the force on the gimbal f_G = -m_e (g + sum_k l_k d_k
theta_k''): the engine is an added mass m_e at the gimbal plus the coupling term. The added mass
-m_e g is left out when the modal model already lumps the engine's mass at the gimbal
(``structure.engine_mass_in_modes``, e.g. the synthetic truss). The accelerations g enter
through the retained modes only (the residual flexibility below is massless).

With no modes the eight engine-axis blocks are independent and each is the planar simplex model
(taos.planar.simplex), the reduction checked by the tests.

Two views of the one model: :meth:`MasvSystem.state_space` assembles the whole as one
:class:`taos.linear.StateSpace` (eigenvalues, the naive reference response; the gimbal
accelerations make the modal mass I + Phi_G^T M_eff Phi_G, inverted once) and
:meth:`MasvSystem.frf` computes the same frequency response by block elimination: the
structure's receptance at the coupling coordinates, R(s) = W(s) Phi diag(1/(s^2 + 2 zeta w s +
w^2)) Phi^T with Phi = [Phi_c; Phi_G] and W = diag(1, .., s^2, ..) (accelerations), costs
O(n m^2) per frequency because the modal part is diagonal, and the engine blocks are small and
independent; closing f_c = G_fu u + G_fc u_c, u_c = R f_c leaves an m x m solve per frequency
(m = 2 x actuators + 3 x engines). Modes dropped by truncation may leave their static
flexibility g_res (a massless compliance in series, "static correction"): u_c = Phi_c q +
g_res f_c for e and r, i.e. R(s) + g_res in the frequency domain.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from taos.linear import StateSpace
from taos.model import TvcModel
from taos.planar.simplex import simplex_state_space

from .config import MasvConfig
from .structure import ModalStructure

BLOCK_INPUTS = ("command_rad", "elongation_m", "gimbal_rotation_rad", "gimbal_accel_m_s2")
BLOCK_OUTPUTS = ("x_p_m", "theta_rad", "load_force_N", "spring_torque_Nm", "twd_force_N")
_IN = {n: i for i, n in enumerate(BLOCK_INPUTS)}
_OUT = {n: i for i, n in enumerate(BLOCK_OUTPUTS)}


def engine_axis_block(model: TvcModel, axis: str, engine_cg_offset_m: float = 0.0) -> StateSpace:
    """One actuator driving one engine axis, with the structure's motion as inputs: the simplex
    block :func:`taos.planar.simplex.simplex_state_space` (``structure_inputs=True``), friction input
    left at zero.

    Inputs: ``command_rad`` theta_c [rad] (x_c = R theta_c), ``elongation_m`` e [m] (structure
    motion along the line of action, gimbal minus attach point), ``gimbal_rotation_rad`` r [rad],
    ``gimbal_accel_m_s2`` a [m/s^2] (gimbal acceleration along d). Outputs: ``x_p_m``,
    ``theta_rad``, ``load_force_N`` = K_L (x_p - R theta - e), ``spring_torque_Nm`` =
    K_n (theta - r), ``twd_force_N`` = -m_e l_e theta'' [N]. ``engine_cg_offset_m`` l_e [m].
    The taos load-path damping (``[structure] load_damping_ratio``) is off here: MASV's structural
    damping is modal (the structure's own damping ratios)."""
    ss = full_block(model, axis, engine_cg_offset_m)
    ii = [ss.input_index(n) for n in BLOCK_INPUTS]
    oo = [ss.output_index(n) for n in BLOCK_OUTPUTS]
    return StateSpace(ss.A, ss.B[:, ii], ss.C[oo], ss.D[np.ix_(oo, ii)], ss.states, BLOCK_INPUTS, BLOCK_OUTPUTS)


def full_block(model: TvcModel, axis: str, engine_cg_offset_m: float = 0.0) -> StateSpace:
    """The simplex block with every input (command, friction torque, e, r, a_g) and the
    structure outputs, load-path damping off (MASV's damping is modal): the block
    :func:`engine_axis_block` and the time domain (:mod:`masv.coupled`) take their parts of."""
    import dataclasses
    model = model.replace(structure=dataclasses.replace(model.structure, load_damping_ratio=0.0))
    return simplex_state_space(model, axis, structure_inputs=True, engine_cg_offset_m=engine_cg_offset_m)


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


def gimbal_shapes(cfg: MasvConfig) -> np.ndarray:
    """Phi_G (3 n_eng, n_modes): translations of each engine's gimbal node [m/sqrt(kg)], engine
    order, vehicle x, y, z."""
    st = cfg.structure
    out = np.zeros((3 * len(cfg.engines), st.n_modes))
    if st.n_modes:
        for j, e in enumerate(cfg.engines):
            out[3 * j:3 * j + 3] = st.phi[:, st.node_index(e.gimbal_node), 0:3].T
    return out


def cg_lever_arms(cfg: MasvConfig) -> tuple[np.ndarray, np.ndarray]:
    """Per actuator k: l_k = |a_k x c| [m] and the unit direction d_k (n_act, 3) of the engine
    c.g.'s motion for a positive theta_k (zero where l_k = 0); c the engine's c.g. offset."""
    na = len(cfg.actuators)
    arms, dirs = np.zeros(na), np.zeros((na, 3))
    for k, a in enumerate(cfg.actuators):
        v = np.cross(np.asarray(a.rotation_axis, float), cfg.engine(a.engine).cg_vector_m)
        arms[k] = float(np.linalg.norm(v))
        if arms[k] > 0:
            dirs[k] = v / arms[k]
    return arms, dirs


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
    R_k [m], ``phi_c`` the coupling shapes (:func:`coupling_shapes`), ``phi_g`` the gimbal
    translations (:func:`gimbal_shapes`), ``engine_of`` the engine index of each actuator,
    ``cg_dirs`` the unit directions d_k (n_act, 3), ``added_mass_kg`` the mass each engine adds
    at its gimbal (m_e, or 0 when the modes already hold it), ``omega_rad_s`` and ``zeta`` the
    modal frequencies [rad/s] and damping ratios [-], ``g_res`` the residual flexibility of
    truncated modes at the coupling coordinates (:func:`residual_flexibility`), a massless
    compliance in series: u_c = Phi_c q + g_res f_c.
    """

    config: MasvConfig
    blocks: tuple[StateSpace, ...]
    moment_arms_m: np.ndarray
    phi_c: np.ndarray
    omega_rad_s: np.ndarray
    zeta: np.ndarray
    g_res: np.ndarray
    phi_g: np.ndarray
    engine_of: np.ndarray
    cg_dirs: np.ndarray
    added_mass_kg: np.ndarray
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        return self.config.actuator_names

    @property
    def n_actuators(self) -> int:
        return len(self.blocks)

    @property
    def n_coupling(self) -> int:
        """m = 2 n_act + 3 n_eng coupling coordinates [e; r; g]."""
        return 2 * self.n_actuators + self.phi_g.shape[0]

    def _gcols(self, k: int) -> slice:
        """Columns of actuator k's engine gimbal acceleration in the coupling coordinates."""
        o = 2 * self.n_actuators + 3 * int(self.engine_of[k])
        return slice(o, o + 3)

    # -- the whole as one state space ---------------------------------------------------------
    def state_space(self) -> StateSpace:
        """One StateSpace of the whole: states [each block's states, q, q'], inputs the eight
        commands ``<actuator>.command_rad``, outputs ``<actuator>.x_p_m`` then
        ``<actuator>.theta_rad`` (all eight position loops closed); assembled by
        :func:`masv.coupled.assemble` (the time domain's assembly, with only the commands open)."""
        if "ss" in self._cache:
            return self._cache["ss"]
        cm = self.coupled(("command_rad",))
        na, nm = self.n_actuators, self.omega_rad_s.size
        C = np.vstack([cm.output_rows(k, o)[0] for o in ("x_p_m", "theta_rad") for k in range(na)])
        names = self.actuator_names
        states = tuple(f"{names[k]}.{s}" for k, b in enumerate(self.blocks) for s in b.states) + tuple(
            f"mode_{i + 1}.q" for i in range(nm)) + tuple(f"mode_{i + 1}.qdot" for i in range(nm))
        ss = StateSpace(cm.A, cm.B, C, np.zeros((2 * na, na)), states, tuple(f"{a}.command_rad" for a in names),
                        tuple(f"{a}.x_p_m" for a in names) + tuple(f"{a}.theta_rad" for a in names))
        self._cache["ss"] = ss
        return ss

    def coupled(self, ext=("command_rad",), torque_reaction: bool = False):
        """The whole as a :class:`masv.coupled.CoupledModel` with the block inputs ``ext`` open
        (:func:`masv.coupled.assemble`)."""
        from .coupled import assemble

        full = tuple(full_block(self.config.engine(a.engine).model, a.axis, self._cg_arm(k))
                     for k, a in enumerate(self.config.actuators))
        return assemble(full, self.phi_c, self.phi_g, self.omega_rad_s, self.zeta, self.g_res, self.engine_of,
                        self.cg_dirs, self.added_mass_kg, ext, torque_reaction)

    def _cg_arm(self, k: int) -> float:
        return float(cg_lever_arms(self.config)[0][k])

    # -- fast exact frequency response --------------------------------------------------------
    def receptance(self, freq_hz) -> np.ndarray:
        """Structure receptance at the coupling coordinates, (F, m, m): u_c = R(j w) f_c with
        u_c = [e; r; g] (g gimbal accelerations, hence the factor s^2 on their rows) and
        f_c = [F_L; K_n (theta - r); f_G]."""
        f = np.atleast_1d(np.asarray(freq_hz, float))
        w = 2.0 * np.pi * f
        om = self.omega_rad_s
        h = 1.0 / (om[None] ** 2 - w[:, None] ** 2 + 2j * self.zeta[None] * om[None] * w[:, None])
        P = np.vstack([self.phi_c, self.phi_g])
        md = 2 * self.n_actuators
        m = P.shape[0]
        # R[f] = P diag(h_f) P^T for all f as two real GEMMs: (m m, n) @ (n, F)
        Q = (P[:, None, :] * P[None, :, :]).reshape(m * m, -1)
        R = (Q @ h.real.T + 1j * (Q @ h.imag.T)).T.reshape(f.size, m, m)
        R[:, md:, :] *= -(w ** 2)[:, None, None]
        R[:, :md, :md] += self.g_res[None]
        return R

    def _pieces(self, f: np.ndarray):
        """Frequency-domain pieces of the block elimination: (Gyu, Gyc, Gfu, Gfc, Gtw) with
        y = Gyu u + Gyc u_c, f_c = Gfu u + Gfc u_c, and Gtw (F, n_act, m) each block's own
        TWD-force response to the coupling coordinates (for loop breaks)."""
        s = 2j * np.pi * f
        na, m, F = self.n_actuators, self.n_coupling, f.size
        Gyu = np.zeros((F, 2 * na, na), complex)
        Gyc = np.zeros((F, 2 * na, m), complex)
        Gfu = np.zeros((F, m, na), complex)
        Gfc = np.zeros((F, m, m), complex)
        Gtw = np.zeros((F, na, m), complex)
        md = 2 * na
        for j in range(self.phi_g.shape[0] // 3):
            Gfc[:, md + 3 * j:md + 3 * j + 3, md + 3 * j:md + 3 * j + 3] -= self.added_mass_kg[j] * np.eye(3)
        for k, b in enumerate(self.blocks):
            g = _block_frd(b, s)               # (F, 5 outputs, 4 inputs)
            gs, d = self._gcols(k), self.cg_dirs[k]

            def row(o, g=g, gs=gs, d=d, k=k):
                r = np.zeros((F, m), complex)
                r[:, k] = g[:, o, 1]
                r[:, na + k] = g[:, o, 2]
                r[:, gs] = g[:, o, 3][:, None] * d[None]
                return r
            for ry, o in ((k, _OUT["x_p_m"]), (na + k, _OUT["theta_rad"])):
                Gyu[:, ry, k] = g[:, o, 0]
                Gyc[:, ry] = row(o)
            for rf, o in ((k, _OUT["load_force_N"]), (na + k, _OUT["spring_torque_Nm"])):
                Gfu[:, rf, k] = g[:, o, 0]
                Gfc[:, rf] += row(o)
            tw = row(_OUT["twd_force_N"])
            Gtw[:, k] = tw
            Gfu[:, gs, k] += g[:, _OUT["twd_force_N"], 0][:, None] * d[None]
            Gfc[:, gs] += d[None, :, None] * tw[:, None, :]
        return Gyu, Gyc, Gfu, Gfc, Gtw

    def frf(self, freq_hz) -> tuple[np.ndarray, np.ndarray]:
        """Exact responses by block elimination (module docstring): returns
        ``x_p`` (F, n_act, n_act) [m/rad] and ``theta`` (F, n_act, n_act) [rad/rad],
        element [f, i, j] from command j to output i."""
        f = np.atleast_1d(np.asarray(freq_hz, float))
        na, m = self.n_actuators, self.n_coupling
        Gyu, Gyc, Gfu, Gfc, _ = self._pieces(f)
        if self.omega_rad_s.size or np.any(self.g_res):
            R = self.receptance(f)
            fc = np.linalg.solve(np.eye(m)[None] - Gfc @ R, Gfu)
            Y = Gyu + Gyc @ (R @ fc)
        else:
            Y = Gyu
        return Y[:, :na, :], Y[:, na:, :]

    def tvse_loop(self, freq_hz, actuator: int | None = None) -> np.ndarray:
        """Thrust Vector Servo Elastic (TVSE) loop of actuator index ``actuator``, (F,) complex,
        or of every actuator (F, n_act) when None: the loop broken at that engine axis's
        inertial coupling into the structure (paper sec. 3.3: "an open loop break between the
        flexible body dynamics and the nozzle inertial coupling (DWT/TWD interface)"). A force
        f on the gimbal along d_k drives the structure with everything else closed (all
        position loops at zero command, the other axes' TWD forces, the load paths, the engines'
        added mass); the broken block's own response to that motion is its TWD force f_twd,k.
        L = -f_twd,k / f (the loop closes positively through f = f_twd,k, so 1 + L = 0 is the
        critical point of :func:`masv.analysis.margins_from_loop`). Zero on a rigid structure
        or with no c.g. offset."""
        f = np.atleast_1d(np.asarray(freq_hz, float))
        m, na = self.n_coupling, self.n_actuators
        ks = range(na) if actuator is None else [actuator]
        out = np.zeros((f.size, len(ks)), complex)
        if self.omega_rad_s.size:
            _, _, _, Gfc, Gtw = self._pieces(f)
            R = self.receptance(f)
            for i, k in enumerate(ks):
                inj = np.zeros(m)                       # d_k at the broken engine's gimbal force rows
                inj[self._gcols(k)] = self.cg_dirs[k]
                Gk = Gfc - inj[None, :, None] * Gtw[:, k][:, None, :]   # cut f_twd,k out of f_G
                uc = np.linalg.solve(np.eye(m)[None] - R @ Gk, (R @ inj)[..., None])[..., 0]
                out[:, i] = -np.einsum("fm,fm->f", Gtw[:, k], uc)
        return out if actuator is None else out[:, 0]

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
    arms_cg, dirs = cg_lever_arms(cfg)
    eidx = {e.name: j for j, e in enumerate(cfg.engines)}
    blocks = []
    arms = []
    for k, a in enumerate(cfg.actuators):
        model = cfg.engine(a.engine).model
        blocks.append(engine_axis_block(model, a.axis, float(arms_cg[k])))
        arms.append(model.actuator.moment_arm_m)
    st = cfg.structure
    added = np.array([0.0 if st.engine_mass_in_modes else e.model.engine.mass_kg for e in cfg.engines])
    phi_g = gimbal_shapes(cfg)
    if st.engine_mass_in_modes and st.n_modes:
        _check_lumped_engine_mass(cfg, phi_g, arms_cg, dirs)
    return MasvSystem(cfg, tuple(blocks), np.asarray(arms), coupling_shapes(cfg), st.omega_rad_s.copy(),
                      st.damping_ratio.copy(), residual_flexibility(cfg), phi_g,
                      np.array([eidx[a.engine] for a in cfg.actuators]), dirs, added)


def _check_lumped_engine_mass(cfg: MasvConfig, phi_g: np.ndarray, arms: np.ndarray, dirs: np.ndarray) -> None:
    """With the engines' mass lumped in the modes, the engines' free rotation removes
    m_e^2 l_k^2 / J_k along d_k from it; the modal mass I - Phi_G^T (sum d d^T m^2 l^2/J) Phi_G
    must stay positive definite (the modes must lump at least that much mass at the gimbal)."""
    ne = len(cfg.engines)
    eidx = {e.name: j for j, e in enumerate(cfg.engines)}
    D = np.zeros((3 * ne, 3 * ne))
    for k, a in enumerate(cfg.actuators):
        e = cfg.engine(a.engine)
        j = 3 * eidx[a.engine]
        D[j:j + 3, j:j + 3] += (e.model.engine.mass_kg * arms[k]) ** 2 / e.model.engine.inertia(a.axis) \
            * np.outer(dirs[k], dirs[k])
    if np.linalg.eigvalsh(np.eye(phi_g.shape[1]) - phi_g.T @ D @ phi_g).min() <= 0:
        from taos.errors import InputError
        raise InputError(cfg.source, "structure.engine_mass_in_modes",
                         "modes that lump at least m_e^2 l_e^2 / J_n of each engine's mass at its gimbal "
                         "(or false: MASV then adds the engine mass)", got="true")
