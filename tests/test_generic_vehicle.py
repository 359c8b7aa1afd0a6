"""Any launcher's flight (issue 42.4): a second, non-SLS vehicle flies through every flight tool.

The shipped generic two-engine upper stage (``models/flight/generic_upper_stage.toml``, its ascent
``generic_upper_ascent.toml``, its engine ``models/generic_upper_engine.toml`` and the campaign
``models/montecarlo/generic_upper_stage.toml``) differs from the SLS core stage in engine count
(2 vs 4), inertia (1.1e6 vs 4.5e8 kg m^2), thrust (180 vs 2279 kN per engine), gimbal arm, FCS
gains and servo size; ``taos lco``, ``taos ascent`` and ``taos montecarlo`` give it a verdict.
Its servo is dynamically similar to the RS-25 set (time scale 1): its lab response in angle is
the RS-25's, which is what makes it a credible flight servo without a second calibration.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from taos.flight.ascent import load_ascent
from taos.flight.vehicle import flight_loop_margins, load_flight
from taos.model import load_model
from taos.planar.simplex import simplex_state_space

from .conftest import MODELS, run_cli

GENERIC = MODELS / "flight" / "generic_upper_stage.toml"
ASCENT = MODELS / "flight" / "generic_upper_ascent.toml"
ENGINE = MODELS / "generic_upper_engine.toml"
CAMPAIGN = MODELS / "montecarlo" / "generic_upper_stage.toml"


def test_the_second_vehicle_is_not_the_sls_one():
    g, s = load_flight(GENERIC), load_flight(MODELS / "flight" / "core_stage.toml")
    gv, sv = g.vehicle, s.vehicle
    assert (gv.engine_count, sv.engine_count) == (2, 4)
    assert gv.pitch_inertia_kgm2 == pytest.approx(1.1e6) and gv.thrust_per_engine_N == pytest.approx(180e3)
    assert g.fcs.attitude_gain != s.fcs.attitude_gain and g.fcs.integral_gain_per_s != s.fcs.integral_gain_per_s
    # the engine count enters the control acceleration a = n T l_c / I: 2 x 180 kN x 8 m / 1.1e6
    assert gv.control_acceleration_per_s2("pitch") == pytest.approx(2 * 180e3 * 8.0 / 1.1e6)
    m = flight_loop_margins(g)      # the figures the flight file's header states
    assert m.low_gain_margin_db == pytest.approx(9.5, abs=0.05) and m.low_phase_crossover_hz == pytest.approx(0.094, abs=0.001)
    assert m.phase_margin_deg == pytest.approx(56.5, abs=0.5) and m.high_gain_margin_db == pytest.approx(24.7, abs=0.1)
    assert g.tvc_model == str(ENGINE)


def _lab(m):
    return dataclasses.replace(m, structure=dataclasses.replace(m.structure, load_stiffness_N_per_m=1e12))


@pytest.mark.parametrize("lab", [True, False])
def test_the_small_servo_is_dynamically_similar_to_the_rs25_set(lab):
    """Command -> engine angle of the generic engine equals the RS-25 flight model's within 0.1 dB
    and 0.5 deg over 0.05-30 Hz, in the lab and on each flight load path (5.3 Hz load mode)."""
    g, r = load_model(ENGINE), load_model(MODELS / "rs25_flight.toml")
    if lab:
        g, r = _lab(g), _lab(r)
    f = np.geomspace(0.05, 30.0, 60)
    hg = simplex_state_space(g, "pitch").freqresp(f, "command_rad", "theta_rad")
    hr = simplex_state_space(r, "pitch").freqresp(f, "command_rad", "theta_rad")
    assert np.max(np.abs(20 * np.log10(np.abs(hg / hr)))) < 0.1
    assert np.max(np.abs(np.degrees(np.angle(hg / hr)))) < 0.5
    # the pre-sliding angle T_c / sigma_0 is the RS-25's (0.072 deg)
    assert np.degrees(g.friction.coulomb_torque_Nm / g.friction.bristle_stiffness_Nm_per_rad) == pytest.approx(
        np.degrees(r.friction.coulomb_torque_Nm / r.friction.bristle_stiffness_Nm_per_rad), rel=0.01)


def test_ascent_without_boosters_loads_with_the_defaults():
    a = load_ascent(ASCENT)
    assert a.boosters.count == 0 and a.flight.vehicle.engine_count == 2
    from taos.flight.ascent import control_acceleration
    core, boost = control_acceleration(a, np.array([0.0, 400.0]))
    assert core == pytest.approx([2 * 180e3 * 8.0 / 1.1e6, 2 * 180e3 * 9.5 / 0.45e6]) and not boost.any()


def test_lco_verdict_for_the_generic_stage(tmp_path):
    r = run_cli("lco", ENGINE, "--flight", GENERIC, "--no-time-domain", "--amplitudes-deg", "0.03,0.1,0.3,1",
                "--freq-hz", "0.05,0.08,0.1,0.13,0.2,0.4", "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout[: r.stdout.rindex("}") + 1])
    assert d["verdict"]["kind"] == "none" and d["lco"] is False
    assert 0.3 < d["margin_db"] < 1.5          # close to the edge: 0.72 dB (9.5 dB loop margin, ~8.8 dB TVC gain loss)


def test_taos_ascent_flies_the_generic_stage(tmp_path):
    out = tmp_path / "asc"
    r = run_cli("ascent", ASCENT, "--axis", "pitch", "--end", "40", "--dt", "5e-4", "--friction", "dahl",
                "--out", out, "--json", "-")
    assert r.returncode == 0, r.stderr
    s = json.loads((out / "summary.json").read_text())
    (run,) = s["runs"]
    assert run["friction_model"] == "dahl"
    quiet = [w for w in run["windows"] if w["kind"] == "quiescent"]
    assert quiet and all(isinstance(w["lco"], bool) for w in quiet)


def test_montecarlo_campaign_of_the_generic_stage(tmp_path):
    from taos.montecarlo import load_campaign, run_campaign

    c = load_campaign(CAMPAIGN)
    assert load_ascent(c.ascent_file).flight.vehicle.engine_count == 2
    res = run_campaign(c, tmp_path / "mc", runs=2, workers=0, progress=False)
    s = res.summary
    assert s["runs_ok"] == 2 and s["lco_fraction"]["lco_runs"] in (0, 1, 2)


def test_template_writes_the_generic_ascent_and_it_loads(tmp_path):
    p = tmp_path / "mine.toml"
    r = run_cli("ascent", "--template", p)
    assert r.returncode == 0, r.stderr
    a = load_ascent(p)         # its references resolve from the shipped folder by the one rule
    assert a.flight.vehicle.engine_count == 2 and a.tvc_model == str(ENGINE)
    again = run_cli("ascent", "--template", p)
    assert again.returncode == 2 and again.stderr.count("\n") == 1 and "exists" in again.stderr
    both = run_cli("ascent", ASCENT, "--template", tmp_path / "x.toml")
    assert both.returncode == 2 and not (tmp_path / "x.toml").exists()


def test_flight_files_page_names_every_key_of_the_shipped_flight_and_ascent_files():
    import tomllib

    from taos.flight.ascent import TRAJECTORY_COLUMNS
    from taos.flight.vehicle import _FCS_KEYS, _VEHICLE_KEYS

    text = (MODELS.parent / "docs" / "reference" / "flight_files.md").read_text(encoding="utf-8")
    keys = set(TRAJECTORY_COLUMNS) | set(_VEHICLE_KEYS) | set(_FCS_KEYS) | {"engine_count", "pade_order"}
    for f in ("core_stage", "generic_upper_stage", "ascent", "generic_upper_ascent"):
        doc = tomllib.loads((MODELS / "flight" / f"{f}.toml").read_text(encoding="utf-8"))
        for k, v in doc.items():
            keys.add(k)
            for item in (v if isinstance(v, list) else [v]):
                if isinstance(item, dict):
                    keys.update(item)
    missing = sorted(k for k in keys if not any(f"`{w}`" in text for w in (k, f"[{k}]", f"[[{k}]]")))
    assert missing == []
