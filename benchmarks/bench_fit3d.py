#!/usr/bin/env python
"""Time of the 3-D fit (taos.identify.fit3d, issue 39.1) on a 40 s two-axis record, with the
number of 3-D runs it took; peer: the planar fit (taos.identify.fit) of the same record.

The record: the hot-fire 3-D model with K_L = 180,000 lbf/in and T_c = 100,000 in-lbf, pitch
dwells 0.5/1/2/4/7/10/14 Hz and yaw dwells 0.75/1.5/3/5/8/12/16 Hz at once (0.4 deg; about 40 s),
250 Hz with sensor noise (tests/_records3d.py). Usage: python benchmarks/bench_fit3d.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests._records3d import IN_LBF, LBF_PER_IN, two_axis_profile, write_record3d  # noqa: E402

PITCH = ((0.5, 3, 0.4), (1.0, 6, 0.4), (2.0, 12, 0.4), (4.0, 24, 0.4), (7.0, 42, 0.4), (10.0, 60, 0.4),
         (14.0, 84, 0.4))
YAW = ((0.75, 4, 0.4), (1.5, 9, 0.4), (3.0, 18, 0.4), (5.0, 30, 0.4), (8.0, 48, 0.4), (12.0, 72, 0.4),
       (16.0, 112, 0.4))


def main() -> None:
    from taos.identify.data import load_test_data
    from taos.identify.estimation import estimate
    from taos.identify.fit import fit_frequency_response
    from taos.identify.fit3d import fit_taos
    from taos.model import load_model
    from taos.taos3d import taos_model, with_values
    from taos.taos3d.model import normal_load_N

    base = load_model(ROOT / "models" / "rs25_hotfire.toml")
    tm = taos_model(base)
    tc = 100000.0 * IN_LBF
    truth = with_values(tm, {"structure.load_stiffness": 180000.0 * LBF_PER_IN, "friction.coulomb_torque": tc,
                             "gimbal.friction_coefficient": tc / (normal_load_N(base) * tm.gimbal.bearing_radius_m)})
    with tempfile.TemporaryDirectory() as d:
        path = write_record3d(truth, Path(d) / "rec40.csv", profile=two_axis_profile(PITCH, YAW))
        data = load_test_data(path)
    print(f"record: {data.t_s[-1] - data.t_s[0]:.1f} s, two axes, {data.sample_rate_hz:.0f} Hz")
    t0 = time.perf_counter()
    res = fit_taos(tm, [data], ["load_stiffness", "coulomb_torque"], refuse=False)
    t3 = time.perf_counter() - t0
    print(res.table())
    print(f"3-D fit: {t3:.1f} s wall, {res.runs} 3-D runs ({res.global_search['cells']} in the grid), "
          f"{t3 / max(1, res.runs):.3f} s per run including estimation")
    t0 = time.perf_counter()
    pres = fit_frequency_response(base, estimate(data), ["load_stiffness", "coulomb_torque"])
    tp = time.perf_counter() - t0
    print(pres.table())
    print(f"planar fit of the same record (peer): {tp:.1f} s wall")


if __name__ == "__main__":
    main()
