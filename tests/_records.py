"""Test records made by the simulator (deterministic, seeded): a mixed record (pitch dwells and
a yaw sweep at once) and a series of records of one hardware item whose load stiffness K_L and
friction level drift by known amounts. Written as CSV the way a test stand would record them:
sampled at 250 Hz, Gaussian sensor noise (piston 0.001 in RMS, engine 0.004 deg RMS), engine
angles with an unknown constant offset per axis (string pots)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from taos.identify.data import from_time_history
from taos.model import load_model
from taos.planar.simulate import simulate
from taos.profiles import Sequence, SineDwell, SineSweep, Step, TwoAxis

ROOT = Path(__file__).resolve().parents[1]
DEG = math.pi / 180
IN = 0.0254
LBF_PER_IN = 175.126835          # N/m per lbf/in
IN_LBF = 0.112984829             # N*m per in*lbf
PISTON_NOISE_IN = 0.001
ENGINE_NOISE_DEG = 0.004

#: pitch dwells (Hz, cycles, amplitude deg) of the mixed record and the series records
PITCH_DWELLS = ((1.0, 6, 0.4), (2.0, 10, 0.4), (4.0, 16, 0.4), (7.0, 21, 0.4), (10.0, 30, 0.8))
#: yaw: 2 s quiet, then a logarithmic sweep 0.5 -> 14 Hz over 20 s at 0.4 deg
YAW_QUIET_S, YAW_SWEEP = 2.0, (0.4, 0.5, 14.0, 20.0)


def mixed_profile() -> TwoAxis:
    """Pitch sine dwells (:data:`PITCH_DWELLS`) while yaw is quiet, then sweeps."""
    pitch = Sequence(tuple(SineDwell(a * DEG, f, c) for f, c, a in PITCH_DWELLS))
    a, f0, f1, T = YAW_SWEEP
    yaw = Sequence((Step(0.0, 0.0, YAW_QUIET_S), SineSweep(a * DEG, f0, f1, T)))
    return TwoAxis(pitch, yaw, "pitch dwells + yaw sweep")


def with_drift(model, load_stiffness_lbf_in: float, coulomb_torque_in_lbf: float):
    """``model`` with K_L and the Coulomb torque set (the static torque scaled with it, as a
    fitted model file is written: :data:`taos.identify.surrogate.PARAMETERS`)."""
    from taos.identify.surrogate import PARAMETERS

    m = model.replace(structure=dataclasses.replace(model.structure,
                                                    load_stiffness_N_per_m=load_stiffness_lbf_in * LBF_PER_IN))
    return PARAMETERS["coulomb_torque"].set(m, coulomb_torque_in_lbf * IN_LBF)


def write_record(model, profile, path: Path, seed: int, meta: dict | None = None, offsets_deg=(0.02, -0.015)) -> Path:
    """Simulate ``profile`` through ``model`` and write the noisy 250 Hz record to ``path``."""
    th = simulate(model, profile, dt_s=2e-4, record_every=20)
    rng = np.random.default_rng(seed)
    n_ax = len(th.axes)
    d = from_time_history(th, engine_offset_rad=np.asarray(offsets_deg[:n_ax]) * DEG, condition="hot fire",
                          source=path.name)
    noisy = dataclasses.replace(
        d, piston_m=d.piston_m + PISTON_NOISE_IN * IN * rng.standard_normal(d.piston_m.shape),
        engine_rad=d.engine_rad + ENGINE_NOISE_DEG * DEG * rng.standard_normal(d.engine_rad.shape),
        load_pressure_Pa=None, spool_flow_m_s=None, supply_pressure_Pa=None,
        metadata={"description": "SYNTHETIC record made by tests/_records.py", "seed": seed, **(meta or {})})
    noisy.to_csv(path, digits=7)
    return path


def mixed_record(path: Path) -> Path:
    """The hot-fire model run with :func:`mixed_profile` (pitch dwells, yaw quiet then sweep)."""
    return write_record(load_model(ROOT / "models" / "rs25_hotfire.toml"), mixed_profile(), path, seed=5)


#: the series: (test date, K_L lbf/in, Coulomb torque in*lbf) -- K_L falls 6,000 lbf/in and the
#: friction level rises 4,000 in*lbf from one test to the next (a known, linear drift)
SERIES = (("2026-03-02", 205000.0, 110000.0), ("2026-03-09", 199000.0, 114000.0),
          ("2026-03-16", 193000.0, 118000.0), ("2026-03-23", 187000.0, 122000.0))


def series_profile():
    """Pitch-only sine dwells (:data:`PITCH_DWELLS`): each record of the series."""
    return Sequence(tuple(SineDwell(a * DEG, f, c) for f, c, a in PITCH_DWELLS))


def series_records(folder: Path, dated: bool = True) -> list[Path]:
    """One record per :data:`SERIES` entry, made by the hot-fire model with that K_L and friction;
    written in REVERSED order of their dates (the series must sort them by ``test_date``)."""
    base = load_model(ROOT / "models" / "rs25_hotfire.toml")
    out = []
    for k, (date, kl, tc) in enumerate(SERIES):
        meta = {"true_load_stiffness": f"{kl:g} lbf/in", "true_coulomb_torque": f"{tc:g} in*lbf"}
        if dated:
            meta["test_date"] = __import__("datetime").date.fromisoformat(date)
        out.append(write_record(with_drift(base, kl, tc), series_profile(), folder / f"test_{k + 1}.csv",
                                seed=40 + k, meta=meta, offsets_deg=(0.01 * (k + 1),)))
    return out[::-1]
