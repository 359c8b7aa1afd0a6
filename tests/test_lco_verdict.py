"""An LCO verdict a reviewer can sign (issue 17 point 6): plain words, the margin meant, margins
over amplitude, the vehicle motion of the cycle (describing function against the time-domain
run), and a Nichols chart with frequency marks and the exclusion zone."""

from __future__ import annotations

import json

import pytest

from .conftest import MODELS, run_cli
from .inprocess import taos_json

FLIGHT = MODELS / "flight" / "core_stage.toml"
GRID = ("--amplitudes-deg", "0.02,0.05,0.1,0.2,0.5", "--freq-hz", "0.05,0.08,0.12,0.2,0.3")


@pytest.mark.slow
def test_coulomb_soft_structure_verdict_in_plain_words_with_vehicle_motion(tmp_path):
    r = run_cli("lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--friction", "coulomb-switching", *GRID,
                "--duration", "60", "--json", tmp_path / "lco.json", "--plot", tmp_path / "n.svg")
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "lco.json").read_text())
    v = d["verdict"]
    print(v["text"])
    assert d["lco"] and d["margin_db"] is None            # no "margin 0.0" beside a cycle
    assert v["kind"] == "limit-cycle" and v["text"].startswith("limit cycle expected: ")
    assert "deg command" in v["text"] and "Hz, self-sustaining" in v["text"] and "vehicle attitude" in v["text"]
    assert [round(x["amplitude_deg"], 6) for x in v["margin_table"]] == [0.02, 0.05, 0.1, 0.2, 0.5]
    assert v["margin_table"][-1]["low_gain_margin_db"] > 1.0     # large commands: margin restored
    df, td = v["cycle_motion"]
    assert df["source"] == "describing function" and td["source"] == "time domain"
    # two methods agree on the vehicle motion of the cycle
    assert df["attitude_amplitude_deg"] == pytest.approx(td["attitude_amplitude_deg"], rel=0.3)
    assert df["attitude_rate_amplitude_deg_s"] == pytest.approx(td["attitude_rate_amplitude_deg_s"], rel=0.3)
    svg = (tmp_path / "n.svg").read_text()
    assert 'id="exclusion-zone' in svg and 'id="frequency-marks' in svg and "0.1 Hz" in svg
    assert "limit cycle expected" in r.stdout and "low GM" in r.stdout   # text beside the JSON file


@pytest.mark.slow
def test_no_cycle_states_which_margin_and_where(tmp_path):
    """(The JSON's figures and words are the subject: the command runs in this process,
    :mod:`tests.inprocess`.)"""
    d = taos_json(tmp_path / "lco.json", "lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--friction", "dahl",
                  "--load-stiffness", "205000 lbf/in", *GRID, "--no-time-domain")
    v = d["verdict"]
    print(v["text"])
    assert not d["lco"] and v["kind"] == "none"
    assert v["text"].startswith("no limit cycle expected: the loop gain would have to ")
    near = v["nearest_margin"]
    assert near["margin_db"] == pytest.approx(d["margin_db"], abs=0.3)
    assert 0.02 <= near["amplitude_deg"] <= 0.5 and 0.05 <= near["frequency_hz"] <= 0.3
    assert "over all command amplitudes" in v["margin_meaning"]
