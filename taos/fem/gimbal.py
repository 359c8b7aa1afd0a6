"""Parametric ball-and-socket gimbal bearing, its two halves, two load conditions.

Public facts (NASA SSME reference data): the RS-25 gimbal bearing is a
ball-and-socket universal joint about 0.29 m high and 0.36 m in diameter (11.4 in x 14 in),
titanium, 48 kg (105 lb), bolted above to the core-stage thrust structure and below to the
engine's main injector/dome. Everything else here is notional and listed in
:class:`GimbalGeometry`.

Notional layout (body of revolution about the engine axis z, origin at the bearing centre O,
z from the engine towards the thrust structure; meridian (r, z))::

    z5 ___________________________________   upper half (socket) bolted face
       |  socket body                     |
    S(r)\\_seat_/-------------------.      |   spherical seat z = sqrt(Rs^2 - r^2), r <= r_seat
        | ball |                    |skirt|
    z4  | cap  |__shoulder__        |     |
    z3  |      |___________|  _lip__|     |   hanging contact: shoulder bottom on lip top
    z2  | neck |             |____________|
    z1  |      |_______________________       lower half (ball) engine flange
    z0  |__________________________________|  lower half bolted face
       r_bore  r_seat  r_lip  r_sh  r_skirt  r_out

Load paths (what carries load across the bearing):

* ``thrust`` (hot fire): thrust presses the ball into the socket; the spherical seat is
  closed and carries load directly: bearing interface = the seat (ball cap / socket seat).
* ``hanging`` (ambient): the engine weight pulls the halves apart, the seat opens (a small
  gap), and the ball hangs by its shoulder on the socket's retaining lip: bearing interface
  = the annular contact between shoulder bottom and lip top (r_lip..r_sh at z3). Load goes
  round through the ball shoulder, the lip (plate bending) and the socket skirt.

Both bearing interfaces are tied rigidly (RBE2) to O, the bolted faces rigidly to their
centres: see :mod:`taos.fem.elasticity`. The contact is linearised about the preloaded state
(closed contact stays closed and stuck for small increments), so each condition is linear.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .elasticity import TI_6AL_4V, ElasticModel, Interface, Material, assemble_elasticity, guyan_condense, volume
from .mesh import RevolvedMesh, curved_mesh, divisions, revolve_meridian

CONDITIONS = ("hanging", "thrust")
HALVES = ("upper", "lower")


@dataclass(frozen=True)
class GimbalGeometry:
    """Notional gimbal dimensions [m] (public envelope 0.29 m high x 0.36 m diameter).

    bore_radius : central bore (cross-pin / instrumentation passage), keeps r > 0.
    seat_sphere_radius : Rs, radius of the spherical seat centred at O.
    seat_radius : r_seat, outer radius of the seat contact; also the ball neck radius.
    lip_inner_radius : inner edge of the socket's retaining lip.
    shoulder_radius : outer radius of the ball's shoulder (hanging contact r_lip..r_sh).
    skirt_inner_radius, skirt_outer_radius : socket skirt (the lip's root).
    outer_radius : bolted flanges' radius (0.36 m diameter envelope, public).
    z_bottom, z_top : bolted faces (0.29 m overall height, public).
    flange_top : top of the ball's engine flange.
    lip_bottom, lip_top : retaining lip faces (lip thickness lip_top - lip_bottom).
    shoulder_top : top of the ball shoulder.
    top_flange_bottom : underside of the socket's bolted flange beyond the skirt.

    The retaining path (lip 4 mm, shoulder 8 mm) is sized for the hanging engine only, not
    for thrust: plate-bending stress sigma = 6 M / t^2 with M = W s / (2 pi r) is reported by
    :func:`retainer_stress` (654 MPa in the lip at 1 g, yield margin ~1.35 on Ti-6Al-4V's
    ~880 MPa). The lip thickness is the notional dimension that sets the hanging compliance
    (roughly as t^-3); 4 mm was chosen as the thinnest lip with that margin, which makes the
    FEM explain ~45 % of the Green Run load-stiffness shift (K_L x1.35 of the paper's x1.78; the
    paper calls the gimbal FEM "a partial explanation", sec. 4). That share depends strongly on
    the notional lip and seat: its range over plausible values is :func:`taos.fem.shift.fem_shift_share`.
    """

    bore_radius: float = 0.040
    seat_sphere_radius: float = 0.110
    seat_radius: float = 0.085
    lip_inner_radius: float = 0.095
    shoulder_radius: float = 0.110
    skirt_inner_radius: float = 0.150
    skirt_outer_radius: float = 0.162
    outer_radius: float = 0.180
    z_bottom: float = -0.145
    flange_top: float = -0.123
    lip_bottom: float = -0.088
    lip_top: float = -0.084
    shoulder_top: float = -0.076
    top_flange_bottom: float = 0.123
    z_top: float = 0.145

    def seat_z(self, r: np.ndarray) -> np.ndarray:
        """Seat line z = sqrt(Rs^2 - min(r, r_seat)^2) [m] (flat beyond the seat edge)."""
        rr = np.minimum(np.asarray(r, float), self.seat_radius)
        return np.sqrt(self.seat_sphere_radius ** 2 - rr ** 2)

    @property
    def r_breaks(self) -> tuple[float, ...]:
        return (self.bore_radius, self.seat_radius, self.lip_inner_radius, self.shoulder_radius,
                self.skirt_inner_radius, self.skirt_outer_radius, self.outer_radius)

    @property
    def z_flat(self) -> tuple[float, ...]:
        return (self.z_bottom, self.flange_top, self.lip_bottom, self.lip_top, self.shoulder_top)


#: Meridian block tables [radial zone][vertical zone]; vertical zones between the key lines
#: z0|z1|z2|z3|z4|S(r)|z6|z7: flange, neck gap, lip, shoulder, gap/cap, socket body, flange.
_BLOCKS = {
    "lower": [[1, 1, 1, 1, 1, 0, 0],   # r_bore..r_seat: flange, neck, cap
              [1, 0, 0, 1, 0, 0, 0],   # r_seat..r_lip: flange, shoulder
              [1, 0, 0, 1, 0, 0, 0],   # r_lip..r_sh: flange, shoulder (hanging contact)
              [1, 0, 0, 0, 0, 0, 0],   # r_sh..r_skirt: flange
              [1, 0, 0, 0, 0, 0, 0],   # skirt radii: flange
              [0, 0, 0, 0, 0, 0, 0]],  # r_skirt_out..r_out: (engine flange ends at the skirt)
    "upper": [[0, 0, 0, 0, 0, 1, 1],   # socket body over the seat, flange
              [0, 0, 0, 0, 0, 1, 1],
              [0, 0, 1, 0, 0, 0, 1],   # lip (hanging contact), annular pocket, flange
              [0, 0, 1, 0, 0, 0, 1],   # lip, pocket, flange
              [0, 0, 1, 1, 1, 1, 1],   # skirt
              [0, 0, 0, 0, 0, 0, 1]],  # flange only
}
_SEAT_LINE, _LIP_TOP_LINE, _TOP_LINE, _BOTTOM_LINE = 5, 3, 7, 0
_FULL = (0, 6)


@dataclass(frozen=True)
class MeshSpec:
    """Mesh density: meridian element size h [m] and sectors around the axis n_theta."""

    h: float = 0.010
    n_theta: int = 32
    min_layers: int = 2


def build_half_mesh(geom: GimbalGeometry, half: str, spec: MeshSpec) -> RevolvedMesh:
    """Structured hexahedral mesh of one gimbal half (``'upper'`` socket or ``'lower'`` ball)."""
    if half not in HALVES:
        raise ValueError(f"half must be one of {HALVES}")
    rb = geom.r_breaks
    r_divs = [divisions(rb[a + 1] - rb[a], spec.h, spec.min_layers) for a in range(len(rb) - 1)]
    flat = [(lambda z: (lambda r: np.full_like(r, z)))(z) for z in geom.z_flat]
    keys = flat + [geom.seat_z, lambda r: np.full_like(r, geom.top_flange_bottom),
                   lambda r: np.full_like(r, geom.z_top)]
    # zone heights: use the largest extent of each vertical zone over the radius
    rr = np.linspace(rb[0], rb[-1], 200)
    vals = np.array([np.broadcast_to(f(rr), rr.shape) for f in keys])
    z_divs = [divisions(np.max(vals[b + 1] - vals[b]), spec.h, spec.min_layers) for b in range(len(keys) - 1)]
    return revolve_meridian(rb, r_divs, keys, z_divs, _BLOCKS[half], spec.n_theta)


@dataclass(frozen=True)
class CondensedHalf:
    """One gimbal half condensed to its two interfaces (RBE2 + Guyan).

    K_free : (12, 12) free-free stiffness, DOFs (ux, uy, uz, rx, ry, rz) of the bearing
    reference point O then of the bolted-face reference point [N/m, N/rad, N m/m, N m/rad].
    K_held : (6, 6) bearing-point stiffness with the bolted face held = K_free[:6, :6].
    ref_points_m : (2, 3) bearing point, bolted-face point [m].
    """

    half: str
    condition: str
    K_free: np.ndarray
    ref_points_m: np.ndarray
    n_elements: int
    n_dofs: int
    mass_kg: float
    spec: MeshSpec

    @property
    def K_held(self) -> np.ndarray:
        return self.K_free[:6, :6].copy()


def half_interfaces(geom: GimbalGeometry, half: str, condition: str, rm: RevolvedMesh) -> list[Interface]:
    """Bearing interface (depends on the load condition) and bolted face of one half."""
    if condition not in CONDITIONS:
        raise ValueError(f"condition must be one of {CONDITIONS}")
    if condition == "thrust":
        bearing = rm.nodes_on_key_line(_SEAT_LINE, (0, 1))
    else:
        bearing = rm.nodes_on_key_line(_LIP_TOP_LINE, (2, 3))
    if half == "upper":
        bolted, zb = rm.nodes_on_key_line(_TOP_LINE, _FULL), geom.z_top
    else:
        bolted, zb = rm.nodes_on_key_line(_BOTTOM_LINE, _FULL), geom.z_bottom
    return [Interface(f"bearing ({condition})", bearing, (0.0, 0.0, 0.0)),
            Interface("bolted face", bolted, (0.0, 0.0, zb))]


def condense_half(geom: GimbalGeometry, half: str, condition: str, spec: MeshSpec,
                  material: Material = TI_6AL_4V, model: tuple[RevolvedMesh, ElasticModel] | None = None
                  ) -> CondensedHalf:
    """Mesh, assemble and condense one gimbal half for one load condition.

    ``model`` may pass a (mesh, assembled model) pair to reuse between conditions.
    """
    if model is None:
        model = half_model(geom, half, spec, material)
    rm, em = model
    itf = half_interfaces(geom, half, condition, rm)
    K = guyan_condense(em, itf)
    refs = np.array([i.ref_point_m for i in itf])
    return CondensedHalf(half, condition, K, refs, em.nelements, em.ndofs,
                         volume(em) * material.density_kg_m3, spec)


def half_model(geom: GimbalGeometry, half: str, spec: MeshSpec,
               material: Material = TI_6AL_4V) -> tuple[RevolvedMesh, ElasticModel]:
    """Mesh (quadratic geometry) and assembled stiffness of one half."""
    rm = build_half_mesh(geom, half, spec)
    return rm, assemble_elasticity(curved_mesh(rm, spec.n_theta), material)


def geometry_table(geom: GimbalGeometry) -> dict[str, float]:
    """Dimensions as a flat {name_m: value} table for provenance files."""
    return {f"{k}_m": float(v) for k, v in asdict(geom).items()}


def retainer_stress(geom: GimbalGeometry, load_N: float = 3527.0 * 9.80665) -> dict[str, float]:
    """Root bending stress [Pa] of the retaining lip and ball shoulder under the hanging load.

    Annular plate strip estimate: the load W acts at the mean contact radius r_c; the moment
    per unit circumference at a root of radius r_0 is M = W |r_0 - r_c| / (2 pi r_0) [N m/m],
    sigma = 6 M / t^2. Default W: the 3,527 kg engine at 1 g [N].
    """
    rc = 0.5 * (geom.lip_inner_radius + geom.shoulder_radius)
    out = {}
    for name, r0, t in (("lip", geom.skirt_inner_radius, geom.lip_top - geom.lip_bottom),
                        ("shoulder", geom.seat_radius, geom.shoulder_top - geom.lip_top)):
        M = load_N * abs(r0 - rc) / (2 * np.pi * r0)
        out[name] = 6 * M / t ** 2
    return out
