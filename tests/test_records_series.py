"""A series of test records compared (issue 29, point 1): ``taos compare --model MODEL --records
R1 R2 ...`` fits every record and recovers a known drift of the load stiffness K_L and the
friction level made by the simulator, within the standard errors; the trend line against
numpy's weighted polynomial fit."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from taos.identify.series import weighted_line

from . import _records
from .conftest import MODELS
from .inprocess import taos_main


def test_weighted_line_matches_numpy_weighted_polyfit():
    rng = np.random.default_rng(1)
    x = np.array([0.0, 7.0, 14.0, 21.0, 30.0])
    s = rng.uniform(0.5, 2.0, x.size)
    y = 3.0 - 0.4 * x + s * rng.standard_normal(x.size)
    t = weighted_line(x, y, s)
    c, cov = np.polyfit(x, y, 1, w=1 / s, cov="unscaled")
    assert (t.slope, t.intercept) == (pytest.approx(c[0], rel=1e-10), pytest.approx(c[1], rel=1e-10))
    assert t.slope_std_error == pytest.approx(math.sqrt(cov[0, 0]), rel=1e-10)
    assert t.chi2 == pytest.approx(np.sum(((y - np.polyval(c, x)) / s) ** 2), rel=1e-10) and t.dof == 3


@pytest.mark.slow
def test_series_recovers_the_known_drift_of_K_L_friction_and_notch(tmp_path):
    from taos.model import load_model
    from tests._records import with_drift

    recs = _records.series_records(tmp_path)           # newest first: the test dates must order them
    out = tmp_path / "series"
    js = tmp_path / "series.json"
    # the command's files, made in this process (tests.inprocess)
    assert taos_main("compare", "--model", MODELS / "rs25_hotfire.toml", "--records", *recs, "--out", out,
                     "--json", js) == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "responses_overlay.png", "series.json", "series_table.txt", "trend.png"]
    d = json.loads(js.read_text())
    assert d == json.loads((out / "series.json").read_text())
    assert d["x_axis"].startswith("days since 2026-03-02")
    assert [x["test_date"] for x in d["records"]] == [s[0] for s in _records.SERIES]
    assert [x["x"] for x in d["records"]] == [0.0, 7.0, 14.0, 21.0]
    base = load_model(MODELS / "rs25_hotfire.toml")
    for rec, (_, kl, tc) in zip(d["records"], _records.SERIES):
        q = rec["quantities"]
        assert rec["adequacy"]["verdict"] == "adequate"
        for name, true in (("load_stiffness", kl), ("coulomb_torque", tc)):
            v, se = q[name]["value"], q[name]["std_error"]
            assert 0 < se < 0.01 * true and abs(v - true) < 3.5 * se, (rec["label"], name, v, true, se)
        # the notch against the load resonance of the true hardware, paper eq. 1 (the damped
        # zero sits ~1e-4 w_L from it: tests/test_compare.py)
        true_notch = with_drift(base, kl, tc).load_resonance_hz("pitch")
        v, se = q["notch_pitch_hz"]["value"], q["notch_pitch_hz"]["std_error"]
        assert abs(v - true_notch) < 3.5 * se + 3e-4 * true_notch, (v, true_notch, se)
    days = 7.0
    for name, true_slope in (("load_stiffness", -6000.0 / days), ("coulomb_torque", 4000.0 / days)):
        t = d["trends"][name]
        assert abs(t["slope"] - true_slope) < 3.5 * t["slope_std_error"], (name, t, true_slope)
        assert t["slope_std_error"] < 0.05 * abs(true_slope)
    table = (out / "series_table.txt").read_text()
    assert "load_stiffness" in table and "trend per unit of x" in table and table.count("adequate") == 4


def test_order_by_test_date_only_when_every_record_has_one(tmp_path):
    """Dates (a TOML date, or ISO text with a time) order the series in days since the first test;
    one record without a date leaves the given order (x = 1, 2, ...)."""
    import datetime as dt

    from taos.identify.data import TestData, load_test_data
    from taos.identify.series import _order

    t = np.arange(64) / 100.0
    u = 0.01 * np.sin(2 * np.pi * 2 * t)[None]

    def rec(meta):
        return TestData("r.csv", t, ("pitch",), u, 0.01 * u, None, metadata=meta)

    # a date written by to_csv is read back as a TOML date
    p = tmp_path / "dated.csv"
    rec({"test_date": dt.date(2026, 3, 9)}).to_csv(p)
    assert "# test_date = 2026-03-09\n" in p.read_text()
    d = load_test_data(p)
    idx, x, dates, label = _order([rec({"test_date": "2026-03-12T12:00:00"}), d], ["a", "b"])
    assert (idx, x, label) == ([1, 0], [0.0, 3.5], "days since 2026-03-09 (test_date)")
    assert dates == ["2026-03-09", "2026-03-12T12:00:00"]
    idx, x, dates, label = _order([rec({"test_date": "2026-03-12"}), rec({})], ["a", "b"])
    assert (idx, x, dates, label) == ([0, 1], [1.0, 2.0], ["", ""], "record order")
