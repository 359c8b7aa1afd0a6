"""Display geometry of one RS-25 engine, its gimbal and its two TVC actuators (metres).

Frame: z up, gimbal pivot at the origin, the engine hanging along -z. The pitch actuator
works in the x-z plane (engine rotation about +y), the yaw actuator in the y-z plane
(rotation about -x), each vertical at a perpendicular distance ``moment_arm_m`` (R) from the
pivot, so a small engine rotation theta moves its clevis by R theta along the actuator line.

Public dimensions (RS-25 public figures): engine length 4.3 m, nozzle exit diameter 2.4 m, gimbal
bearing about 0.29 m x 0.36 m. RS-25 throat diameter 0.262 m and nozzle length about 3.07 m
are public figures too. Powerhead envelope, actuator lengths and attach heights are notional
(display only, they change no result).

Meshes: if ``models/meshes/`` holds ``rs25_powerhead.stl`` and ``rs25_nozzle.stl`` (metres,
this same gimbal frame, written by :mod:`taos.engine_geometry`), they are loaded with
trimesh; otherwise procedural trimesh primitives with the dimensions above are used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from taos.shipped import models_dir

#: repository folder with engine meshes (optional)
MESH_DIR = models_dir() / "meshes"
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".glb")


@dataclass(frozen=True)
class EngineDrawing:
    """Display dimensions [m] of the drawn engine, gimbal and actuators; defaults are the RS-25
    public figures (module docstring). Display only: the bearing's structural geometry is
    :class:`taos.fem.gimbal.GimbalGeometry`."""

    moment_arm_m: float = 0.8
    engine_length_m: float = 4.3
    nozzle_exit_diameter_m: float = 2.4
    nozzle_length_m: float = 3.07
    throat_diameter_m: float = 0.262
    gimbal_diameter_m: float = 0.36
    gimbal_height_m: float = 0.29
    structure_attach_height_m: float = 1.0
    engine_attach_depth_m: float = 0.55
    body_length_m: float = 0.95
    body_diameter_m: float = 0.2
    rod_length_m: float = 0.8
    rod_diameter_m: float = 0.075

    @property
    def powerhead_length_m(self) -> float:
        return self.engine_length_m - self.nozzle_length_m

    def structure_attach_m(self, axis: str) -> np.ndarray:
        """Undeflected structure-side actuator attach point S0 [m]."""
        return np.array([*self._plane(axis), self.structure_attach_height_m])

    def engine_attach_m(self, axis: str) -> np.ndarray:
        """Engine clevis C0 at zero engine angle [m]."""
        return np.array([*self._plane(axis), -self.engine_attach_depth_m])

    def _plane(self, axis: str) -> tuple[float, float]:
        R = self.moment_arm_m
        return (R, 0.0) if axis == "pitch" else (0.0, R)

    @property
    def actuator_length_m(self) -> float:
        """Pin-to-pin actuator length at null [m]."""
        return self.structure_attach_height_m + self.engine_attach_depth_m


def _nozzle(g: EngineDrawing) -> trimesh.Trimesh:
    """Bell nozzle and combustion chamber, revolved about z (open surface, drawn two-sided)."""
    top = g.gimbal_height_m / 2  # the engine length runs from the bearing top, as in models/meshes
    z_throat = top - g.powerhead_length_m
    z_exit = top - g.engine_length_m
    rt, re = g.throat_diameter_m / 2, g.nozzle_exit_diameter_m / 2
    s = np.linspace(0.0, 1.0, 24)
    # bell: radius rises fast past the throat then flattens (parabolic in the axial coordinate)
    r_bell = rt + (re - rt) * (1 - (1 - s) ** 2) ** 0.85
    z_bell = z_throat + (z_exit - z_throat) * s
    chamber = [(0.215, z_throat + 0.55), (0.215, z_throat + 0.25), (rt, z_throat)]
    prof = np.array(chamber + list(zip(r_bell[1:], z_bell[1:])))
    return trimesh.creation.revolve(prof, sections=48)


def _powerhead(g: EngineDrawing) -> trimesh.Trimesh:
    """Powerhead envelope: main body, two high-pressure turbopumps, injector dome."""
    L = g.powerhead_length_m
    parts = [
        trimesh.creation.box(extents=(1.1, 0.9, L - 0.45),
                             transform=trimesh.transformations.translation_matrix((0, 0, -0.3 - (L - 0.45) / 2))),
        trimesh.creation.cylinder(0.22, 1.3, sections=24,
                                  transform=trimesh.transformations.translation_matrix((-0.35, 0.55, -0.75))),
        trimesh.creation.cylinder(0.2, 1.2, sections=24,
                                  transform=trimesh.transformations.translation_matrix((-0.35, -0.55, -0.8))),
        trimesh.creation.cone(0.42, 0.16, sections=24,
                              transform=trimesh.transformations.translation_matrix((0, 0, -0.3))),
    ]
    return trimesh.util.concatenate(parts)


def _load_mesh(name: str) -> trimesh.Trimesh | None:
    """``models/meshes/rs25_<name>.stl`` (written by :mod:`taos.engine_geometry`) or ``<name>.*``."""
    if not MESH_DIR.is_dir():
        return None
    for stem in (f"rs25_{name}", name):
        for suffix in MESH_SUFFIXES:
            p = MESH_DIR / f"{stem}{suffix}"
            if p.is_file():
                try:
                    m = trimesh.load(p, force="mesh")
                except Exception:  # an unreadable file falls back to the procedural shape
                    return None
                if isinstance(m, trimesh.Trimesh) and len(m.faces):
                    return m
    return None


def engine_meshes(g: EngineDrawing, use_files: bool = True) -> dict[str, trimesh.Trimesh]:
    """{'powerhead': mesh, 'nozzle': mesh} in the engine frame (gimbal pivot at the origin):
    the shipped meshes when present, else the procedural shapes of this module."""
    out = {}
    for name, build in (("powerhead", _powerhead), ("nozzle", _nozzle)):
        m = _load_mesh(name) if use_files else None
        out[name] = m if m is not None else build(g)
    return out


def clevis_bracket(g: EngineDrawing, axis: str) -> trimesh.Trimesh:
    """Engine-side bracket from the powerhead out to the actuator clevis."""
    c = g.engine_attach_m(axis)
    inner = c.copy()
    inner[:2] *= 0.4
    return trimesh.creation.cylinder(0.05, segment=(inner, c), sections=12)


def gimbal_half(g: EngineDrawing, upper: bool) -> trimesh.Trimesh:
    """One half of the ball-and-socket gimbal block (upper to the structure, lower to the engine)."""
    h = g.gimbal_height_m / 2
    z = h / 2 if upper else -h / 2
    return trimesh.creation.cylinder(g.gimbal_diameter_m / 2, h * 0.96, sections=32,
                                     transform=trimesh.transformations.translation_matrix((0, 0, z)))


def axis_pin(g: EngineDrawing, axis: str) -> trimesh.Trimesh:
    """Friction-state indicator through the bearing, along the rotation axis of ``axis``."""
    rot = trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0) if axis == "pitch" else (0, 1, 0))
    return trimesh.creation.cylinder(0.045, g.gimbal_diameter_m * 1.7, sections=16, transform=rot)


def actuator_body(g: EngineDrawing) -> trimesh.Trimesh:
    """Actuator cylinder along local +z from 0 to the body length (placed at the structure attach)."""
    return trimesh.creation.cylinder(g.body_diameter_m / 2, segment=((0, 0, 0), (0, 0, g.body_length_m)), sections=24)


def actuator_rod(g: EngineDrawing) -> trimesh.Trimesh:
    """Piston rod along local -z from 0 back into the cylinder (placed at the engine clevis)."""
    return trimesh.creation.cylinder(g.rod_diameter_m / 2, segment=((0, 0, -g.rod_length_m), (0, 0, 0)), sections=16)


def attach_point(radius: float = 0.07) -> trimesh.Trimesh:
    return trimesh.creation.icosphere(subdivisions=2, radius=radius)


def thrust_structure(g: EngineDrawing) -> trimesh.Trimesh:
    """Thrust-structure beams carrying the gimbal and the two actuator attach points."""
    zt = g.structure_attach_height_m + 0.12
    R = g.moment_arm_m
    beams = [
        trimesh.creation.box(extents=(2 * R + 0.5, 0.16, 0.16), transform=trimesh.transformations.translation_matrix((0, 0, zt))),
        trimesh.creation.box(extents=(0.16, 2 * R + 0.5, 0.16), transform=trimesh.transformations.translation_matrix((0, 0, zt))),
        trimesh.creation.cylinder(0.1, segment=((0, 0, g.gimbal_height_m / 2), (0, 0, zt)), sections=16),
    ]
    return trimesh.util.concatenate(beams)


def geometry_from_model(model) -> EngineDrawing:
    """Display geometry whose actuator attach points are the model file's ``[geometry]`` (the
    3-D TAOS model's, :func:`taos.taos3d.model.parse_geometry`): moment arm, structure attach
    height and engine attach depth from the pitch actuator's points, not repeated here."""
    from taos.taos3d.model import parse_geometry
    geo = parse_geometry(model)
    S, E = geo.structure_attach_m[0], geo.engine_attach_m[0]
    return EngineDrawing(moment_arm_m=float(np.hypot(E[0], E[1])), structure_attach_height_m=float(S[2]),
                          engine_attach_depth_m=float(-E[2]))


def geometry_for_run(th) -> EngineDrawing:
    """Display geometry of a recorded run: the ``[geometry]`` of the model file named in its
    provenance when that file is readable and has one, else the defaults with the run's moment arm."""
    src = (getattr(th, "provenance", None) or {}).get("model_file")
    if src:
        from taos.errors import InputError
        from taos.model import load_model
        try:
            m = load_model(src)
            if "geometry" in m.extra:
                return geometry_from_model(m)
        except InputError:  # a moved or edited model file: fall back to the defaults
            pass
    return EngineDrawing(moment_arm_m=float(th.moment_arm_m))
