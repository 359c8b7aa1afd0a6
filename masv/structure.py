"""Modal model of the core-stage thrust structure seen by the eight TVC actuators.

The elastic structure (core stage thrust structure, gimbal blocks, actuator attach fittings)
is represented by its ``n`` normal modes::

    q_i'' + 2 zeta_i w_i q_i' + w_i^2 q_i = phi_i . F          (mass-normalised, M = I)
    u(node, dof) = sum_i phi[i, node, dof] q_i

with ``w_i = 2 pi freq_hz[i]`` [rad/s], ``zeta_i`` viscous damping ratios (0.5 % by default,
the paper's conservative assumption, section 3.3), and ``phi`` the mass-normalised mode shapes
at the coupling nodes (each engine's gimbal point and each actuator's attach point; any
number, any names: the shipped SLS file has the twelve of :data:`NODE_NAMES`): translations
in m/sqrt(kg), rotations in rad/sqrt(kg) (numerically 1/sqrt(kg) and 1/(sqrt(kg) m): with
u = phi q the kinetic energy is 1/2 |q'|^2), vehicle frame (x along the vehicle axis forward,
y and z lateral). No modes means a rigid structure. The format of every file and key:
``docs/reference/masv_files.md``; FE results (Universal File 55, Nastran punch) are read by
:mod:`masv.fe_import`.

The engines are MASV's (:mod:`masv.system`): their rotation always, and their translational
mass m_e at the gimbal unless the modal model already lumps it there
(``engine_mass_in_modes``; the shipped FEM does not, the synthetic truss does).

File contract (``fem_data/thrust_structure_modes.npz``, with a sidecar ``.toml`` holding its
provenance): ``freq_hz`` (n,), ``damping_ratio`` (n,), ``node_names`` (N,),
``node_xyz_m`` (N, 3), ``phi`` (n, N, 6). :func:`load_modes` validates a user's file the
same way (one-line :class:`~taos.errors.InputError` on NaN, wrong shapes, negative
frequencies, missing node names).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from taos.errors import InputError

#: The twelve coupling nodes of the shipped SLS layout (four engines), in order.
NODE_NAMES = tuple([f"gimbal_{e}" for e in range(1, 5)]
                   + [f"actuator_{e}_{ax}" for e in range(1, 5) for ax in ("pitch", "yaw")])

#: Paper section 3.3: "structural modes are conservatively assumed to have 0.5 % viscous damping".
DEFAULT_DAMPING_RATIO = 0.005


@dataclass(frozen=True, eq=False)
class ModalStructure:
    """Modal structure (SI): ``freq_hz`` (n,) [Hz], ``damping_ratio`` (n,) [-],
    ``node_names`` (N,), ``node_xyz_m`` (N, 3) [m], ``phi`` (n, N, 6) mass-normalised shapes
    [m/sqrt(kg) for dofs 0-2, rad/sqrt(kg) for dofs 3-5]; ``source`` the file it came from.

    ``residual_freq_hz``/``residual_phi``: modes dropped by :meth:`truncated` whose static
    flexibility sum phi phi^T / w^2 [m/N] is kept as a massless compliance (static correction,
    "residual flexibility"; Craig and Kurdila, *Fundamentals of Structural Dynamics*, 2006,
    sec. 13.3) so that truncation loses only the dropped modes' inertia, not their compliance.

    ``engine_mass_in_modes``: True when the modes already carry the engines' translational mass
    lumped at the gimbal nodes (MASV then adds only the engines' rotation and c.g. coupling)."""

    freq_hz: np.ndarray
    damping_ratio: np.ndarray
    node_names: tuple[str, ...]
    node_xyz_m: np.ndarray
    phi: np.ndarray
    source: str = "<code>"
    residual_freq_hz: np.ndarray | None = None
    residual_phi: np.ndarray | None = None
    engine_mass_in_modes: bool = False

    @property
    def n_modes(self) -> int:
        return int(self.freq_hz.size)

    @property
    def omega_rad_s(self) -> np.ndarray:
        return 2.0 * np.pi * self.freq_hz

    def node_index(self, name: str, source: str = "<code>", field: str = "node") -> int:
        """Index of node ``name``; InputError naming ``source``/``field`` when absent."""
        try:
            return self.node_names.index(name)
        except ValueError:
            raise InputError(source, field, "one of the modal file's nodes (" + ", ".join(self.node_names) + ")",
                             got=repr(name)) from None

    def node_position(self, name: str) -> np.ndarray:
        return self.node_xyz_m[self.node_index(name)]

    def with_damping(self, zeta: float) -> "ModalStructure":
        """The same modes with every damping ratio set to ``zeta`` [-]."""
        return ModalStructure(self.freq_hz, np.full_like(self.freq_hz, float(zeta)), self.node_names,
                              self.node_xyz_m, self.phi, self.source, self.residual_freq_hz, self.residual_phi,
                              self.engine_mass_in_modes)

    def truncated(self, max_freq_hz: float, static_correction: bool = True) -> "ModalStructure":
        """Only the modes at or below ``max_freq_hz`` [Hz]; with ``static_correction`` the
        dropped modes' static flexibility is kept (class docstring)."""
        keep = self.freq_hz <= max_freq_hz
        rf, rp = None, None
        if static_correction:
            rf = np.concatenate([self.freq_hz[~keep]] + ([self.residual_freq_hz] if self.residual_freq_hz is not None
                                                        else []))
            rp = np.concatenate([self.phi[~keep]] + ([self.residual_phi] if self.residual_phi is not None else []))
        return ModalStructure(self.freq_hz[keep], self.damping_ratio[keep], self.node_names,
                              self.node_xyz_m, self.phi[keep], self.source, rf, rp, self.engine_mass_in_modes)

    def translation(self, node: str) -> np.ndarray:
        """(n, 3) translational shapes at ``node`` [m/sqrt(kg)]."""
        return self.phi[:, self.node_index(node), 0:3]

    def rotation(self, node: str) -> np.ndarray:
        """(n, 3) rotational shapes at ``node`` [rad/sqrt(kg)]."""
        return self.phi[:, self.node_index(node), 3:6]


def rigid_structure(node_names=NODE_NAMES, node_xyz_m=None) -> ModalStructure:
    """A structure without modes (rigid): the actuators see only their own load stiffness."""
    names = tuple(node_names)
    xyz = np.zeros((len(names), 3)) if node_xyz_m is None else np.asarray(node_xyz_m, float)
    return ModalStructure(np.zeros(0), np.zeros(0), names, xyz, np.zeros((0, len(names), 6)), "<rigid>")


def validate_modes(freq_hz, damping_ratio, node_names, node_xyz_m, phi, source: str = "<code>",
                   required_nodes=()) -> ModalStructure:
    """Check arrays against the file contract and return a :class:`ModalStructure`.

    ``required_nodes``: names the file must hold (the configuration checks the nodes it names
    itself; :data:`NODE_NAMES` is the shipped four-engine layout's).

    Raises InputError (one line: source, field, expectation) on a wrong shape, NaN/inf,
    a negative or zero frequency, a negative damping ratio, or a missing or repeated node name.
    """
    def arr(x, field):
        try:
            a = np.asarray(x, dtype=float)
        except (TypeError, ValueError):
            raise InputError(source, field, "a numeric array", got=type(x).__name__) from None
        if not np.all(np.isfinite(a)):
            raise InputError(source, field, "finite numbers", got="NaN or infinity")
        return a

    f = arr(freq_hz, "freq_hz")
    if f.ndim != 1:
        raise InputError(source, "freq_hz", "a 1-D array of mode frequencies in Hz", got=f"shape {f.shape}")
    n = f.size
    if np.any(f <= 0):
        raise InputError(source, "freq_hz", "positive frequencies in Hz (elastic modes only)",
                         got=f"{f[f <= 0][0]!r}")
    z = arr(damping_ratio, "damping_ratio")
    if z.shape != (n,):
        raise InputError(source, "damping_ratio", f"shape ({n},) like freq_hz", got=f"shape {z.shape}")
    if np.any(z < 0) or np.any(z >= 1):
        raise InputError(source, "damping_ratio", "damping ratios in [0, 1)", got=f"{z[(z < 0) | (z >= 1)][0]!r}")
    try:
        names = tuple(str(s) for s in np.asarray(node_names).ravel())
    except Exception:  # noqa: BLE001 - any unreadable names array
        raise InputError(source, "node_names", "an array of node-name strings") from None
    if len(set(names)) != len(names):
        raise InputError(source, "node_names", "distinct node names", got="a repeated name")
    for req in required_nodes:
        if req not in names:
            raise InputError(source, "node_names", "the nodes " + ", ".join(required_nodes),
                             got=f"no {req!r}")
    xyz = arr(node_xyz_m, "node_xyz_m")
    if xyz.shape != (len(names), 3):
        raise InputError(source, "node_xyz_m", f"shape ({len(names)}, 3)", got=f"shape {xyz.shape}")
    p = arr(phi, "phi")
    if p.shape != (n, len(names), 6):
        raise InputError(source, "phi", f"shape ({n}, {len(names)}, 6) (modes, nodes, dofs)", got=f"shape {p.shape}")
    order = np.argsort(f, kind="stable")
    return ModalStructure(f[order], z[order], names, xyz, p[order], source)


def load_modes(path, required_nodes=()) -> ModalStructure:
    """Read a modal file (.npz with the contract's keys) and validate it (see module docstring)."""
    src = str(path)
    try:
        with np.load(path, allow_pickle=False) as d:
            data = {k: d[k] for k in d.files}
    except FileNotFoundError:
        raise InputError(src, "(file)", "an existing .npz modal file", got="no such file") from None
    except (OSError, ValueError) as e:
        raise InputError(src, "(file)", "a readable .npz modal file", got=str(e).splitlines()[0] if str(e) else
                         type(e).__name__) from None
    for key in ("freq_hz", "damping_ratio", "node_names", "node_xyz_m", "phi"):
        if key not in data:
            raise InputError(src, key, "an array in the modal file", got="nothing (key missing)")
    return validate_modes(data["freq_hz"], data["damping_ratio"], data["node_names"], data["node_xyz_m"],
                          data["phi"], source=src, required_nodes=required_nodes)
