"""Flight sign-off (issue 29 point 6): ``taos lco ... --requirements FILE [--signoff DIR]`` checks
stated limits over the nominal case or a ``--sweep`` grid and writes the pass/fail table with the
margin to each limit (JSON and a page), labelled notional where the requirements are.

References: the low-frequency gain margin and the phase margin are checked against the margin
table of ``taos lco`` (crossings located by :func:`taos.stability.loop_margins`, another
locator than the sign-off's own); the LCO amplitude and frequency against the describing-
function prediction; every margin against its definition (value - limit, limit - value, band)."""

from __future__ import annotations

import json
import math

import pytest

from tests.conftest import MODELS, run_cli
from tests.inprocess import taos_json

REQ = MODELS / "specs" / "flight_signoff_notional.toml"
GRID = ("--amplitudes-deg", "0.03,0.1,0.3", "--freq-hz", "0.05,0.08,0.12,0.18,0.27,0.4")
LCO = ("lco", "rs25_flight", "--flight", "core_stage", *GRID, "--no-time-domain")


@pytest.fixture(scope="module")
def nominal(tmp_path_factory):
    """The plain ``taos lco`` JSON (its figures are the reference: run in this process,
    :mod:`tests.inprocess`) and the sign-off run by the console script (its printed verdict is
    checked), with its JSON, folder and completed process."""
    tmp = tmp_path_factory.mktemp("signoff")
    lco = taos_json(tmp / "lco.json", *LCO)
    r2 = run_cli(*LCO, "--requirements", REQ, "--signoff", tmp / "so", "--json", tmp / "so.json")
    assert r2.returncode == 0, r2.stderr
    return lco, json.loads((tmp / "so.json").read_text()), tmp / "so", r2


def _checks(case) -> dict:
    return {c["requirement"]: c for c in case["checks"]}


@pytest.mark.slow
def test_nominal_signoff_values_agree_with_the_lco_margin_table(nominal):
    lco, so, _, r = nominal
    s = so["signoff"]
    assert s["notional"] is True and s["requirements"]["notional"] is True
    (case,) = s["cases"]
    ck = _checks(case)
    table = {round(x["amplitude_deg"], 6): x for x in lco["verdict"]["margin_table"]}
    big = table[0.3]                               # margin_amplitude_min = 0.3 deg: only 0.3 deg counts
    assert ck["low-frequency gain margin"]["value"] == pytest.approx(big["low_gain_margin_db"], abs=0.02)
    assert ck["phase margin"]["value"] == pytest.approx(big["phase_margin_deg"], abs=0.1)
    assert lco["lco"] is True
    assert ck["LCO engine amplitude"]["value"] == pytest.approx(lco["engine_amplitude_deg"], rel=1e-9)
    assert ck["LCO frequency band"]["value"] == pytest.approx(lco["frequency_hz"], rel=1e-9)
    # the margin to each limit, by definition
    req = s["requirements"]
    assert ck["low-frequency gain margin"]["margin"] == pytest.approx(ck["low-frequency gain margin"]["value"]
                                                                       - req["low_gain_margin_min_db"])
    assert ck["phase margin"]["margin"] == pytest.approx(ck["phase margin"]["value"] - req["phase_margin_min_deg"])
    assert ck["LCO engine amplitude"]["margin"] == pytest.approx(req["lco_engine_amplitude_max_deg"]
                                                                  - ck["LCO engine amplitude"]["value"])
    lo, hi = req["lco_frequency_band_hz"]
    f = ck["LCO frequency band"]["value"]
    assert ck["LCO frequency band"]["margin"] == pytest.approx(min(f - lo, hi - f))
    assert all(c["pass"] == (c["margin"] is None or c["margin"] >= 0) for c in case["checks"])
    assert s["pass"] is case["pass"] is all(c["pass"] for c in case["checks"])
    # the verdict in words first, then the table
    lines = r.stdout.splitlines()
    assert lines[0].startswith("flight sign-off against NOTIONAL requirements") and "PASS" in lines[0]
    assert lines[1].split()[:2] == ["case", "requirement"]


@pytest.mark.slow
def test_signoff_folder_holds_the_json_and_a_page_that_works_offline(nominal):
    _, so, folder, _ = nominal
    assert sorted(p.name for p in folder.iterdir() if not p.name.startswith(".")) == ["signoff.html", "signoff.json"]
    assert json.loads((folder / "signoff.json").read_text())["signoff"]["cases"] == so["signoff"]["cases"]
    page = (folder / "signoff.html").read_text()
    assert page.index('id="signoff-verdict"') < page.index('id="signoff-table"') < page.index('id="nichols"')
    assert "NOTIONAL requirements" in page and "<script src" not in page.lower()
    assert page.count("<tr class='pass'>") + page.count("<tr class='fail'>") == 4


@pytest.mark.slow
def test_signoff_over_dispersions_fails_the_soft_load_path_and_passes_the_stiff_one(tmp_path):
    s = taos_json(tmp_path / "so.json", *LCO, "--requirements", REQ, "--sweep",
                  "load_stiffness=60000 lbf/in,205000 lbf/in")["signoff"]
    soft, stiff = s["cases"]
    assert soft["parameters"]["load_stiffness_N_per_m"] == pytest.approx(60000 * 4.4482216152605 / 0.0254)
    assert not soft["pass"] and stiff["pass"] and s["pass"] is False
    ck = _checks(soft)
    # the soft load path: the loop lacks low-frequency gain even at the map's largest amplitude
    assert ck["low-frequency gain margin"]["value"] < 0 and ck["phase margin"]["value"] < 0
    assert not ck["LCO engine amplitude"]["pass"]   # the map, extended past its largest amplitude, finds the cycle
    assert "FAIL in 1 of 2 case(s)" in s["text"]


@pytest.mark.slow
def test_signed_low_frequency_margin_is_negative_where_the_loop_lacks_gain():
    """At 0.03 deg friction takes enough gain that the conditionally stable crossing has |L| < 1:
    the signed margin is minus the (upward) gain margin that loop_margins finds at that crossing."""
    from taos.flight.lco import analyse_lco
    from taos.flight.signoff import low_frequency_crossing_hz, signed_low_gain_margin
    from taos.flight.vehicle import load_flight
    from taos.model import load_model

    rep = analyse_lco(load_flight(MODELS / "flight" / "core_stage.toml"), load_model(MODELS / "rs25_flight.toml"),
                      amplitudes_rad=[math.radians(a) for a in (0.03, 0.1, 0.3)],
                      freq_hz=[0.05, 0.08, 0.12, 0.18, 0.27, 0.4], time_domain=False)
    pred = rep.prediction
    f0 = low_frequency_crossing_hz(pred)
    g, fx = signed_low_gain_margin(pred, math.radians(0.03), f0)
    lm = pred.margins_at(math.radians(0.03)).crossings
    k = min(range(len(lm.phase_crossover_hz)), key=lambda i: abs(math.log10(lm.phase_crossover_hz[i] / f0)))
    assert g < 0
    assert g == pytest.approx(-lm.gain_margin_db[k], abs=0.02) and fx == pytest.approx(lm.phase_crossover_hz[k], rel=2e-3)


def test_bad_requirements_and_options_stop_before_any_work(tmp_path):
    bad = tmp_path / "req.toml"
    bad.write_text('name = "x"\n[limits]\nphase_margn_min = "30 deg"\n')
    r = run_cli(*LCO, "--requirements", bad)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "phase_margin_min" in r.stderr
    bad.write_text('[limits]\nlco_frequency_band = ["1 Hz", "0.1 Hz"]\n')
    r = run_cli(*LCO, "--requirements", bad)
    assert r.returncode == 2 and "low < high" in r.stderr
    r = run_cli(*LCO, "--signoff", tmp_path / "so")
    assert r.returncode == 2 and "--requirements" in r.stderr
    (tmp_path / "afile").write_text("mine")
    r = run_cli(*LCO, "--requirements", REQ, "--signoff", tmp_path / "afile")
    assert r.returncode == 2 and (tmp_path / "afile").read_text() == "mine"
    assert "sign-off" not in r.stderr          # refused before the analysis started (no progress bar)
    r = run_cli(*LCO, "--requirements", REQ, "--plot", tmp_path / "n.png")
    assert r.returncode == 2 and "--plot" in r.stderr and not (tmp_path / "n.png").exists()


@pytest.mark.slow
def test_a_loop_unstable_at_the_largest_amplitude_is_not_called_cycle_free(tmp_path):
    """Soft load path (60000 lbf/in): on a map up to 0.3 deg the loop with the TVC is unstable at
    every amplitude, so the verdict says the motion grows beyond the map (it used to read "no
    limit cycle expected"); the map extended to 3 deg finds the cycle above 0.3 deg, and the
    time-domain run (another method) oscillates near it."""
    soft = ("--load-stiffness", "60000 lbf/in")
    m = taos_json(tmp_path / "map.json", *LCO, *soft)   # the map is extended past 0.3 deg by itself (issue 40)
    assert m["verdict"]["kind"] == "limit-cycle" and m["amplitude_deg"] > 0.3
    d = taos_json(tmp_path / "extended.json", "lco", "rs25_flight", "--flight", "core_stage",
                  "--amplitudes-deg", "0.03,0.1,0.3,1,3", "--freq-hz", GRID[3], "--duration", "100", *soft)
    assert d["verdict"]["kind"] == "limit-cycle" and d["amplitude_deg"] > 0.3
    td = d["time_domain"]
    assert td["lco"] and td["amplitude_deg"] == pytest.approx(d["amplitude_deg"], rel=0.25)
    assert td["frequency_hz"] == pytest.approx(d["frequency_hz"], rel=0.1)
