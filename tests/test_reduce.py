"""``taos reduce`` (issue 39.4): the planar model whose friction reproduces the 3-D model's
low-frequency engine response, written as a model file that ``taos lco`` takes unchanged.

Acceptance: the reduced model's engine dwells within 0.5 dB / 5 deg of the 3-D model's over
0.1-2 Hz x 0.02-0.5 deg, for every shipped 3-D model (hot fire, modified LuGre; flight bounding,
plain LuGre, whose least-squares reduction was outside it between grid points until the
worst-point refinement). Here the reduction's own check grid is 3 x 3 (both axes) and the
acceptance is tested on ANOTHER 3 x 3 grid the reduction never saw, away from the fit and check
points where it can be (the edges 2 Hz and 0.5 deg kept); the full 9 x 9 figures are in
docs/guide/reduce.md and benchmarks/RESULTS.md. A reduction outside the tolerance is refused
(exit 4, one line naming the worst point, nothing written) unless --allow-outside."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests._shared import shared_dir
from tests.conftest import MODELS, run_cli
from tests.inprocess import taos_main

HOTFIRE = MODELS / "rs25_hotfire.toml"
RECORD = MODELS / "data" / "greenrun_hotfire_synthetic.csv"
FLIGHT = MODELS / "flight" / "core_stage.toml"
FLIGHT_MODEL = MODELS / "rs25_flight.toml"
#: the reduction's check grid here (the default is the 9 x 9 acceptance grid)
CHECK = ("--check-freq-hz", "0.15,0.7,2", "--check-amplitudes-deg", "0.03,0.15,0.5")
#: the acceptance grid of the test, apart from the fit and check grids
ACCEPT_F, ACCEPT_A = [0.12, 0.35, 1.4], [0.02, 0.07, 0.3]


def _reduce(d: Path) -> None:
    rc = taos_main("reduce", HOTFIRE, "--out", d / "planar.toml", "--records", RECORD, "--json", d / "reduce.json",
                   *CHECK)
    assert rc == 0


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    """``taos reduce`` of the shipped hot-fire 3-D model (default grid), in this process, once a
    session even when xdist splits this module over both workers (:mod:`tests._shared`)."""
    d = shared_dir(tmp_path_factory, "reduce", _reduce)
    return d / "planar.toml", json.loads((d / "reduce.json").read_text())


def test_reduced_model_meets_the_acceptance_tolerance(reduced):
    from taos.identify.reduce import TOLERANCE_DB, TOLERANCE_DEG, match_table
    from taos.model import load_model

    out, d = reduced
    assert d["within_tolerance"] and d["match"]["max_gain_error_db"] <= TOLERANCE_DB
    assert d["match"]["max_phase_error_deg"] <= TOLERANCE_DEG
    # the reduction is worth having: the unreduced planar model is outside the tolerance
    assert d["match_before"]["max_phase_error_deg"] > TOLERANCE_DEG
    c = d["check"]   # its own check grid, both axes
    assert c["max_gain_error_db"] <= TOLERANCE_DB and c["max_phase_error_deg"] <= TOLERANCE_DEG
    assert {p["axis"] for p in c["points"]} == {"pitch", "yaw"} and len(c["points"]) == 18
    r = d["refine"]   # the worst-point refinement does not make the worst point worse
    assert r["worst"] <= r["least_squares_worst"] + 1e-9 and r["nfev"] > 0
    m = match_table(HOTFIRE, load_model(out), ACCEPT_F, ACCEPT_A, ("pitch", "yaw"))
    assert m.max_gain_error_db <= TOLERANCE_DB, m.to_dict()
    assert m.max_phase_error_deg <= TOLERANCE_DEG, m.to_dict()
    g = d["greenrun"]["engine"]   # the Green Run dwell match it keeps (0.4 deg up to 7 Hz)
    assert g["max_gain_error_db"] <= 1.0 and g["max_phase_error_deg"] <= 5.0
    assert max(p["freq_hz"] for p in g["points"]) == 7.0 and g["points"][0]["amplitude_deg"] == 0.4


@pytest.mark.slow
def test_flight_model_plain_lugre_is_within_tolerance_after_the_worst_point_refinement():
    """rs25_flight (plain LuGre): least squares alone left 0.54-0.57 dB between grid points."""
    from taos.identify.reduce import (
        TOLERANCE_DB,
        TOLERANCE_DEG,
        match_table,
        reduce_to_planar,
    )
    from taos.taos3d import load_taos_model

    tm = load_taos_model(FLIGHT_MODEL)
    red = reduce_to_planar(tm, axes=("pitch",), check_freq_hz=[0.15, 0.7, 2.0], check_amplitudes_deg=[0.03, 0.15, 0.5])
    assert red.within_tolerance, red.summary_lines()
    assert red.refine["worst"] <= red.refine["least_squares_worst"] + 1e-9
    m = match_table(tm, red.model, ACCEPT_F, ACCEPT_A, ("pitch", "yaw"))
    assert m.max_gain_error_db <= TOLERANCE_DB and m.max_phase_error_deg <= TOLERANCE_DEG, m.to_dict()


def test_minimax_reaches_the_worst_point_optimum_least_squares_misses():
    """min_x max_i |r_i| of a line through four points (one off the line): least squares leaves
    a worst error of 0.4, the minimax (Chebyshev) line 1/3, equal errors of alternating sign at
    t = 0, 2, 3."""
    import numpy as np
    import scipy.optimize as so

    from taos.identify.minimax import minimax

    t, y = np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 0.0, 0.0, 1.0])
    fun = lambda x: x[0] + x[1] * t - y
    ls = so.least_squares(fun, [0.0, 0.0])
    mm = minimax(fun, ls.x, [-5.0, -5.0], [5.0, 5.0], step=1e-6, min_delta=1e-9, ftol=1e-9, max_nfev=60)
    assert np.max(np.abs(ls.fun)) == pytest.approx(0.4, rel=1e-6)
    assert mm.max_abs == pytest.approx(1.0 / 3.0, rel=1e-6)
    assert mm.x == pytest.approx([-1.0 / 3.0, 1.0 / 3.0], abs=1e-6)   # y = (t - 1) / 3


def test_reduction_outside_tolerance_is_refused_exit_4_unless_allowed(tmp_path):
    """Only the friction level free, one fit dwell: the check grid sees it outside -> exit 4,
    one line naming the worst point, nothing written; --allow-outside writes it, with a WARNING."""
    out = tmp_path / "p.toml"
    args = (FLIGHT_MODEL, "--out", out, "--free", "coulomb_torque", "--freq-hz", "0.5", "--amplitudes-deg", "0.1",
            "--check-freq-hz", "2", "--check-amplitudes-deg", "0.02")
    r = run_cli("reduce", *args)
    assert r.returncode == 4, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "NOT within" in r.stderr and " Hz: " in r.stderr, r.stderr
    assert not out.exists()
    r = run_cli("reduce", *args, "--allow-outside")
    assert r.returncode == 0, r.stderr
    assert "WARNING" in r.stderr and out.is_file() and "NOT within" in out.read_text()


def test_written_file_is_a_planar_model_naming_its_3d_source(reduced):
    from taos.model import load_model
    from taos.results import file_sha256

    out, d = reduced
    text = out.read_text()
    m = load_model(out)
    assert "gimbal" not in m.extra and "geometry" not in m.extra and "\n[gimbal]" not in text
    assert "parameter_set" not in dict(m.friction_table)   # the reduced friction is the file's own
    for key, row in d["free"].items():   # written exactly: the file loads back to the reduced values
        from taos.identify.reduce import key_value
        assert key_value(m, key) == pytest.approx(row["value_si"], rel=1e-12)
    src = load_model(HOTFIRE)
    assert m.structure == src.structure   # the load path: the simplex equivalent already
    head = text.split("\nname = ")[0]
    assert str(HOTFIRE.relative_to(MODELS.parent)) in head or str(HOTFIRE) in head
    assert src.sha256 in head and file_sha256(RECORD) in head
    p = d["provenance"]
    assert p["source_model_sha256"] == src.sha256 and p["records"][0]["sha256"] == file_sha256(RECORD)
    assert Path(p["source_model_file"]).resolve() == HOTFIRE.resolve()


def test_lco_takes_the_reduced_model_unchanged(reduced):
    out, _ = reduced
    r = run_cli("lco", out, "--flight", FLIGHT, "--no-time-domain", "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["verdict"]["text"]
    assert Path(d["provenance"]["model_file"]).resolve() == out.resolve()
    r = run_cli("info", out)
    assert r.returncode == 0, r.stderr


def test_bad_input_exits_2_with_one_line_and_writes_nothing(reduced, tmp_path):
    out, _ = reduced
    foreign = tmp_path / "mine.toml"
    foreign.write_text("# not taos's\n")
    cases = [
        (out, "--out", tmp_path / "a.toml"),                  # a planar model: nothing 3-D to reduce
        (HOTFIRE, "--out", HOTFIRE),                          # the input itself
        (HOTFIRE, "--out", foreign),                          # a file taos did not write
        (HOTFIRE, "--out", tmp_path / "a.txt"),               # not a model file name
        (HOTFIRE, "--out", tmp_path / "a.toml", "--free", "dahl_exponent"),
        (HOTFIRE, "--out", tmp_path / "a.toml", "--amplitudes-deg", "0.1,90"),
    ]
    for args in cases:
        r = run_cli("reduce", *args)
        assert r.returncode == 2, (args, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert foreign.read_text() == "# not taos's\n" and not (tmp_path / "a.toml").exists()


def test_fit_header_names_the_records_of_a_fit_result(tmp_path):
    from taos.identify.reduce_file import fit_header

    p = tmp_path / "fit.toml"
    p.write_text("# Model fitted by taos fit on 2026-01-01 00:00 UTC to rec.csv; values marked '# fitted' were "
                 "estimated.\n# RS-25 hot fire\nname = 'x'\n# fitted later\n")
    line = "Model fitted by taos fit on 2026-01-01 00:00 UTC to rec.csv; values marked '# fitted' were estimated."
    assert fit_header(p) == (line,)
    assert fit_header(tmp_path / "missing.toml") == ()
