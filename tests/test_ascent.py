"""Ascent flight with boosters, PTIs and winds (seed paper sec. 3.2, figs. 7-8)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from taos.flight.ascent import control_acceleration, load_ascent, pti_command
from taos.flight.ascent_sim import analyse_ascent, flight_at, simulate_ascent, simulate_ascents
from taos.flight.lco import simulate_flight, with_bounding_avionics
from taos.flight.vehicle import loop_freqresp
from taos.model import Structure, load_model

LBF_PER_IN = 175.12683524647636
PAPER_LCO_DEG = 0.1  # paper sec. 3.2: "the LCO reaches an amplitude of about 0.1 degrees"


@pytest.fixture(scope="module")
def ascent():
    return load_ascent("ascent")


def _model(ascent, law, k_lbf_in):
    m = load_model(ascent.tvc_model, friction=law)
    return with_bounding_avionics(m).replace(structure=Structure(k_lbf_in * LBF_PER_IN))


def test_post_separation_loop_is_the_flight_file_loop(ascent):
    """At the trajectory point equal to core_stage.toml (130 s, after separation) the scheduled
    loop is exactly the flight file's loop (gain factor 1, same vehicle)."""
    fl, boost = flight_at(ascent, 130.0, "yaw")
    assert boost == 0.0
    f = np.logspace(-2, 1, 50)
    np.testing.assert_allclose(loop_freqresp(fl, f, "yaw"), loop_freqresp(ascent.flight, f, "yaw"), rtol=1e-12)


def test_gain_scheduling_keeps_the_rigid_body_loop():
    """Control-effectiveness scheduling: K a(t) = K_ref a_ref at every point of the trajectory
    (so the rigid-body loop keeps its crossover), boosters included before separation."""
    asc = load_ascent("ascent")
    a_ref = asc.flight.vehicle.control_acceleration_per_s2("yaw") * asc.flight.fcs.attitude_gain
    for t in (10.0, 60.0, 110.0, 200.0, 470.0):
        fl, boost = flight_at(asc, t, "yaw")
        core = fl.vehicle.control_acceleration_per_s2("yaw")
        assert fl.fcs.attitude_gain * (core + boost) == pytest.approx(a_ref, rel=1e-12)
    core, boost = control_acceleration(asc, np.array([0.0, 125.0, 127.0]))
    assert boost[0] > 3 * core[0]          # boosters carry most of the authority at liftoff
    assert boost[2] == 0.0                 # none after separation


def test_one_segment_equals_the_constant_flight_loop(ascent):
    """Identity between two code paths: an ascent with the trajectory frozen at the flight file's
    vehicle, no boosters, wind or PTI, flown from a 0.2 deg attitude error, equals
    :func:`taos.flight.lco.simulate_flight` of the same loop (same kernel, segments carried)."""
    tr = ascent.trajectory
    n = tr.time_s.size
    v = ascent.flight.vehicle
    frozen = dataclasses.replace(
        tr, mass_kg=np.full(n, v.mass_kg), inertia_kgm2=np.full(n, v.yaw_inertia_kgm2),
        gimbal_arm_m=np.full(n, v.gimbal_arm_m), core_thrust_per_engine_N=np.full(n, v.thrust_per_engine_N),
        booster_thrust_N=np.zeros(n), dynamic_pressure_Pa=np.zeros(n), wind_speed_m_s=np.zeros(n))
    asc = dataclasses.replace(ascent, trajectory=frozen, ptis=(), update_interval_s=2.0,
                              boosters=dataclasses.replace(ascent.boosters, count=0))
    wind = dataclasses.replace(asc.wind, scale=0.0)
    asc = dataclasses.replace(asc, wind=wind)
    m = load_model(ascent.tvc_model, friction="dahl")
    h = simulate_ascent(asc, m, axes=("yaw",), start_s=0.0, end_s=20.0, dt_s=1e-3, record_interval_s=0.01,
                        attitude0_rad=math.radians(0.2))
    ref = simulate_flight(ascent.flight, m, 20.0, attitude0_rad=math.radians(0.2), axis="yaw", dt_s=1e-3,
                          record_every=10)
    np.testing.assert_allclose(h.signal("engine_rad", "yaw"), ref.engine_rad, rtol=0, atol=1e-12)
    np.testing.assert_allclose(h.signal("attitude_rad", "yaw"), ref.attitude_rad, rtol=0, atol=1e-12)


def test_ascent_plant_keeps_every_limit_of_the_flight_plant(ascent):
    """The ascent plant is the flight plant grown by the booster state: the packed actuator and
    gimbal limits (valve rate, supply pressure and relief, hard stops) are the flight plant's
    over the same states, zero on the booster state; a limit pack over the wrong number of
    states is refused."""
    from taos.flight.ascent_sim import ascent_plant
    from taos.flight.vehicle import flight_plant
    from taos.planar import saturation as sat
    from taos.planar.simplex import LurePlant

    m = load_model(ascent.tvc_model, friction="dahl")
    assert m.actuator.pressure_limited
    base = flight_plant(ascent.flight, m, "yaw")
    grown = ascent_plant(ascent.flight, m, "yaw", 1.0, 0.1)
    n0, n = base.ss.A.shape[0], grown.ss.A.shape[0]
    assert n == n0 + 1 and sat.n_limit_states(grown.limits) == n
    assert base.limits[sat.LIM_PS] > 0.0
    np.testing.assert_array_equal(grown.limits[:sat.N_HEAD], base.limits[:sat.N_HEAD])
    for i in range(sat.N_ROWS):
        row = grown.limits[sat.row_start(i, n):sat.row_start(i + 1, n)]
        np.testing.assert_array_equal(row[:n0], base.limits[sat.row_start(i, n0):sat.row_start(i + 1, n0)])
        assert row[n0] == 0.0
    with pytest.raises(ValueError, match="limits packed over"):
        LurePlant(ss=grown.ss, n_ext=2, cmd_c=grown.cmd_c, cmd_d=grown.cmd_d, rate_c=grown.rate_c,
                  applied_c=grown.applied_c, inertia_kgm2=grown.inertia_kgm2, limits=base.limits)


def test_pti_windows_and_signals(ascent):
    t = np.linspace(0, 480, 48001)
    u = pti_command(ascent, "yaw", t)
    for p in ascent.ptis:
        inside = (t > p.start_s + 0.5) & (t < p.end_s - 0.5)
        assert np.max(np.abs(u[inside])) == pytest.approx(p.amplitude_rad, rel=0.05)
    quiet = np.ones_like(t, bool)
    for p in ascent.ptis:
        quiet &= (t < p.start_s) | (t > p.end_s)
    assert np.all(u[quiet] == 0.0)


def _yaw_on_both_structures(ascent, law, dt_s):
    """The yaw axis flown 100-300 s with ``law`` on the soft and the stiff structure
    ({115000: history, 205000: history}), side by side in one lockstep kernel call
    (:func:`simulate_ascents`, seed 0 as :func:`simulate_ascent`'s default): a run's numbers do not
    depend on the other runs of its call (tests/test_montecarlo.py, lockstep tests), and the pair
    costs about 0.6 of two calls."""
    ks = (115000, 205000)
    flown = simulate_ascents([(ascent, _model(ascent, law, k), 0) for k in ks], axis="yaw", start_s=100, end_s=300,
                             dt_s=dt_s, record_interval_s=0.02)
    for h in flown:
        if isinstance(h, Exception):
            raise h
    return dict(zip(ks, flown))


@pytest.mark.slow
def test_figure_7_and_8_on_a_shortened_segment(ascent):
    """Paper figs. 7-8 on 100-300 s (separation at 126 s, quiescent 141-170 s, a PTI at 170-190 s,
    quiescent after): soft structure (115,000 lbf/in, 144,000 in-lbf): every law limit-cycles in
    the quiescent windows; in the PTI's second half the friction adds at the LCO frequency less
    than half the cycle it had before the PTI (the PTI breaks the cycle up). Stiff structure
    (205,000 lbf/in): no LCO for Dahl and LuGre; the Coulomb LCO about halved."""
    res = {}
    ref = _yaw_on_both_structures(ascent, "none", 1e-3)
    for law in ("coulomb-switching", "dahl", "lugre"):
        flown = _yaw_on_both_structures(ascent, law, 2e-4 if law == "coulomb-switching" else 1e-3)
        for k, h in flown.items():
            w = analyse_ascent(h, ref[k])
            res[k, law] = ({("quiescent_before" if x.kind == "quiescent" and x.end_s <= 170.0 else x.kind): x
                            for x in w if x.start_s < 250}, h)
    for law in ("coulomb-switching", "dahl", "lugre"):
        win, h = res[115000, law]
        assert win["quiescent"].lco, law
        assert 0.2 * PAPER_LCO_DEG < math.degrees(win["quiescent"].amplitude_rad) < 2.5 * PAPER_LCO_DEG, law
        assert 0.085 <= win["quiescent"].freq_hz <= 0.2, law  # paper: 0.1-0.2 Hz (LuGre still growing: 0.095)
        assert win["quiescent_before"].lco, law
        assert win["pti"].friction_band_amplitude_rad < 0.5 * win["quiescent_before"].amplitude_rad, law
        pre = h.t_s < ascent.boosters.separation_time_s                  # no LCO before separation
        assert np.max(np.abs(h.signal("command_rad", "yaw")[pre])) < math.radians(0.6)
    for law in ("dahl", "lugre"):
        assert not res[205000, law][0]["quiescent"].lco, law
    ratio = res[205000, "coulomb-switching"][0]["quiescent"].amplitude_rad / \
        res[115000, "coulomb-switching"][0]["quiescent"].amplitude_rad
    assert 0.35 < ratio < 0.75                                           # "reduced by half"


def test_ascent_cli_writes_runs_and_refuses_foreign_names(tmp_path):
    from taos.cli import main
    out = tmp_path / "asc"
    assert main(["ascent", "ascent", "--friction", "dahl", "--start", "120", "--end", "150", "--dt", "1e-3",
                 "--out", str(out), "--json", str(tmp_path / "s.json")]) == 0
    # (and taos's mark .taos-output.json, the list of the files it wrote there: docs/reference/bounds.md)
    assert {p.name for p in out.iterdir()} == {"ascent_dahl.h5", "ascent.png", "summary.json", ".taos-output.json"}
    import h5py
    with h5py.File(out / "ascent_dahl.h5") as f:
        assert f.attrs["ascent_sha256"] and f["yaw/engine_rad"].shape == f["t_s"].shape
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "summary.json").write_text("my notes")
    assert main(["ascent", "ascent", "--friction", "dahl", "--start", "120", "--end", "150",
                 "--out", str(tmp_path / "mine")]) == 2
    assert (tmp_path / "mine" / "summary.json").read_text() == "my notes"


def test_fly_ascent_is_the_cli_study(tmp_path, ascent):
    """``taos ascent`` is :func:`taos.fly_ascent` plus files: the library's study summarises to
    the command's summary.json; a law ``none`` in the list is the reference run itself."""
    import json

    import taos
    from taos.cli import main
    out = tmp_path / "asc"
    assert main(["ascent", "ascent", "--friction", "dahl,none", "--start", "120", "--end", "150", "--dt", "1e-3",
                 "--out", str(out)]) == 0
    tvc = lambda law: load_model(ascent.tvc_model, friction=law)  # noqa: E731
    study = taos.fly_ascent(ascent, [tvc("dahl"), tvc("none")], reference=tvc("none"), start_s=120.0,
                            end_s=150.0, dt_s=1e-3)
    assert isinstance(study, taos.AscentStudy) and study.runs[1] is study.reference
    assert [h.friction_model for h in study.runs] == ["dahl", "none"] and study.axes == ("yaw",)
    assert study.summary() == json.loads((out / "summary.json").read_text())
    assert {p.name for p in out.iterdir()} >= {f["file"] for f in study.summary()["runs"]}
    duty = study.summary()["runs"][0]["duty"]   # the hydraulic duty cycle against the model's limits
    yaw = duty["axes"]["yaw"]
    assert yaw["flow_limit_m3_s"] == tvc("dahl").actuator.rated_flow_m3_per_s > 0
    assert 0 < yaw["peak_flow_fraction_of_limit"] and duty["engine"]["mean_flow_fraction_of_pump"] > 0


@pytest.mark.parametrize("patch, field", [
    ("[boosters]\ncount = -1", "boosters.count"),
    ("[wind]\ngust_duratoin = \"4 s\"", "wind.gust_duratoin"),
    ("[[pti]]\nstart = \"10 s\"\nkind = \"chirp\"", "pti[4].kind"),
])
def test_bad_ascent_files_name_the_field(tmp_path, patch, field):
    from taos.errors import InputError
    from taos.shipped import models_dir
    text = (models_dir() / "flight" / "ascent.toml").read_text()
    section = patch.split("\n")[0]
    if section.startswith("[[pti]]"):
        text += "\n" + patch + "\n"
    else:
        head, rest = text.split(section + "\n", 1)
        key = patch.split("\n")[1].split(" =")[0]
        lines = [ln for ln in rest.split("\n") if not ln.startswith(key.replace("oin", "ion") + " ")]
        text = head + patch + "\n" + "\n".join(lines)
    p = tmp_path / "ascent.toml"
    p.write_text(text.replace('flight = "core_stage.toml"', f'flight = "{models_dir() / "flight" / "core_stage.toml"}"')
                 .replace('tvc_model = "../rs25_flight.toml"', f'tvc_model = "{models_dir() / "rs25_flight.toml"}"'))
    with pytest.raises(InputError) as e:
        load_ascent(p)
    assert field in str(e.value)
