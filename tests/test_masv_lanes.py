"""The MASV time-domain kernel's lane layout (masv._kernel): the lane operators equal the
coupled model's rows they were built from (blocks of unequal size, entries on another lane and
on the modes), and actuators with their own commands get their own avionics output."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from masv._kernel import _lanes, lane_layout, lane_operator
from masv.config import load_config
from masv.timedomain import simulate
from taos.profiles import load_profile

ROOT = Path(__file__).resolve().parents[1]


def test_lane_operator_equals_the_rows_it_was_built_from():
    rng = np.random.default_rng(7)
    offsets, nm = np.array([0, 3, 7, 9]), 2               # blocks of 3, 4 and 2 states, two modes
    na, N = 3, 9 + 2 * nm
    lay = lane_layout(offsets, nm)
    nv = N + 4 * na + nm
    # lane rows: each lane's row over the original stage vector, dense and random (own block,
    # other blocks' states, u, T, e_v, c_q of every actuator, q, q', q'')
    rows = [rng.standard_normal((na, nv)) * (rng.random((na, nv)) < 0.5) for _ in range(lay.m)]
    op = lane_operator(rows, lay.colmap, na, lay.ws0, lay.nw)
    W = rng.standard_normal(lay.nw)
    out = np.empty(lay.m * na)
    _lanes(*op.arrays(), W, lay.ws0, out)
    v = W[lay.colmap]                                     # the original stage vector
    ref = np.array([[r[k] @ v for k in range(na)] for r in rows]).ravel()
    assert np.abs(out - ref).max() <= 1e-12 * np.abs(ref).max()
    # the state map is one-to-one onto the kernel's state, blocks interleaved by lane
    assert len(set(lay.xmap.tolist())) == N and lay.xmap[offsets[1]] == 1 and lay.xmap[1] == na


def test_actuators_with_their_own_commands_get_their_own_avionics():
    cfg = load_config(ROOT / "models" / "masv" / "core_stage.toml")
    names = cfg.actuator_names
    step = load_profile(ROOT / "models" / "profiles" / "step_pitch.toml")
    green = load_profile(ROOT / "models" / "profiles" / "greenrun_two_axis.toml")
    h = simulate(cfg, {names[0]: step, names[3]: green, names[5]: green}, duration_s=0.8)
    for k, a in enumerate(cfg.actuators):
        av = cfg.engine(a.engine).model.avionics
        assert np.array_equal(h.command_avionics_rad[k], av(h.command_rad[k]))
    assert np.abs(h.command_rad[0]).max() > 0 and not np.array_equal(h.command_rad[0], h.command_rad[3])
    assert np.all(h.command_rad[[1, 2, 4, 6, 7]] == 0.0)
