"""A flight against its Monte Carlo envelope (issue 43, part 3; taos.montecarlo.envelope):
percentile envelopes of the stored actuator command and engine angle over time, a record overlaid,
the fraction of time outside."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from taos.errors import InputError
from taos.flight.pti_record import FlightRecord
from taos.montecarlo import load_campaign, open_store, run_campaign
from taos.montecarlo.envelope import compare_to_envelope, envelope

SHORT = Path(__file__).resolve().parent / "data" / "mc_short.toml"


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("mce") / "short"
    run_campaign(load_campaign(SHORT), out, runs=8, workers=0)
    return out


def test_envelope_percentiles_and_the_fraction_outside(campaign, tmp_path):
    """The envelope is numpy's percentile of the ok runs' stored command at each time; a record on
    the median is never outside, one far above always is, and a stored run's own trace is outside
    exactly where it lies beyond the 5-95 % band (counted by hand)."""
    env = envelope(campaign, "command", (5, 50, 95))
    ds = open_store(campaign / "campaign.zarr", dask=False)
    ok = np.asarray(ds["status"].values) == 1
    tr = np.asarray(ds["trace"].values)[ok]
    assert env.runs_ok == ok.sum() >= 2 and env.axis == "yaw"
    assert np.array_equal(env.bands_rad[1], np.percentile(tr, 50, axis=0))
    assert np.all(env.bands_rad[0] <= env.bands_rad[1]) and np.all(env.bands_rad[1] <= env.bands_rad[2])
    t = env.t_s
    assert compare_to_envelope((t, env.band(50)), env).fraction_outside == 0.0
    up = compare_to_envelope((t, env.band(95) + 1e-3), env)
    assert up.fraction_outside == up.fraction_above == 1.0 and up.fraction_below == 0.0
    x = tr[0]
    rec = FlightRecord(t, ("yaw",), {"command_rad": x[None, :]}, source="run 0")
    c = compare_to_envelope(rec, env)
    by_hand = np.mean((x < env.bands_rad[0]) | (x > env.bands_rad[2]))
    assert c.fraction_outside == pytest.approx(by_hand) and c.t_s.size == t.size
    half = compare_to_envelope((t[: t.size // 2], x[: t.size // 2]), env)   # only the overlap counts
    assert half.t_s.size == t.size // 2
    d = c.to_dict()
    assert d["expected_fraction_outside_if_from_the_campaign"] == pytest.approx(0.10)
    json.dumps(env.to_dict(), allow_nan=False)
    from taos.plotting import save
    from taos.plotting.envelope import plot_envelope
    save(plot_envelope(env, c), tmp_path / "env.png")
    assert (tmp_path / "env.png").stat().st_size > 0


def test_bad_envelope_requests_are_named(campaign, tmp_path):
    with pytest.raises(InputError, match="the stored traces"):
        envelope(campaign, "attitude")
    for bad in ((50,), (95, 5), (0, 50), (5, True), "5,95"):
        with pytest.raises(InputError):
            envelope(campaign, "command", bad)
    with pytest.raises(InputError):
        envelope(tmp_path / "nothing")
    env = envelope(campaign)
    with pytest.raises(InputError):   # no overlap with the campaign's 120-160 s
        compare_to_envelope((np.array([0.0, 10.0]), np.zeros(2)), env)
    with pytest.raises(InputError):   # not the campaign's axis
        compare_to_envelope(FlightRecord(env.t_s, ("pitch",), {"command_rad": env.bands_rad[1][None]}), env)


def test_engine_angle_envelope_from_the_stored_engine_trace(campaign):
    """The campaign stores each run's engine angle beside its command at the trace times: run 0
    flown again on its own (its factors and seed, simulate_ascents) gives the stored trace; the
    engine envelope is numpy's percentile of the ok runs' engine traces, and a record of a stored
    run's engine angle is outside exactly where it lies beyond the 5-95 % band."""
    from taos.flight.ascent_sim import simulate_ascents
    from taos.montecarlo.campaign import apply_factors, base_models

    c = load_campaign(SHORT)
    ds = open_store(campaign / "campaign.zarr", dask=False)
    ok = np.asarray(ds["status"].values) == 1
    eng = np.asarray(ds["engine_trace"].values)
    t = np.asarray(ds["time"].values)
    i = int(np.flatnonzero(ok)[0])
    asc, m = base_models(c)
    fac = dict(zip([str(n) for n in ds["parameter"].values], map(float, ds["factor"].values[i])))
    a2, m2, _ = apply_factors(asc, m, c.cases[c.default_case], fac)
    h = simulate_ascents([(a2, m2, int(ds["seed"].values[i]))], axis="yaw", start_s=c.start_s,
                         end_s=c.start_s + c.duration_s, dt_s=c.dt_s, record_interval_s=0.02)[0]
    again = np.interp(t, h.t_s, h.signal("engine_rad", "yaw"))
    assert np.allclose(eng[i], again, rtol=0, atol=1e-12 + 1e-9 * np.abs(again).max())
    env = envelope(campaign, "engine")
    assert env.quantity == "engine" and env.runs_ok == ok.sum() and np.array_equal(env.t_s, t)
    assert np.array_equal(env.bands_rad, np.percentile(eng[ok], (5, 50, 95), axis=0))
    x = eng[i]
    rec = FlightRecord(t, ("yaw",), {"command_rad": np.zeros((1, t.size)), "engine_rad": x[None, :]}, source="run")
    cmp = compare_to_envelope(rec, env)
    assert cmp.quantity == "engine" and cmp.to_dict()["quantity"] == "engine"
    assert cmp.fraction_outside == pytest.approx(np.mean((x < env.bands_rad[0]) | (x > env.bands_rad[2])))
    from taos.montecarlo.envelope import record_against_campaign
    both = record_against_campaign(rec, campaign)
    assert set(both) == {"command", "engine"} and both["engine"][1].fraction_outside == cmp.fraction_outside
    assert both["command"][1].quantity == "command"
    no_engine = FlightRecord(t, ("yaw",), {"command_rad": x[None, :]}, source="telemetry")
    e, c_, why = record_against_campaign(no_engine, campaign)["engine"]
    assert e is not None and c_ is None and "engine" in why


def test_a_store_without_the_engine_trace(campaign, tmp_path):
    """A store written before the engine angle was stored: its engine envelope is refused with one
    line naming the variable; the command envelope still reads, and the engine is reported as not
    compared."""
    from taos.montecarlo.envelope import record_against_campaign

    old = tmp_path / "old"
    shutil.copytree(campaign, old)
    shutil.rmtree(old / "campaign.zarr" / "engine_trace")
    (old / "campaign.zarr" / ".zmetadata").unlink(missing_ok=True)
    with pytest.raises(InputError, match="engine_trace.*run the campaign again") as e:
        envelope(old, "engine")
    assert "\n" not in str(e.value)
    env = envelope(old)
    res = record_against_campaign((env.t_s, env.band(50)), old)
    assert res["command"][1].fraction_outside == 0.0 and res["engine"][:2] == (None, None)


def test_taos_pti_envelope_option(campaign, tmp_path):
    """``taos pti RECORD --envelope CAMPAIGN_DIR``: the record's command against the campaign's
    envelope in pti.json and envelope.png; a folder that is no campaign: exit 2, nothing written."""
    from taos.cli import main
    from taos.flight.ascent import load_ascent
    from taos.flight.ascent_sim import simulate_ascent
    from taos.flight.lco import with_bounding_avionics
    from taos.model import load_model

    asc = load_ascent("ascent")
    m = with_bounding_avionics(load_model(asc.tvc_model, friction="dahl"))
    h = simulate_ascent(asc, m, axes=("yaw",), start_s=120.0, end_s=215.0, dt_s=1e-3)
    h.to_hdf5(tmp_path / "rec.h5")
    out = tmp_path / "o"
    assert main(["pti", str(tmp_path / "rec.h5"), "--flight", "ascent", "--no-df", "--envelope", str(campaign),
                 "--out", str(out)]) == 0
    d = json.loads((out / "pti.json").read_text())["envelope"]
    for q in ("command", "engine"):   # both, each with its fraction of time outside
        assert d[q]["quantity"] == q and 0.0 <= d[q]["fraction_outside"] <= 1.0
        assert d[q]["samples"] == envelope(campaign, q).t_s.size
    assert d["campaign"]["campaign_dir"] == str(campaign)
    assert (out / "envelope.png").exists()
    bad = tmp_path / "b"
    assert main(["pti", str(tmp_path / "rec.h5"), "--flight", "ascent", "--no-df", "--envelope",
                 str(tmp_path / "none"), "--out", str(bad)]) == 2
    assert not bad.exists()
