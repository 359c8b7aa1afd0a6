"""``taos ascent --friction-follows-thrust`` (issue 43, part 3): along the ascent the Coulomb level
follows the trajectory's thrust, T_c(t) = mu N(t) r_b, on both axes; without the flag it stays the
model's. Read from the flown runs' HDF5: while the gimbal slides, the switching Coulomb law's torque
is exactly the level, so the largest |T_f| of each update interval with sliding is T_c there."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from taos.flight.ascent import load_ascent
from taos.model import load_model

MU, RB = 0.0649, 0.110   # models/rs25_flight.toml [gimbal] friction_coefficient, bearing_radius


@pytest.mark.parametrize("follow", [False, True])
def test_coulomb_level_along_the_ascent_follows_the_thrust_profile(tmp_path, follow):
    from taos.cli import main

    asc = load_ascent("ascent")
    m = load_model(asc.tvc_model, friction="coulomb-switching")
    out = tmp_path / "o"
    # 38-58 s: the booster phase, core thrust rising 1.98 -> 2.04 MN, a PTI on both axes at 40-55 s
    assert main(["ascent", "ascent", "--friction", "coulomb-switching", "--axis", "both", "--start", "38",
                 "--end", "58", "--out", str(out), "--dt", "2e-4"]
                + (["--friction-follows-thrust"] if follow else [])) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["friction_follows_thrust"] is follow
    assert s["runs"][0]["provenance"].get("friction_follows_thrust", False) is follow
    with h5py.File(out / "ascent_coulomb-switching.h5") as f:
        t = f["t_s"][()]
        for ax in ("pitch", "yaw"):
            tf, w = np.abs(f[ax]["friction_torque_Nm"][()]), np.abs(f[ax]["engine_rate_rad_s"][()])
            seen = []
            for a in np.arange(38.0, 58.0):   # the file's update interval: 1 s, the level held over each
                sel = (t > a + 1e-6) & (t < a + 1 - 1e-6)
                if w[sel].max() < 1e-3:       # stuck throughout: the torque stays below the level
                    continue
                n = float(asc.trajectory.at("core_thrust_per_engine_N", a + 0.5))
                level = MU * n * RB if follow else m.friction.coulomb_torque_Nm
                assert tf[sel].max() == pytest.approx(level, rel=2e-5), (ax, a)   # file T_c = mu N r_b to 5 digits
                seen.append((n, tf[sel].max()))
            assert len(seen) >= 5, ax
            (n0, t0), (n1, t1) = seen[0], seen[-1]
            assert n1 / n0 > 1.02   # the thrust changed along the stretch checked
            if follow:
                assert t1 / t0 == pytest.approx(n1 / n0, rel=1e-9)
            else:
                assert t1 == t0 == pytest.approx(MU * m.engine.thrust_N * RB, rel=2e-5)


def test_campaign_key_flies_the_runs_with_the_level_following_the_thrust(tmp_path):
    """``friction_follows_thrust = true`` in a campaign file: each run is flown as
    simulate_ascents(..., friction_follows_thrust=True) flies it (its stored traces are that run's),
    and differs from the default where the thrust is not the model's; not a boolean: named."""
    from taos.errors import InputError
    from taos.flight.ascent_sim import simulate_ascents
    from taos.montecarlo import load_campaign
    from taos.montecarlo.campaign import apply_factors, base_models
    from taos.montecarlo.executor import flight_runs

    src = (Path(__file__).resolve().parent / "data" / "mc_short.toml").read_text()
    asc = (Path(__file__).resolve().parent.parent / "models" / "flight" / "ascent.toml").as_posix()
    src = src.replace('"../../models/flight/ascent.toml"', json.dumps(asc)).replace('"120 s"', '"30 s"')
    kinds = {}
    for follow in (False, True):
        p = tmp_path / f"c{follow}.toml"
        p.write_text(src.replace('axis = "yaw"', f'axis = "yaw"\nfriction_follows_thrust = {str(follow).lower()}'))
        kinds[follow] = flight_runs(load_campaign(p), "soft", None)[0]
    c = kinds[True].campaign
    assert c.friction_follows_thrust and not kinds[False].campaign.friction_follows_thrust
    names = tuple(d.name for d in c.dispersions)
    ones, seeds = np.ones((1, len(names))), np.array([3])
    out = {f: k.run_batch(names, ones, seeds) for f, k in kinds.items()}
    asc_, m = base_models(c)
    a2, m2, _ = apply_factors(asc_, m, c.cases["soft"], dict(zip(names, [1.0] * len(names))))
    h = simulate_ascents([(a2, m2, 3)], axis="yaw", start_s=30.0, end_s=70.0, dt_s=c.dt_s, record_interval_s=0.02,
                         friction_follows_thrust=True)[0]
    t = kinds[True].trace_t_s
    assert np.array_equal(out[True]["engine_trace"][0], np.interp(t, h.t_s, h.signal("engine_rad", "yaw")))
    assert not np.array_equal(out[True]["trace"][0], out[False]["trace"][0])
    bad = tmp_path / "bad.toml"
    bad.write_text(src.replace('axis = "yaw"', 'axis = "yaw"\nfriction_follows_thrust = "yes"'))
    with pytest.raises(InputError, match="friction_follows_thrust"):
        load_campaign(bad)
