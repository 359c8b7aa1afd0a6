"""A synthetic, mirror-symmetric thrust structure for tests and benchmarks (not the FEM).

A lumped-mass truss: the twelve coupling nodes of the contract plus ``4 * n_internal`` internal
nodes (random points in the y > 0, z > 0 quadrant mirrored into the other three), joined by
axial springs k_ij e_ij e_ij^T between every pair closer than ``reach_m``, each node tied to
ground (the rest of the vehicle) by an isotropic spring and carrying an isotropic rotational
inertia on an isotropic rotational spring. The layout and every spring are invariant under the
two mirrors y -> -y and z -> -z, so engines mirrored into each other see the same structure.
Modes by ``scipy.linalg.eigh(K, M)`` (mass-normalised); shapes kept at the twelve nodes only.

Layout (vehicle frame, x forward): gimbal e at (0, s_y d, s_z d); the pitch actuator of engine
e attaches at (h, s_y d, s_z (d + R)) and the yaw actuator at (h, s_y (d + R), s_z d), both
with line of action -x (axial actuators pushing aft on the engine), so the geometric moment
arm about the gimbal is R. Engine signs: 1 (+,+), 2 (-,+), 3 (-,-), 4 (+,-).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .config import ActuatorSpec, EngineSpec, default_rotation_axis
from .structure import NODE_NAMES, ModalStructure

ENGINE_SIGNS = ((1, 1), (-1, 1), (-1, -1), (1, -1))


def layout_xyz(d_m: float = 1.2, arm_m: float = 0.8, height_m: float = 1.5) -> np.ndarray:
    """(12, 3) coordinates of the contract's nodes in the layout above [m]."""
    xyz = [(0.0, sy * d_m, sz * d_m) for sy, sz in ENGINE_SIGNS]
    for sy, sz in ENGINE_SIGNS:
        xyz.append((height_m, sy * d_m, sz * (d_m + arm_m)))    # pitch attach
        xyz.append((height_m, sy * (d_m + arm_m), sz * d_m))    # yaw attach
    return np.asarray(xyz)


def synthetic_structure(n_internal: int = 6, seed: int = 0, *, node_mass_kg: float = 16000.0,
                        gimbal_mass_kg: float = 16000.0, spring_N_per_m: float = 1e8,
                        ground_N_per_m: float = 5e7, rot_inertia_kgm2: float = 1000.0,
                        rot_stiffness_Nm_per_rad: float = 2.5e9, reach_m: float = 2.2,
                        n_modes: int | None = None, damping_ratio: float = 0.005) -> ModalStructure:
    """Mirror-symmetric lumped truss (module docstring). Gimbal nodes carry the engine's
    translational mass ``gimbal_mass_kg`` [kg] (``engine_mass_in_modes`` is set: MASV adds only
    the engines' rotation and c.g. coupling); spring constants in N/m, N m/rad; ``n_modes``
    keeps the lowest modes (all 6 (12 + 4 n_internal) by default)."""
    rng = np.random.default_rng(seed)
    base = layout_xyz()
    quad = np.column_stack([rng.uniform(-0.5, 3.0, n_internal), rng.uniform(0.2, 2.2, n_internal),
                            rng.uniform(0.2, 2.2, n_internal)])
    internal = np.concatenate([quad * np.array([1.0, sy, sz]) for sy, sz in ENGINE_SIGNS]) if n_internal else \
        np.zeros((0, 3))
    xyz = np.concatenate([base, internal])
    N = xyz.shape[0]
    mass = np.full(N, node_mass_kg)
    mass[:4] = gimbal_mass_kg
    K = np.zeros((6 * N, 6 * N))
    for i in range(N):
        ti = slice(6 * i, 6 * i + 3)
        K[ti, ti] += ground_N_per_m * np.eye(3) * (1.0 + 0.5 * xyz[i, 0])  # stiffer forward (towards the stage)
        ri = slice(6 * i + 3, 6 * i + 6)
        K[ri, ri] += rot_stiffness_Nm_per_rad * np.eye(3)
        for j in range(i + 1, N):
            dv = xyz[j] - xyz[i]
            L = float(np.linalg.norm(dv))
            if L > reach_m or L < 1e-9:
                continue
            e = dv / L
            k = spring_N_per_m * np.outer(e, e) / L
            tj = slice(6 * j, 6 * j + 3)
            K[ti, ti] += k
            K[tj, tj] += k
            K[ti, tj] -= k
            K[tj, ti] -= k
    Mdiag = np.column_stack([mass, mass, mass] + [np.full(N, rot_inertia_kgm2)] * 3).ravel()  # per node m,m,m,I,I,I
    w2, V = scipy.linalg.eigh(K, np.diag(Mdiag))
    nk = w2.size if n_modes is None else int(n_modes)
    freq = np.sqrt(np.maximum(w2[:nk], 0.0)) / (2 * np.pi)
    phi = V[:12 * 6, :nk].T.reshape(nk, 12, 6)
    return ModalStructure(freq, np.full(nk, damping_ratio), NODE_NAMES, base, phi, "<synthetic truss>",
                          engine_mass_in_modes=True)


def core_stage_specs(models, structure: ModalStructure):
    """Engines and actuators of the four-engine layout for ``models`` (one taos TvcModel, or four),
    with axial lines of action (-x) and rotation axes from the geometry."""
    if not isinstance(models, (list, tuple)):
        models = [models] * 4
    engines = tuple(EngineSpec(f"engine_{e}", models[e - 1], f"gimbal_{e}") for e in range(1, 5))
    acts = []
    n = np.array([-1.0, 0.0, 0.0])
    for e in range(1, 5):
        for ax in ("pitch", "yaw"):
            node = f"actuator_{e}_{ax}"
            a = default_rotation_axis(structure, f"gimbal_{e}", node, n)
            acts.append(ActuatorSpec(node, f"engine_{e}", ax, node, tuple(n), tuple(a)))
    return engines, tuple(acts)
