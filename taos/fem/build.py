"""Rebuild everything in fem_data/ from nothing (used by scripts/build_fem_data.py).

Steps: FE verification (cantilever tube vs beam theory), gimbal mesh study over three mesh
levels (both halves, both load conditions), shipped gimbal matrices from the finest level,
the implied load-stiffness shift, thrust-structure modes, provenance sidecars and README.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .elasticity import TI_6AL_4V
from .gimbal import CONDITIONS, HALVES, GimbalGeometry, MeshSpec, condense_half, geometry_table, half_model
from .io import write_toml
from .load_path import LBF_PER_IN, ActuatorLine, LoadStiffnessShift, actuator_line_compliance, implied_load_stiffness
from .thrust_structure import ThrustStructureSpec, thrust_structure_modes
from .verification import cantilever_tube_check

GENERATOR = "scripts/build_fem_data.py (taos.fem.build)"
FINE_LEVELS = (MeshSpec(0.014, 12), MeshSpec(0.010, 12), MeshSpec(0.007, 12))
COARSE_LEVELS = (MeshSpec(0.030, 8), MeshSpec(0.020, 8))
#: terms that matter for the piston notch: per half, bearing-point diagonal with the bolted
#: face held (lateral ux, axial uz, rocking ry), and the actuator-line compliance.
TERMS = (("ux", 0), ("uz", 2), ("ry", 4))


@dataclass(frozen=True)
class LevelResult:
    """One mesh level: condensed halves per (half, condition) and C_g per condition [m/N]."""

    spec: MeshSpec
    halves: dict
    compliance: dict
    seconds: float

    def terms(self) -> dict[str, float]:
        out = {}
        for c in CONDITIONS:
            out[f"C_actuator_line_{c}"] = self.compliance[c]
            for half in HALVES:
                K = self.halves[half, c].K_held
                for name, i in TERMS:
                    out[f"K_{half}_{name}_{c}"] = float(K[i, i])
        return out


def run_level(geom: GimbalGeometry, spec: MeshSpec, line: ActuatorLine) -> LevelResult:
    """Condense both halves in both conditions on one mesh level."""
    t0 = time.perf_counter()
    halves = {}
    for half in HALVES:
        model = half_model(geom, half, spec)
        for c in CONDITIONS:
            halves[half, c] = condense_half(geom, half, c, spec, model=model)
    comp = {c: actuator_line_compliance(halves["upper", c].K_held, halves["lower", c].K_free,
                                        halves["lower", c].ref_points_m[1], line) for c in CONDITIONS}
    return LevelResult(spec, halves, comp, time.perf_counter() - t0)


def relative_changes(levels: list[LevelResult]) -> dict[str, float]:
    """|term(finest) / term(second finest) - 1| for each term."""
    a, b = levels[-2].terms(), levels[-1].terms()
    return {k: abs(b[k] / a[k] - 1.0) for k in a}


def _save_gimbal(out: Path, geom: GimbalGeometry, level: LevelResult, condition: str,
                 shift: LoadStiffnessShift) -> None:
    up, lo = level.halves["upper", condition], level.halves["lower", condition]
    refs = np.array([up.ref_points_m[0], up.ref_points_m[1], lo.ref_points_m[1]])
    np.savez(out / f"gimbal_{condition}.npz", K_upper_free=up.K_free, K_lower_free=lo.K_free,
             K_upper=up.K_held, K_lower=lo.K_held, ref_points_m=refs,
             ref_point_names=np.array(["bearing_centre", "upper_bolted_face", "lower_bolted_face"]),
             ref_points_upper_m=up.ref_points_m, ref_points_lower_m=lo.ref_points_m,
             condition=np.array(condition))
    C = shift.compliance_hanging_m_per_N if condition == "hanging" else shift.compliance_thrust_m_per_N
    bearing = ("spherical seat (ball cap / socket seat, r <= r_seat) closed and stuck" if condition == "thrust"
               else "seat open; retaining contact shoulder-bottom / lip-top (r_lip..r_shoulder) closed")
    write_toml(out / f"gimbal_{condition}.toml", {
        "": {"generator": GENERATOR, "condition": condition, "bearing_interface": bearing,
             "coupling": "RBE2 (rigid) on each interface surface, Guyan static condensation",
             "frame": "origin bearing centre; z engine -> thrust structure; x pitch-lateral; y yaw-lateral",
             "dof_order": "ux, uy, uz, rx, ry, rz per reference point; free matrices: bearing centre then bolted face",
             "units": "N/m, N/rad, N*m/m, N*m/rad blocks; points in m"},
        "mesh": {"element": "20-node serendipity hexahedron (ElementHexS2) on 27-node curved geometry",
                 "h_m": level.spec.h, "n_theta": level.spec.n_theta,
                 "upper_elements": up.n_elements, "upper_dofs": up.n_dofs,
                 "lower_elements": lo.n_elements, "lower_dofs": lo.n_dofs},
        "material": {"name": TI_6AL_4V.name, "youngs_modulus_Pa": TI_6AL_4V.youngs_modulus_Pa,
                     "poisson_ratio": TI_6AL_4V.poisson_ratio, "density_kg_m3": TI_6AL_4V.density_kg_m3},
        "geometry": {**geometry_table(geom), "mass_upper_kg": up.mass_kg, "mass_lower_kg": lo.mass_kg},
        "actuator_line": {"compliance_m_per_N": C},
    }, header=f"Provenance of gimbal_{condition}.npz (generated; do not edit).")


def engine_actuator_line(moment_arm_m: float = 0.8) -> ActuatorLine:
    """Pitch actuator line (along the engine axis at x = R, 0.5 m below O) with the engine's
    mesh-derived mass properties (taos.engine_geometry)."""
    from ..engine_geometry import engine_mass_properties
    p = engine_mass_properties()
    return ActuatorLine(attach_point_m=(moment_arm_m, 0.0, -0.5), engine_mass_kg=p.mass_kg,
                        engine_com_m=tuple(float(x) for x in p.com_m),
                        engine_inertia_about_gimbal_kgm2=p.inertia_pitch_kgm2)


def write_thrust_structure_modes(stem: Path, spec: ThrustStructureSpec, generator: str = GENERATOR,
                                 notes: dict | None = None):
    """Compute the frame's modes for ``spec`` and write ``stem``.npz (the MASV file contract) and
    its provenance ``stem``.toml (``notes``: extra top-level provenance keys); return the modes."""
    stem = Path(stem)
    modes = thrust_structure_modes(spec)
    np.savez(stem.with_suffix(".npz"), freq_hz=modes.freq_hz, damping_ratio=modes.damping_ratio,
             node_names=np.array(modes.node_names), node_xyz_m=modes.node_xyz_m, phi=modes.phi)
    write_toml(stem.with_suffix(".toml"), {
        "": {"generator": generator, "model": "notional engine-section frame (taos.fem.thrust_structure)",
             "element": "3-D Euler-Bernoulli frame, consistent mass", "boundary": "forward ring clamped",
             "frame": "vehicle: x along the axis forward positive, y and z lateral; origin on the axis in the cross-beam plane",
             "units": "freq_hz Hz; node_xyz_m m; phi translations m/sqrt(kg), rotations rad/sqrt(kg)",
             "normalisation": "phi^T M phi = 1", "damping": "0.5 % viscous on every mode (paper sec. 3.3)",
             **(notes or {})},
        "mesh": {"elements": modes.n_elements, "nodes": modes.n_nodes, "free_dofs": modes.n_dofs},
        "parameters": {**{k: v for k, v in asdict(spec).items()}, "structural_mass_kg": modes.total_mass_kg},
        "modes": {"count": int(modes.freq_hz.size), "freq_hz": [round(float(f), 4) for f in modes.freq_hz]},
    }, header=f"Provenance of {stem.name}.npz (generated; do not edit).")
    return modes


def build_fem_data(out: Path, coarse: bool = False, geom: GimbalGeometry = GimbalGeometry(),
                   line: ActuatorLine | None = None, log=print) -> dict:
    """Rebuild fem_data into ``out``; return a summary of the figures (also in README.md)."""
    out = Path(out)
    line = engine_actuator_line() if line is None else line
    out.mkdir(parents=True, exist_ok=True)
    timing = {}
    t0 = time.perf_counter()
    tube = cantilever_tube_check(0.02, 8) if coarse else cantilever_tube_check(0.015, 12)
    timing["verification_s"] = time.perf_counter() - t0
    log(f"tube check: max error {100 * tube.max_error:.2f} %")
    levels = []
    for spec in (COARSE_LEVELS if coarse else FINE_LEVELS):
        levels.append(run_level(geom, spec, line))
        log(f"mesh h={spec.h} n_theta={spec.n_theta}: {levels[-1].seconds:.1f} s")
    timing["gimbal_s"] = sum(lv.seconds for lv in levels)
    fine = levels[-1]
    shift = implied_load_stiffness(fine.compliance["hanging"], fine.compliance["thrust"])
    for c in CONDITIONS:
        _save_gimbal(out, geom, fine, c, shift)
    t1 = time.perf_counter()
    modes = write_thrust_structure_modes(out / "thrust_structure_modes", ThrustStructureSpec())
    timing["modes_s"] = time.perf_counter() - t1
    changes = relative_changes(levels)
    summary = {"tube": tube, "levels": levels, "changes": changes, "shift": shift, "modes": modes,
               "timing": timing, "coarse": coarse, "geom": geom, "line": line}
    write_toml(out / "mesh_study.toml", {
        "": {"generator": GENERATOR, "coarse": coarse,
             "max_relative_change_two_finest": max(changes.values())},
        **{f"level_{i}": {"h_m": lv.spec.h, "n_theta": lv.spec.n_theta, "seconds": lv.seconds,
                          "upper_dofs": lv.halves["upper", "thrust"].n_dofs,
                          "lower_dofs": lv.halves["lower", "thrust"].n_dofs, **lv.terms()}
           for i, lv in enumerate(levels)},
        "relative_change_two_finest": changes,
        "verification_tube": {"axial_ratio": tube.axial, "torsion_ratio": tube.torsion,
                              "lateral_ratio": tube.lateral, "rotation_ratio": tube.rotation,
                              "max_error": tube.max_error, "dofs": tube.n_dofs},
        "load_path": {"K_L_ambient_N_per_m": shift.K_L_ambient_N_per_m, "K_L_hotfire_N_per_m": shift.K_L_hotfire_N_per_m,
                      "K_L_ambient_lbf_per_in": shift.K_L_ambient_N_per_m / LBF_PER_IN,
                      "K_L_hotfire_lbf_per_in": shift.K_L_hotfire_N_per_m / LBF_PER_IN,
                      "rest_compliance_m_per_N": shift.rest_compliance_m_per_N,
                      "gimbal_compliance_hanging_m_per_N": shift.compliance_hanging_m_per_N,
                      "gimbal_compliance_thrust_m_per_N": shift.compliance_thrust_m_per_N},
    }, header="Gimbal mesh-convergence study and verification (generated; do not edit).")
    from .report import readme_text
    (out / "README.md").write_text(readme_text(summary))
    return summary
