"""Notional SLS core-stage engine-section thrust structure: frame model and its modes.

Vehicle frame: x along the vehicle axis, forward positive; y, z lateral; origin on the axis
in the plane of the thrust cross-beams. Public: core-stage diameter 8.4 m, four RS-25s on a
square pattern (2.5 to 3.5 m; 3.0 m here). Everything else is notional (no public FEM):

* aft ring frame at x = 0, radius 4.2 m (box 0.50 x 0.30 m, wall 10 mm, Al 2219);
* four cross-beams in the x = 0 plane along y = +-a and z = +-a (a = 1.5 m, half the engine
  spacing), spanning ring to ring (box 0.70 x 0.40 m, wall 14 mm); they cross at the four
  engine stations (y, z) = (+-a, +-a);
* thrust posts: at each crossing, a short stiff fitting (tube 0.35 m, wall 25 mm, steel,
  0.35 m) down to the gimbal point at x = -0.35 m (the top of the gimbal bearing);
* thrust struts: from each crossing, three tubes (0.30 m, wall 10 mm) forward to a mid ring
  at x = 2.5 m (the two nearest ring nodes either side of the engine's azimuth and the one at
  it), carrying thrust into the barrel;
* barrel: 24 longerons (lumped skin-stringer panels, box 0.20 x 0.20 m, wall 8 mm) from the
  aft ring to the forward interface ring at x = 5.0 m, with the mid ring (box 0.30 x 0.20 m,
  wall 8 mm); the forward interface ring is clamped (the rest of the core stage treated as
  rigid: global core-stage bending, from about 6 Hz, is outside this local model); the
  skin's shear stiffness is one diagonal tube (0.15 m, wall 6 mm) per bay;
* actuator attach points on the cross-beams 0.8 m (the moment arm) from each crossing
  towards the vehicle axis: the pitch actuator on the beam along z (it drives the engine
  about the y axis), the yaw actuator on the beam along y (about the z axis);
* non-structural mass: 3,000 kg on the aft ring (heat shield, harnesses, hydraulics), 60 kg
  per actuator bracket, 150 kg per gimbal fitting. Engines are NOT included (MASV couples
  them through the gimbal points and actuators).

``stiffness_scale`` multiplies every member's elastic moduli (E, G) and nothing else: the
consistent mass is unchanged, so the mass-normalised mode shapes are the same and every
frequency scales by sqrt(stiffness_scale). The shipped nominal frame uses 1; the notional
"local modes in the actuator band" variant (``scripts/build_local_modes.py``) softens it so
that its lowest mode sits in the 3-9 Hz actuator band, where the paper (sec. 1) says the real
engine section's local modes are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .frame import Frame, Modes, box_section, frame_modes, tube_section

AL_E, AL_G, AL_RHO = 73.8e9, 27.6e9, 2840.0       # Al 2219-T87 (MMPDS typical)
ST_E, ST_G, ST_RHO = 200e9, 77e9, 7850.0          # steel fittings


@dataclass(frozen=True)
class ThrustStructureSpec:
    """Notional thrust-structure parameters [m, kg]; see the module notes."""

    radius_m: float = 4.2
    engine_half_spacing_m: float = 1.5
    moment_arm_m: float = 0.8
    gimbal_drop_m: float = 0.35
    mid_ring_x_m: float = 2.5
    forward_ring_x_m: float = 5.0
    n_ring: int = 24
    max_element_m: float = 0.5
    ring_mass_kg: float = 3000.0
    bracket_mass_kg: float = 60.0
    fitting_mass_kg: float = 150.0
    f_max_hz: float = 50.0
    stiffness_scale: float = 1.0


def node_names() -> list[str]:
    """The 12 interface names in file order (gimbal_1..4, actuator_k_pitch/yaw)."""
    return [f"gimbal_{k}" for k in range(1, 5)] + [f"actuator_{k}_{ax}" for k in range(1, 5)
                                                     for ax in ("pitch", "yaw")]


def engine_stations(spec: ThrustStructureSpec) -> np.ndarray:
    """(4, 2) engine (y, z) stations: engines 1..4 counter-clockwise from (+a, +a)."""
    a = spec.engine_half_spacing_m
    return np.array([[a, a], [-a, a], [-a, -a], [a, -a]])


def build_thrust_structure(spec: ThrustStructureSpec) -> Frame:
    """Assemble the notional engine-section frame (named interface nodes in node_names())."""
    if not spec.stiffness_scale > 0:
        raise ValueError(f"stiffness_scale must be positive, got {spec.stiffness_scale!r}")
    fr = Frame()
    R, a, h = spec.radius_m, spec.engine_half_spacing_m, spec.max_element_m
    ks = spec.stiffness_scale
    al_e, al_g, st_e, st_g = ks * AL_E, ks * AL_G, ks * ST_E, ks * ST_G
    ring = box_section("aft ring", 0.50, 0.30, 0.010, al_e, al_g, AL_RHO)
    beam = box_section("cross-beam", 0.70, 0.40, 0.014, al_e, al_g, AL_RHO)
    post = tube_section("thrust post", 0.35, 0.025, st_e, st_g, ST_RHO)
    strut = tube_section("thrust strut", 0.30, 0.010, al_e, al_g, AL_RHO)
    longeron = box_section("longeron", 0.20, 0.20, 0.008, al_e, al_g, AL_RHO)
    diagonal = tube_section("skin shear diagonal", 0.15, 0.006, al_e, al_g, AL_RHO)
    midring = box_section("mid ring", 0.30, 0.20, 0.008, al_e, al_g, AL_RHO)
    nr = spec.n_ring
    ang = 2 * np.pi * np.arange(nr) / nr
    aft = [fr.node((0.0, R * np.cos(t), R * np.sin(t))) for t in ang]
    mid = [fr.node((spec.mid_ring_x_m, R * np.cos(t), R * np.sin(t))) for t in ang]
    fwd = [fr.node((spec.forward_ring_x_m, R * np.cos(t), R * np.sin(t))) for t in ang]
    for k in range(nr):
        fr.member(aft[k], aft[(k + 1) % nr], ring, h)
        fr.member(mid[k], mid[(k + 1) % nr], midring, h)
        fr.member(aft[k], mid[k], longeron, h, up=(0.0, np.cos(ang[k]), np.sin(ang[k])))
        fr.member(mid[k], fwd[k], longeron, h, up=(0.0, np.cos(ang[k]), np.sin(ang[k])))
        # skin shear stiffness as one diagonal per bay (a shear-panel equivalent)
        fr.member(aft[k], mid[(k + 1) % nr], diagonal, h, up=(0.0, np.cos(ang[k]), np.sin(ang[k])))
        fr.member(mid[k], fwd[(k + 1) % nr], diagonal, h, up=(0.0, np.cos(ang[k]), np.sin(ang[k])))
        fr.fixed.add(fwd[k])
        fr.lumped[aft[k]] = fr.lumped.get(aft[k], 0.0) + spec.ring_mass_kg / nr
    # cross-beams: crossing points and actuator attach points are nodes on them
    c = np.sqrt(R * R - a * a)
    stations = engine_stations(spec)
    cross = {(sy, sz): fr.node((0.0, sy * a, sz * a)) for sy in (1, -1) for sz in (1, -1)}
    arm = spec.moment_arm_m
    act = {}
    for (y, z) in stations:
        sy, sz = int(np.sign(y)), int(np.sign(z))
        act[(sy, sz, "pitch")] = fr.node((0.0, y, z - sz * arm))
        act[(sy, sz, "yaw")] = fr.node((0.0, y - sy * arm, z))
    for s in (1, -1):
        # beam along z at y = s a: ring end, crossings / attach points sorted by z
        ends = [fr.node((0.0, s * a, -c)), fr.node((0.0, s * a, c))]
        pts = sorted({ends[0], ends[1], cross[(s, 1)], cross[(s, -1)], act[(s, 1, "pitch")],
                      act[(s, -1, "pitch")]}, key=lambda i: fr.nodes[i][2])
        for i, j in zip(pts[:-1], pts[1:]):
            fr.member(i, j, beam, h, up=(1.0, 0.0, 0.0))
        ends_y = [fr.node((0.0, -c, s * a)), fr.node((0.0, c, s * a))]
        pts = sorted({ends_y[0], ends_y[1], cross[(1, s)], cross[(-1, s)], act[(1, s, "yaw")],
                      act[(-1, s, "yaw")]}, key=lambda i: fr.nodes[i][1])
        for i, j in zip(pts[:-1], pts[1:]):
            fr.member(i, j, beam, h, up=(1.0, 0.0, 0.0))
        # tie the beam ends into the ring: nearest ring node by a short rigid-ish link
        for e in ends + ends_y:
            p = fr.nodes[e]
            k = int(np.argmin([np.linalg.norm(fr.nodes[r] - p) for r in aft]))
            fr.member(e, aft[k], beam, h, up=(1.0, 0.0, 0.0))
    gimbals = {}
    for (y, z) in stations:
        sy, sz = int(np.sign(y)), int(np.sign(z))
        cn = cross[(sy, sz)]
        g = fr.node((-spec.gimbal_drop_m, y, z))
        fr.member(cn, g, post, h, up=(0.0, 1.0, 0.0))
        fr.lumped[g] = fr.lumped.get(g, 0.0) + spec.fitting_mass_kg
        gimbals[(sy, sz)] = g
        az = np.arctan2(z, y)
        k0 = int(np.round(az / (2 * np.pi / nr))) % nr
        for k in (k0 - 1, k0, k0 + 1):
            fr.member(cn, mid[k % nr], strut, 10.0, up=(0.0, -np.sin(az), np.cos(az)))
    for key, n in act.items():
        fr.lumped[n] = fr.lumped.get(n, 0.0) + spec.bracket_mass_kg
    for k, (y, z) in enumerate(stations, start=1):
        sy, sz = int(np.sign(y)), int(np.sign(z))
        fr.names[f"gimbal_{k}"] = gimbals[(sy, sz)]
        fr.names[f"actuator_{k}_pitch"] = act[(sy, sz, "pitch")]
        fr.names[f"actuator_{k}_yaw"] = act[(sy, sz, "yaw")]
    return fr


@dataclass(frozen=True)
class InterfaceModes:
    """Modes at the 12 interface nodes (the MASV file contract).

    freq_hz (n,); damping_ratio (n,); node_names (12,); node_xyz_m (12, 3);
    phi (n, 12, 6) mass-normalised [m/sqrt(kg), rad/sqrt(kg)]; plus model counts.
    """

    freq_hz: np.ndarray
    damping_ratio: np.ndarray
    node_names: list[str]
    node_xyz_m: np.ndarray
    phi: np.ndarray
    total_mass_kg: float
    n_elements: int
    n_nodes: int
    n_dofs: int


def thrust_structure_modes(spec: ThrustStructureSpec = ThrustStructureSpec(),
                           damping_ratio: float = 0.005) -> InterfaceModes:
    """Modes up to spec.f_max_hz at the 12 interface nodes; 0.5 % damping (paper sec. 3.3)."""
    fr = build_thrust_structure(spec)
    m: Modes = frame_modes(fr, spec.f_max_hz)
    names = node_names()
    idx = [fr.names[n] for n in names]
    return InterfaceModes(m.freq_hz, np.full(m.freq_hz.size, damping_ratio), names,
                          m.nodes_m[idx], m.phi[:, idx, :], m.total_mass_kg, m.n_elements,
                          len(fr.nodes), m.n_dofs)
