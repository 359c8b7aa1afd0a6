"""How much of the Green Run ambient -> hot-fire load-stiffness shift the gimbal FEM explains, with
its range over plausible notional gimbal geometry (issue 24.8).

The paper (sec. 4) fits K_L = 115,000 lbf/in ambient and 205,000 lbf/in hot fire, a ratio
r_paper = 205 / 115 = 1.78, and calls the gimbal FEM a partial explanation. The FEM's ratio r_FEM
comes from the series load path 1/K_L = C_rest + C_g (:func:`taos.fem.load_path.implied_load_stiffness`:
C_rest fixed by the ambient fit, C_g the gimbal's actuator-line compliance hanging on its lip or
thrust-loaded on its seat). The share of the shift it explains is

    share = (r_FEM - 1) / (r_paper - 1)                                      [-]

(0: no shift, 1: all of it). Its inputs that are not public are the gimbal's internal dimensions
(:class:`taos.fem.gimbal.GimbalGeometry`); the two that decide the hanging compliance are the
retaining-lip thickness t (plate bending, compliance roughly as t^-3) and the seat sphere radius
R_s (with the bore, seat, lip and shoulder radii scaled with it; the skirt and flanges, inside the
public 0.29 m x 0.36 m envelope, stay). Plausible ranges, documented where used:

* lip 4-6 mm: 4 mm is the thinnest lip that holds the hanging engine below yield with margin
  (:func:`taos.fem.gimbal.retainer_stress`: 654 MPa at 1 g against ~880 MPa; 3 mm reaches 1,160 MPa
  and would yield), 6 mm a 50 % heavier retainer than needed;
* seat sphere radius 0.10-0.12 m: +-10 % about the notional 0.110 m; the ball's shoulder must stay
  inside the socket skirt (0.150 m) and the seat inside the 0.36 m bearing.

:func:`compute_shift_range` runs the sweep (slow: both halves in both conditions per geometry;
``scripts/fem_shift_sensitivity.py`` writes ``fem_data/fem_shift_range.toml``) and
:func:`fem_shift_share` reads that committed result.
"""

from __future__ import annotations

import dataclasses
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .gimbal import GimbalGeometry, MeshSpec, retainer_stress
from .load_path import ActuatorLine, implied_load_stiffness

#: Paper sec. 4: hot-fire / ambient load stiffness of the Green Run fits.
PAPER_RATIO = 205000.0 / 115000.0
#: Plausible ranges of the two notional dimensions (module docstring) [m].
LIP_RANGE_M = (0.004, 0.006)
SEAT_SPHERE_RADIUS_RANGE_M = (0.100, 0.120)
#: Where :func:`fem_shift_share` reads the committed sweep.
DEFAULT_PATH = Path(__file__).resolve().parents[2] / "fem_data" / "fem_shift_range.toml"


def explained_share(ratio: float, paper_ratio: float = PAPER_RATIO) -> float:
    """(ratio - 1) / (paper_ratio - 1) [-]: the share of the paper's K_L shift a ratio explains."""
    return (float(ratio) - 1.0) / (paper_ratio - 1.0)


def swept_geometry(lip_m: float, seat_sphere_radius_m: float, base: GimbalGeometry = GimbalGeometry()) -> GimbalGeometry:
    """``base`` with lip thickness ``lip_m`` [m] (lip bottom kept) and seat sphere radius
    ``seat_sphere_radius_m`` [m], the bore, seat, lip and shoulder radii scaled with it."""
    s = seat_sphere_radius_m / base.seat_sphere_radius
    return dataclasses.replace(base, bore_radius=base.bore_radius * s, seat_sphere_radius=seat_sphere_radius_m,
                               seat_radius=base.seat_radius * s, lip_inner_radius=base.lip_inner_radius * s,
                               shoulder_radius=base.shoulder_radius * s, lip_top=base.lip_bottom + lip_m)


@dataclass(frozen=True)
class SharePoint:
    """One swept geometry: lip [m], seat sphere radius [m], the implied K_L ratio and share [-]
    (None when the hanging gimbal alone is softer than the whole ambient path), the lip's root
    bending stress under the hanging engine [Pa]."""

    lip_m: float
    seat_sphere_radius_m: float
    ratio: float | None
    share: float | None
    lip_stress_Pa: float


@dataclass(frozen=True)
class ShiftShareRange:
    """The FEM-explained share of the K_L shift: ``nominal`` (shipped geometry) and its
    ``minimum``/``maximum`` over ``points`` (the sweep, corners of the plausible ranges included),
    all on mesh ``mesh_h_m``/``mesh_n_theta``; ``fine_nominal`` the shipped fine-mesh value
    (fem_data/mesh_study.toml) when known; ``convergence`` nominal share per mesh size."""

    nominal: float
    minimum: float
    maximum: float
    points: tuple[SharePoint, ...]
    mesh_h_m: float
    mesh_n_theta: int
    paper_ratio: float = PAPER_RATIO
    fine_nominal: float | None = None
    convergence: tuple[tuple[float, float], ...] = ()
    source: str = "<code>"

    def text(self) -> str:
        """One line: 'about 45 % (range 20-80 % over ...)'."""
        fine = "" if self.fine_nominal is None else f"; {100 * self.fine_nominal:.0f} % on the finest mesh"
        lips = sorted({p.lip_m for p in self.points})
        radii = sorted({p.seat_sphere_radius_m for p in self.points})
        return (f"FEM-explained share of the ambient -> hot-fire K_L shift (paper x{self.paper_ratio:.2f}): "
                f"{100 * self.nominal:.0f} % at the shipped gimbal geometry, range {100 * self.minimum:.0f}-"
                f"{100 * self.maximum:.0f} % over lip {1000 * lips[0]:g}-{1000 * lips[-1]:g} mm x seat radius "
                f"{radii[0]:g}-{radii[-1]:g} m (mesh h = {self.mesh_h_m:g} m{fine})")

    def to_dict(self) -> dict:
        return {"nominal_share": self.nominal, "min_share": self.minimum, "max_share": self.maximum,
                "fine_mesh_nominal_share": self.fine_nominal, "paper_ratio": self.paper_ratio,
                "mesh_h_m": self.mesh_h_m, "mesh_n_theta": self.mesh_n_theta, "source": self.source}


def compute_shift_range(lips_m=(0.004, 0.005, 0.006), radii_m=(0.100, 0.110, 0.120),
                        spec: MeshSpec = MeshSpec(0.014, 12), line: ActuatorLine | None = None,
                        nominal: GimbalGeometry = GimbalGeometry(), log=None) -> ShiftShareRange:
    """Sweep lip thickness x seat sphere radius [m] (both halves, both conditions per geometry on
    mesh ``spec``; about 15 s per geometry at h = 0.014 m) and return the share's range; the
    nominal geometry is computed on the same mesh."""
    from .build import engine_actuator_line, run_level
    line = engine_actuator_line() if line is None else line

    def point(g: GimbalGeometry) -> SharePoint:
        t0 = time.perf_counter()
        lv = run_level(g, spec, line)
        try:
            sh = implied_load_stiffness(lv.compliance["hanging"], lv.compliance["thrust"])
            ratio, share = sh.ratio, explained_share(sh.ratio)
        except ValueError:  # the hanging gimbal alone is softer than the whole ambient path
            ratio = share = None
        p = SharePoint(g.lip_top - g.lip_bottom, g.seat_sphere_radius, ratio, share, retainer_stress(g)["lip"])
        if log:
            log(f"lip {1000 * p.lip_m:.1f} mm, R_s {p.seat_sphere_radius_m:.3f} m: ratio {ratio}, share {share} "
                f"({time.perf_counter() - t0:.0f} s)")
        return p

    nom = point(nominal)
    pts = tuple(point(swept_geometry(t, r, nominal)) for t in lips_m for r in radii_m)
    shares = [p.share for p in pts if p.share is not None] + [nom.share]
    return ShiftShareRange(nom.share, min(shares), max(shares), pts, spec.h, spec.n_theta)


def fem_shift_share(path: str | Path = DEFAULT_PATH) -> ShiftShareRange:
    """The committed sweep (``scripts/fem_shift_sensitivity.py`` writes it): nominal share with its
    minimum and maximum over the plausible gimbal geometry (:class:`ShiftShareRange`)."""
    d = tomllib.loads(Path(path).read_text())
    s = d["share"]
    p = d["points"]
    pts = tuple(SharePoint(t, r, q if ok else None, sh if ok else None, st) for t, r, q, sh, st, ok in
                zip(p["lip_m"], p["seat_sphere_radius_m"], p["ratio"], p["share"], p["lip_stress_Pa"], p["valid"]))
    c = d.get("convergence", {})
    conv = tuple(zip(c.get("h_m", []), c.get("nominal_share", [])))
    return ShiftShareRange(s["nominal"], s["minimum"], s["maximum"], pts, d["mesh"]["h_m"], d["mesh"]["n_theta"],
                           s["paper_ratio"], s.get("fine_mesh_nominal"), conv, str(path))
