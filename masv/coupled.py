"""The coupled MASV model as one linear state space with chosen block inputs left open.

:meth:`masv.system.MasvSystem.state_space` (inputs: the commands) and the nonlinear time
domain (:mod:`masv.timedomain`; inputs: the post-avionics commands and the engines' gimbal
torques, friction and hard stop, that the compiled kernel closes) are both this assembly.

Each engine-axis block k is :func:`taos.planar.simplex.simplex_state_space` with
``structure_inputs=True`` (inputs ``command_rad``, ``friction_torque_Nm``, e, r, a_g; outputs
:data:`taos.planar.simplex.SIMPLEX_OUTPUTS`, K_n (theta - r), f_twd). Equations as in
:mod:`masv.system`::

    x_k'  = A_k x_k + B_k,ext w_k + B_k,e e_k + B_k,r r_k + B_k,a a_k
    u_c   = [e; r] = W (Phi_c q + g_res f_c),  W = (I - g_res D_fc)^-1        (residual flexibility)
    f_c   = [F_L,k ; K_n (theta_k - r_k) + rho T_k]                               [N, N m]
    S q'' = -Om^2 q - 2 Z Om q' + Phi_c^T f_c + Phi_G^T f_G,  S = I + Phi_G^T M_e Phi_G
    f_G,j = -m_e,j g_j + sum_{k on j} d_k f_twd,k,   g = Phi_G q'',  a_k = d_k . g_j(k)

w_k the open inputs of block k (its command, and with ``torque`` its gimbal torque T_k, which
enters the engine as the planar model's friction torque does: J theta'' = ... - T_k). With
``torque_reaction`` (rho = 1) the torque's reaction +T_k acts on the structure's rotation at the
gimbal (friction and stops act between engine and structure); rho = 0 leaves it out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from taos.planar.simplex import SIMPLEX_OUTPUTS, STRUCTURE_OUTPUTS

#: the full block's inputs and outputs (taos.planar.simplex.simplex_state_space, structure_inputs=True)
FULL_INPUTS = ("command_rad", "friction_torque_Nm", "elongation_m", "gimbal_rotation_rad", "gimbal_accel_m_s2")
FULL_OUTPUTS = SIMPLEX_OUTPUTS + STRUCTURE_OUTPUTS
_I = {n: i for i, n in enumerate(FULL_INPUTS)}
_O = {n: i for i, n in enumerate(FULL_OUTPUTS)}


@dataclass(frozen=True, eq=False)
class CoupledModel:
    """x' = A x + B w over x = [blocks' states, q, q'] (N,), w = [open input e of block k for
    e in ``ext``, k in actuator order] (n_ext n_act,). ``offsets`` (n_act + 1,) the blocks'
    first states, ``n_modes``; ``Ux``, ``Uw`` the coupling coordinates u_c = Ux x + Uw w
    (2 n_act rows [e; r]); ``Qx``, ``Qw`` the modal accelerations q'' = Qx x + Qw w; ``blocks``
    the full blocks, ``cg_dirs`` d_k, ``engine_of`` engine index per actuator. The same
    equations factored through q'' (the compiled time domain's form, fewer non-zeros):
    x' = ``A_direct`` x + ``B_direct`` w + ``Gq`` q'', with A = A_direct + Gq Qx and
    B = B_direct + Gq Qw (``Gq`` (N, n_modes): the gimbal accelerations' input into the
    blocks, and the identity on the modal-rate rows)."""

    A: np.ndarray
    B: np.ndarray
    ext: tuple[str, ...]
    offsets: np.ndarray
    n_modes: int
    Ux: np.ndarray
    Uw: np.ndarray
    Qx: np.ndarray
    Qw: np.ndarray
    phi_g: np.ndarray
    blocks: tuple
    cg_dirs: np.ndarray
    engine_of: np.ndarray
    torque_reaction: bool
    A_direct: np.ndarray
    B_direct: np.ndarray
    Gq: np.ndarray

    @property
    def n_act(self) -> int:
        return len(self.blocks)

    def w_index(self, name: str, k: int) -> int:
        return self.ext.index(name) * self.n_act + k

    def output_rows(self, k: int, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Block k's output ``name`` (:data:`FULL_OUTPUTS`) as y = cx . x + cw . w."""
        b, o, na = self.blocks[k], _O[name], self.n_act
        N = self.A.shape[0]
        cx, cw = np.zeros(N), np.zeros(self.B.shape[1])
        cx[self.offsets[k]:self.offsets[k + 1]] = b.C[o]
        for e in self.ext:
            cw[self.w_index(e, k)] += b.D[o, _I[e]]
        if name == "spring_torque_Nm" and self.torque_reaction and "friction_torque_Nm" in self.ext:
            cw[self.w_index("friction_torque_Nm", k)] += 1.0
        cx += b.D[o, _I["elongation_m"]] * self.Ux[k] + b.D[o, _I["gimbal_rotation_rad"]] * self.Ux[na + k]
        cw += b.D[o, _I["elongation_m"]] * self.Uw[k] + b.D[o, _I["gimbal_rotation_rad"]] * self.Uw[na + k]
        da = b.D[o, _I["gimbal_accel_m_s2"]]
        if da != 0.0 and self.n_modes:
            j = 3 * int(self.engine_of[k])
            g = self.cg_dirs[k] @ self.phi_g[j:j + 3]
            cx += da * (g @ self.Qx)
            cw += da * (g @ self.Qw)
        return cx, cw


def assemble(blocks, phi_c, phi_g, omega, zeta, g_res, engine_of, cg_dirs, added_mass_kg,
             ext=("command_rad",), torque_reaction: bool = False) -> CoupledModel:
    """Assemble the coupled model (module docstring) from the full blocks (one per actuator),
    the coupling shapes ``phi_c`` (2 n_act, n) and gimbal translations ``phi_g`` (3 n_eng, n)
    [m/sqrt(kg)], modal ``omega`` [rad/s] and ``zeta`` [-], the residual flexibility ``g_res``
    (2 n_act, 2 n_act) [m/N, rad/(N m)], each actuator's engine index and unit c.g. direction
    d_k, each engine's added mass at its gimbal [kg]; ``ext`` the open inputs (names of
    :data:`FULL_INPUTS`: ``command_rad`` and optionally ``friction_torque_Nm``)."""
    na, nm, ng = len(blocks), omega.size, phi_g.shape[0]
    md, ne = 2 * na, len(ext) * na
    sizes = [b.A.shape[0] for b in blocks]
    off = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    nb = int(off[-1])
    N = nb + 2 * nm
    A, B = np.zeros((N, N)), np.zeros((N, ne))
    Bc, Ba = np.zeros((nb, md)), np.zeros((nb, ng))
    Cf, Dfc, Dfw = np.zeros((md, nb)), np.zeros((md, md)), np.zeros((md, ne))
    Ct, Dtw, Dtc = np.zeros((ng, nb)), np.zeros((ng, ne)), np.zeros((ng, md))
    Dtg = -np.diag(np.repeat(added_mass_kg, 3))
    ie, ir, ia = _I["elongation_m"], _I["gimbal_rotation_rad"], _I["gimbal_accel_m_s2"]
    of, ot, otw = _O["load_force_N"], _O["spring_torque_Nm"], _O["twd_force_N"]
    for k, b in enumerate(blocks):
        sl = slice(off[k], off[k + 1])
        gs = slice(3 * int(engine_of[k]), 3 * int(engine_of[k]) + 3)
        d = cg_dirs[k]
        A[sl, sl] = b.A
        for i, e in enumerate(ext):
            c = i * na + k
            B[sl, c] = b.B[:, _I[e]]
            Dfw[k, c] = b.D[of, _I[e]]
            Dfw[na + k, c] = b.D[ot, _I[e]] + (1.0 if (e == "friction_torque_Nm" and torque_reaction) else 0.0)
            Dtw[gs, c] += d * b.D[otw, _I[e]]
        Bc[sl, k] = b.B[:, ie]
        Bc[sl, na + k] = b.B[:, ir]
        Ba[sl, gs] = np.outer(b.B[:, ia], d)
        Cf[k, sl] = b.C[of]
        Cf[na + k, sl] = b.C[ot]
        Dfc[k, k] = b.D[of, ie]
        Dfc[na + k, na + k] = b.D[ot, ir]
        Ct[gs, sl] += np.outer(d, b.C[otw])
        Dtc[gs, k] += d * b.D[otw, ie]
        Dtc[gs, na + k] += d * b.D[otw, ir]
        Dtg[gs, gs] += b.D[otw, ia] * np.outer(d, d)
    # u_c = W (Phi_c q + g_res f_c), f_c = Cf x_b + Dfc u_c + Dfw w
    W = np.linalg.inv(np.eye(md) - g_res @ Dfc)
    Ux, Uw = np.zeros((md, N)), W @ g_res @ Dfw
    Ux[:, :nb] = W @ g_res @ Cf
    if nm:
        Ux[:, nb:nb + nm] = W @ phi_c
    Fc = np.zeros((md, N))
    Fc[:, :nb] = Cf
    Fc += Dfc @ Ux
    Fw = Dfw + Dfc @ Uw
    A[:nb] += Bc @ Ux
    B[:nb] += Bc @ Uw
    Qx, Qw = np.zeros((nm, N)), np.zeros((nm, ne))
    A_direct, B_direct, Gq = A.copy(), B.copy(), np.zeros((N, nm))
    if nm:
        iq, iv = slice(nb, nb + nm), slice(nb + nm, N)
        Ft = np.zeros((ng, N))
        Ft[:, :nb] = Ct
        Ft += Dtc @ Ux
        Qx = phi_c.T @ Fc + phi_g.T @ Ft
        Qx[:, iq] -= np.diag(omega ** 2)
        Qx[:, iv] -= np.diag(2.0 * zeta * omega)
        Qw = phi_c.T @ Fw + phi_g.T @ (Dtw + Dtc @ Uw)
        S = np.eye(nm) - phi_g.T @ Dtg @ phi_g
        Qx, Qw = np.linalg.solve(S, Qx), np.linalg.solve(S, Qw)
        A[iq, iv] = np.eye(nm)
        A_direct, B_direct = A.copy(), B.copy()
        Gq[:nb] = Ba @ phi_g
        Gq[iv] = np.eye(nm)
        A[iv] += Qx
        B[iv] += Qw
        A[:nb] += Ba @ phi_g @ Qx
        B[:nb] += Ba @ phi_g @ Qw
    return CoupledModel(A, B, tuple(ext), off, nm, Ux, Uw, Qx, Qw, phi_g, tuple(blocks), np.asarray(cg_dirs),
                        np.asarray(engine_of), torque_reaction, A_direct, B_direct, Gq)
