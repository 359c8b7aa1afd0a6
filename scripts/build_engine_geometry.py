#!/usr/bin/env python
"""Rebuild models/meshes/ (RS-25 powerhead and nozzle STL), models/rs25_engine.urdf, and the
inertia_pitch / inertia_yaw lines of models/rs25_{ambient,hotfire,flight}.toml from the meshes.

Usage: python scripts/build_engine_geometry.py [--coarse] [--out DIR] [--no-model-files]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from taos.engine_geometry import (EngineGeometry, engine_mass_properties, load_part_meshes,  # noqa: E402
                                  part_meshes, rewrite_model_inertia, urdf_text)

MODEL_FILES = ("rs25_ambient.toml", "rs25_hotfire.toml", "rs25_flight.toml")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--coarse", action="store_true", help="fewer facets (tests)")
    ap.add_argument("--out", type=Path, default=ROOT / "models", help="models directory")
    ap.add_argument("--no-model-files", action="store_true", help="do not rewrite the model files' inertia lines")
    args = ap.parse_args(argv)
    geom = EngineGeometry()
    if args.coarse:
        geom = replace(geom, sections=32, profile_points=13)
    mesh_dir = args.out / "meshes"
    mesh_dir.mkdir(parents=True, exist_ok=True)
    for name, mesh in part_meshes(geom).items():
        mesh.export(mesh_dir / f"rs25_{name}.stl")
    # mass properties from the files as written (float32 STL), so checks can repeat them exactly
    props = engine_mass_properties(load_part_meshes(mesh_dir), geom)
    (args.out / "rs25_engine.urdf").write_text(urdf_text(props))
    if not args.no_model_files:
        for f in MODEL_FILES:
            rewrite_model_inertia(args.out / f, props)
    print(f"engine {props.mass_kg:.0f} kg, centre of mass z = {props.com_m[2]:.3f} m, "
          f"I_pitch = {props.inertia_pitch_kgm2:.0f} kg m^2, I_yaw = {props.inertia_yaw_kgm2:.0f} kg m^2 about the gimbal")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
