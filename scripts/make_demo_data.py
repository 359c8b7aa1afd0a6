#!/usr/bin/env python
"""Make the SYNTHETIC Green Run style vectoring datasets in models/data/ (not test data).

Runs the notional two-axis Green Run profile (models/profiles/greenrun_two_axis.toml: pitch
and yaw at the same time at different frequencies, 0.4 deg up to 7 Hz and 0.8 deg up to
14 Hz, paper sec. 3.2) through a model and writes what a test would record:

* ambient:  models/rs25_ambient.toml, K_L = 115,000 lbf/in, friction "none" (the paper,
  sec. 1: friction was negligible in the unloaded gimbal);
* hot fire: models/rs25_hotfire.toml, K_L = 205,000 lbf/in, its modified LuGre friction
  (117,525 in-lbf: mu N r_b at the 1,860 kN sea-level thrust).

Both files carry the one servoactuator parameter set models/actuators/tvc_actuator.toml (the
flight-actuator calibration of issue 24.1): regenerate the datasets whenever it changes.

Then: sampled at 250 Hz, Gaussian sensor noise (piston 0.001 in RMS, engine 0.004 deg RMS)
and a constant engine-angle offset per axis (string pots without an absolute reference,
paper sec. 2), written as CSV with a TOML-comment header (``synthetic = true``, the truth
values, the seed). Deterministic (seeded).

Engines: ``--engine simplex`` (default) uses :func:`taos.planar.simulate.simulate` and writes
``greenrun_<condition>_synthetic.csv``. ``--engine taos`` runs the 3-D TAOS model
(:func:`taos.taos3d.simulate_taos`: the engine on its two-half FEM gimbal, each condition's own
``[gimbal] stiffness_file``: ambient ``gimbal_hanging.npz``, hot fire ``gimbal_thrust.npz``;
the actuator lines' stiffness derived from K_L with that gimbal in series) and writes
``greenrun_<condition>_synthetic_3d.csv`` beside the planar files. The 3-D ambient record keeps
the ambient model's OWN friction (its modified LuGre law at mu N r_b with N the engine weight,
not "none": the 3-D bearing carries the hanging engine's weight), so ``taos compare --engine
taos`` fits a friction level in both conditions. These files are regression data from a solver
independent of the planar one, kept with this script that made them (regenerate them whenever
a model file, the actuator set or a FEM gimbal pair changes).

Usage:  .venv/bin/python scripts/make_demo_data.py [--out models/data] [--engine simplex|taos]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from taos.identify.data import from_time_history  # noqa: E402
from taos.model import load_model  # noqa: E402
from taos.profiles import load_profile  # noqa: E402
from taos.planar.simulate import simulate  # noqa: E402
from taos.units import M_PER_IN, N_PER_M_PER_LBF_PER_IN, NM_PER_IN_LBF  # noqa: E402

DEG = math.pi / 180


def simulate_taos3d(model, profile, dt_s, record_every):
    """The 3-D TAOS model of ``model`` (its own FEM gimbal pair) run on ``profile``."""
    from taos.taos3d import simulate_taos, taos_model
    return simulate_taos(taos_model(model), profile, dt_s=dt_s, record_every=record_every)


ENGINES = {"simplex": simulate, "taos": simulate_taos3d}

CONDITIONS = {
    "ambient": dict(model="rs25_ambient.toml", friction="none", offset_deg=(0.031, -0.022), seed=11),
    "hotfire": dict(model="rs25_hotfire.toml", friction=None, offset_deg=(-0.017, 0.026), seed=12),
}
#: the 3-D records: the ambient model's own friction (None: the file's law), other seeds
CONDITIONS_3D = {
    "ambient": dict(CONDITIONS["ambient"], friction=None, seed=21),
    "hotfire": dict(CONDITIONS["hotfire"], seed=22),
}
PISTON_NOISE_IN = 0.001
ENGINE_NOISE_DEG = 0.004
DT_S = 2e-4
RECORD_EVERY = 20          # 250 Hz


def make(condition: str, out_dir: Path, engine: str = "simplex") -> Path:
    spec = (CONDITIONS_3D if engine == "taos" else CONDITIONS)[condition]
    model = load_model(ROOT / "models" / spec["model"], friction=spec["friction"])
    profile = load_profile(ROOT / "models" / "profiles" / "greenrun_two_axis.toml")
    th = ENGINES[engine](model, profile, dt_s=DT_S, record_every=RECORD_EVERY)
    rng = np.random.default_rng(spec["seed"])
    off = np.asarray(spec["offset_deg"]) * DEG
    data = from_time_history(th, engine_offset_rad=off, condition="hot fire" if condition == "hotfire" else condition,
                             source=condition)
    noisy = data.__class__(**{**data.__dict__,
                              "piston_m": data.piston_m + PISTON_NOISE_IN * M_PER_IN * rng.standard_normal(data.piston_m.shape),
                              "engine_rad": data.engine_rad + ENGINE_NOISE_DEG * DEG * rng.standard_normal(data.engine_rad.shape),
                              "metadata": {
                                  "description": "SYNTHETIC vectoring record made by scripts/make_demo_data.py, not test data",
                                  "engine_model": engine, "model_file": f"models/{spec['model']}",
                                  "friction_model": model.friction.name,
                                  "true_load_stiffness": f"{model.structure.load_stiffness_N_per_m / N_PER_M_PER_LBF_PER_IN:.6g} lbf/in",
                                  "true_coulomb_torque": (f"{model.friction.coulomb_torque_Nm / NM_PER_IN_LBF:.6g} in*lbf"
                                                          if model.friction.name != "none" else "none"),
                                  "profile": "models/profiles/greenrun_two_axis.toml",
                                  "piston_noise_rms": f"{PISTON_NOISE_IN} in", "engine_noise_rms": f"{ENGINE_NOISE_DEG} deg",
                                  "engine_offset_deg": ", ".join(f"{o:g}" for o in spec["offset_deg"]),
                                  "seed": spec["seed"], **_taos_meta(model, engine)}})
    path = out_dir / f"greenrun_{condition}_synthetic{'_3d' if engine == 'taos' else ''}.csv"
    noisy.to_csv(path, digits=6)
    return path


def _taos_meta(model, engine: str) -> dict:
    """The 3-D truth beyond K_L and T_c: the FEM gimbal pair and the derived line stiffness."""
    if engine != "taos":
        return {}
    from taos.taos3d import taos_model
    tm = taos_model(model)
    return {"stiffness_file": Path(tm.stiffness_source).name,
            "true_line_load_stiffness": f"{tm.line_load_stiffness_N_per_m / N_PER_M_PER_LBF_PER_IN:.6g} lbf/in",
            "true_friction_coefficient": f"{tm.gimbal.friction_coefficient:.6g}",
            "integration_step": f"{DT_S:g} s"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "models" / "data"))
    ap.add_argument("--engine", choices=sorted(ENGINES), default="simplex")
    args = ap.parse_args(argv)
    out = Path(args.out)
    for c in CONDITIONS:
        p = make(c, out, args.engine)
        print(f"wrote {p} ({p.stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
