"""RS-25 engine geometry (trimesh), mass properties about the gimbal, Pinocchio model.

Frame (the gimbal frame of fem_data/README.md): origin at the gimbal bearing centre O,
z along the engine axis from the engine towards the thrust structure (the engine hangs at
z < 0), x pitch-lateral (pitch rotates about y), y yaw-lateral (yaw rotates about x).

Public: dry mass 3,527 kg, length 4.3 m (gimbal bearing top, z = +0.145 m, to the nozzle
exit plane, z = -4.155 m), nozzle exit diameter 2.4 m. Notional (documented here):

* powerhead: a solid cylinder of radius 0.60 m from the engine's gimbal interface
  (z = -0.145 m) to the nozzle joint at z = -1.90 m (injector, main combustion chamber and
  the turbopumps smeared into one compact axisymmetric body), 2,742 kg;
* nozzle: a bell-shaped shell r(s) = r_j + (r_e - r_j) sqrt(s), s in [0, 1] from the joint
  (r_j = 0.33 m) to the exit (r_e = 1.20 m), 20 mm thick (coolant tubes and jackets
  smeared), 785 kg;
* the masses are shared so that the centre of mass lies 1.50 m below the gimbal (notional: the
  inertia about the gimbal is not public; 1.5 m makes a 3,500 kg engine's inertia near the
  12,000 kg m^2 of the model files).

Each part's density is its mass over its mesh volume; inertia comes from the meshes
(trimesh's exact polyhedral integrals), moved to O by the parallel-axis theorem::

    I_O = sum_parts [ I_c + m (|c|^2 E - c c^T) ]
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from taos.shipped import models_dir



@dataclass(frozen=True)
class EngineGeometry:
    """Notional RS-25 shape and mass split [m, kg] (see the module notes)."""

    dry_mass_kg: float = 3527.0
    gimbal_interface_z_m: float = -0.145
    powerhead_radius_m: float = 0.60
    nozzle_joint_z_m: float = -1.90
    nozzle_joint_radius_m: float = 0.33
    nozzle_exit_z_m: float = -4.155
    nozzle_exit_radius_m: float = 1.20
    nozzle_thickness_m: float = 0.020
    nozzle_mass_kg: float = 785.0
    sections: int = 64
    profile_points: int = 25

    @property
    def powerhead_mass_kg(self) -> float:
        return self.dry_mass_kg - self.nozzle_mass_kg


@dataclass(frozen=True)
class MassProperties:
    """Rigid-body mass properties: mass [kg], centre of mass c [m], inertia about c and
    about the origin O [kg m^2] (3x3, frame above)."""

    mass_kg: float
    com_m: np.ndarray
    inertia_com_kgm2: np.ndarray
    inertia_origin_kgm2: np.ndarray

    @property
    def inertia_pitch_kgm2(self) -> float:
        """About the y axis through the gimbal (pitch deflects the nozzle along x)."""
        return float(self.inertia_origin_kgm2[1, 1])

    @property
    def inertia_yaw_kgm2(self) -> float:
        """About the x axis through the gimbal (yaw deflects the nozzle along y)."""
        return float(self.inertia_origin_kgm2[0, 0])


def revolve_profile(r: np.ndarray, z: np.ndarray, sections: int) -> trimesh.Trimesh:
    """Watertight solid of revolution about z from a closed (r, z) polygon (counter-clockwise)."""
    pts = np.column_stack([r, z])
    if not np.allclose(pts[0], pts[-1]):
        pts = np.vstack([pts, pts[:1]])
    mesh = trimesh.creation.revolve(pts, sections=int(sections))
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def cylinder_mesh(radius: float, z0: float, z1: float, sections: int) -> trimesh.Trimesh:
    """Solid cylinder r <= radius, z0 <= z <= z1 (z0 < z1)."""
    return revolve_profile(np.array([0.0, radius, radius, 0.0]), np.array([z0, z0, z1, z1]), sections)


def shell_mesh(r_of_s, z_of_s, thickness: float, n: int, sections: int) -> trimesh.Trimesh:
    """Shell of revolution: mid-surface (r(s), z(s)), s in [0, 1], radial thickness t."""
    s = np.linspace(0.0, 1.0, int(n))
    r, z = r_of_s(s), z_of_s(s)
    ro, ri = r + 0.5 * thickness, r - 0.5 * thickness
    return revolve_profile(np.concatenate([ri, ro[::-1]]), np.concatenate([z, z[::-1]]), sections)


def part_meshes(geom: EngineGeometry = EngineGeometry()) -> dict[str, trimesh.Trimesh]:
    """{'powerhead': solid, 'nozzle': shell} meshes in m (gimbal frame)."""
    g = geom
    head = cylinder_mesh(g.powerhead_radius_m, g.nozzle_joint_z_m, g.gimbal_interface_z_m, g.sections)
    nozzle = shell_mesh(lambda s: g.nozzle_joint_radius_m + (g.nozzle_exit_radius_m - g.nozzle_joint_radius_m) * np.sqrt(s),
                        lambda s: g.nozzle_joint_z_m + (g.nozzle_exit_z_m - g.nozzle_joint_z_m) * s,
                        g.nozzle_thickness_m, g.profile_points, g.sections)
    return {"powerhead": head, "nozzle": nozzle}


def mesh_mass_properties(mesh: trimesh.Trimesh, mass_kg: float) -> MassProperties:
    """Mass properties of a watertight mesh of uniform density rho = mass / volume."""
    if not mesh.is_watertight:
        raise ValueError("mesh is not watertight")
    vol = float(mesh.volume)
    rho = mass_kg / vol
    mp = mesh.mass_properties
    c = np.asarray(mp["center_mass"], float)
    Ic = np.asarray(mp["inertia"], float) * rho / float(mp["density"])
    return MassProperties(mass_kg, c, Ic, Ic + mass_kg * (c @ c * np.eye(3) - np.outer(c, c)))


def combine(parts: list[MassProperties]) -> MassProperties:
    """Rigid assembly of parts (inertia about O adds; about the common c by parallel axes)."""
    m = sum(p.mass_kg for p in parts)
    c = sum(p.mass_kg * p.com_m for p in parts) / m
    IO = sum(p.inertia_origin_kgm2 for p in parts)
    return MassProperties(m, c, IO - m * (c @ c * np.eye(3) - np.outer(c, c)), IO)


def part_masses(geom: EngineGeometry = EngineGeometry()) -> dict[str, float]:
    return {"powerhead": geom.powerhead_mass_kg, "nozzle": geom.nozzle_mass_kg}


def engine_mass_properties(meshes: dict[str, trimesh.Trimesh] | None = None,
                           geom: EngineGeometry = EngineGeometry()) -> MassProperties:
    """Mass properties of the engine about the gimbal from the part meshes."""
    meshes = part_meshes(geom) if meshes is None else meshes
    masses = part_masses(geom)
    return combine([mesh_mass_properties(meshes[k], masses[k]) for k in masses])


def load_part_meshes(directory: Path | None = None) -> dict[str, trimesh.Trimesh]:
    """Read the shipped meshes models/meshes/rs25_{powerhead,nozzle}.stl."""
    directory = models_dir() / "meshes" if directory is None else Path(directory)
    return {k: trimesh.load_mesh(directory / f"rs25_{k}.stl") for k in ("powerhead", "nozzle")}


def build_engine_model(props: MassProperties | None = None):
    """Pinocchio model: base (thrust structure) -> gimbal_pitch (RY) -> gimbal_yaw (RX) -> engine.

    Both revolute joints sit at the gimbal centre O (origin); the engine body carries the
    mesh-derived mass, centre of mass and inertia. Joint limits +-10.5 deg (public).
    """
    import pinocchio as pin

    props = engine_mass_properties() if props is None else props
    model = pin.Model()
    model.name = "rs25_engine"
    lim = np.deg2rad(10.5)
    j1 = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "gimbal_pitch",
                        np.array([1e9]), np.array([1e3]), np.array([-lim]), np.array([lim]))
    j2 = model.addJoint(j1, pin.JointModelRX(), pin.SE3.Identity(), "gimbal_yaw",
                        np.array([1e9]), np.array([1e3]), np.array([-lim]), np.array([lim]))
    model.appendBodyToJoint(j2, pin.Inertia(props.mass_kg, props.com_m, props.inertia_com_kgm2),
                            pin.SE3.Identity())
    f1 = model.addJointFrame(j1, 0)
    f2 = model.addJointFrame(j2, f1)
    model.addBodyFrame("engine", j2, pin.SE3.Identity(), f2)
    return model


def urdf_text(props: MassProperties) -> str:
    """URDF of the engine on a two-revolute gimbal at the origin (meshes in models/meshes)."""
    c = props.com_m
    I = props.inertia_com_kgm2
    lim = np.deg2rad(10.5)
    return f"""<?xml version="1.0"?>
<!-- Generated by scripts/build_engine_geometry.py from models/meshes (taos.engine_geometry).
     Frame: origin at the gimbal bearing centre, z from the engine towards the thrust
     structure, x pitch-lateral, y yaw-lateral. SI units. -->
<robot name="rs25_engine">
  <link name="thrust_structure"/>
  <link name="gimbal_cross">
    <inertial>
      <origin xyz="0 0 0"/>
      <mass value="1e-6"/>
      <inertia ixx="1e-9" ixy="0" ixz="0" iyy="1e-9" iyz="0" izz="1e-9"/>
    </inertial>
  </link>
  <link name="engine">
    <inertial>
      <origin xyz="{c[0]:.9g} {c[1]:.9g} {c[2]:.9g}"/>
      <mass value="{props.mass_kg:.9g}"/>
      <inertia ixx="{I[0, 0]:.9g}" ixy="{I[0, 1]:.9g}" ixz="{I[0, 2]:.9g}" iyy="{I[1, 1]:.9g}" iyz="{I[1, 2]:.9g}" izz="{I[2, 2]:.9g}"/>
    </inertial>
    <visual><geometry><mesh filename="meshes/rs25_powerhead.stl"/></geometry></visual>
    <visual><geometry><mesh filename="meshes/rs25_nozzle.stl"/></geometry></visual>
  </link>
  <joint name="gimbal_pitch" type="revolute">
    <parent link="thrust_structure"/>
    <child link="gimbal_cross"/>
    <origin xyz="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="{-lim:.9g}" upper="{lim:.9g}" effort="1e9" velocity="1e3"/>
  </joint>
  <joint name="gimbal_yaw" type="revolute">
    <parent link="gimbal_cross"/>
    <child link="engine"/>
    <origin xyz="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="{-lim:.9g}" upper="{lim:.9g}" effort="1e9" velocity="1e3"/>
  </joint>
</robot>
"""


def model_file_inertia_values(props: MassProperties) -> dict[str, tuple[str, str]]:
    """The two model-file entries of [engine]: {'inertia_pitch': (value, comment), ...}."""
    d = abs(float(props.com_m[2]))
    note = (f"# [derived] scripts/build_engine_geometry.py from models/meshes "
            f"({props.mass_kg:.0f} kg, centre of mass {d:.2f} m below the gimbal)")
    return {key: (f"{val:.0f} kg*m**2", note)
            for key, val in (("inertia_pitch", props.inertia_pitch_kgm2), ("inertia_yaw", props.inertia_yaw_kgm2))}


def rewrite_model_inertia(path: Path, props: MassProperties) -> bool:
    """Rewrite just the [engine] inertia_pitch / inertia_yaw entries of a model file (tomlkit:
    every other line and comment stays as it was); True if the file changed."""
    import tomlkit

    from .results import toml_set

    text = Path(path).read_text()
    doc = tomlkit.parse(text)
    engine = doc.get("engine", {})
    if not all(key in engine for key in ("inertia_pitch", "inertia_yaw")):
        raise ValueError(f"{path}: expected inertia_pitch and inertia_yaw in [engine]")
    for key, (value, note) in model_file_inertia_values(props).items():
        toml_set(doc, "engine", key, value, note)
    new = tomlkit.dumps(doc)
    if new != text:
        Path(path).write_text(new)
        return True
    return False
