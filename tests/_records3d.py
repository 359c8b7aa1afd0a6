"""Two-axis test records made by the 3-D TAOS model (deterministic, seeded), for the 3-D fit
(:mod:`taos.identify.fit3d`): pitch and yaw sine dwells at the same time at different
frequencies (the Green Run practice, paper sec. 3.2), run through :func:`taos.taos3d.simulate_taos`
with known parameters, sampled at 250 Hz with Gaussian sensor noise (piston 0.001 in RMS, engine
0.004 deg RMS) and an unknown constant engine-angle offset per axis, written as CSV."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from taos.identify.data import from_time_history
from taos.profiles import Sequence, SineDwell, TwoAxis

ROOT = Path(__file__).resolve().parents[1]
DEG = math.pi / 180
IN = 0.0254
LBF_PER_IN = 175.12683524647636
IN_LBF = 0.1129848290276167
#: (frequency Hz, cycles, amplitude deg): 4 s per segment on each axis, 12 s in all
PITCH_DWELLS = ((1.0, 4, 0.4), (3.0, 12, 0.4), (7.0, 28, 0.4))
YAW_DWELLS = ((1.5, 6, 0.4), (4.5, 18, 0.4), (10.0, 40, 0.4))


def two_axis_profile(pitch=PITCH_DWELLS, yaw=YAW_DWELLS) -> TwoAxis:
    seq = lambda d: Sequence(tuple(SineDwell(a * DEG, f, c) for f, c, a in d))  # noqa: E731
    return TwoAxis(seq(pitch), seq(yaw), "two-axis dwells (3-D fit test)")


def write_record3d(tm, path: Path, seed: int = 7, profile=None, condition: str = "hot fire",
                   offsets_deg=(0.02, -0.015), meta: dict | None = None) -> Path:
    """Simulate ``profile`` (default :func:`two_axis_profile`) through 3-D model ``tm`` and write
    the noisy 250 Hz record to ``path``."""
    from taos.taos3d import simulate_taos

    th = simulate_taos(tm, profile or two_axis_profile(), dt_s=4e-4, record_every=10)
    rng = np.random.default_rng(seed)
    d = from_time_history(th, engine_offset_rad=np.asarray(offsets_deg) * DEG, condition=condition,
                          source=path.name)
    noisy = dataclasses.replace(
        d, piston_m=d.piston_m + 0.001 * IN * rng.standard_normal(d.piston_m.shape),
        engine_rad=d.engine_rad + 0.004 * DEG * rng.standard_normal(d.engine_rad.shape),
        load_pressure_Pa=None, spool_flow_m_s=None, supply_pressure_Pa=None,
        metadata={"description": "SYNTHETIC two-axis record made by tests/_records3d.py (3-D TAOS model)",
                  "seed": seed, **(meta or {})})
    noisy.to_csv(path, digits=8)
    return path
