"""Mixed test records (issue 29, point 1): excitation classified per axis and per segment, a
record with pitch dwells and a yaw sweep estimated in one call (``taos estimate --axis both``,
``--axis pitch``) and used by ``taos greenrun --data``; bad input in one line with exit 2."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from taos.identify.segments import segment_command
from taos.profiles import Sequence, SineDwell, SineSweep

from . import _records
from .conftest import MODELS, run_cli

DEG = math.pi / 180


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    return _records.mixed_record(tmp_path_factory.mktemp("mixed") / "mixed.csv")


def _spans(segs):
    return [(s.kind, round(s.t0_s, 2), round(s.t1_s, 2)) for s in segs]


def test_segments_of_a_command_with_every_kind_at_their_known_times():
    """A command built from known pieces: quiet 1 s, a 0.5 deg step held 1 s, a ramp back to zero
    over 0.5 s, quiet 1 s, a 2 Hz dwell of 8 cycles, a 1 -> 10 Hz log sweep over 10 s, quiet 2 s.
    Each piece comes back with its kind and its span (to a few samples; a dwell's ramp-in cycle
    within a period)."""
    fs = 500.0
    t = np.arange(0, 19.5, 1 / fs)
    u = np.interp(t, [0, 1.0 - 1e-9, 1.0, 2.0, 2.5, 3.5], [0, 0, 0.5 * DEG, 0.5 * DEG, 0, 0])
    osc = Sequence((SineDwell(0.4 * DEG, 2.0, 8), SineSweep(0.4 * DEG, 1.0, 10.0, 10.0)))
    u = np.where(t >= 3.5, osc(t - 3.5), u)
    segs = segment_command(t, u, "yaw")
    kinds = [s.kind for s in segs]
    assert kinds == ["quiet", "step/ramp", "quiet", "step/ramp", "quiet", "dwell", "sweep", "quiet"], _spans(segs)
    q0, step, hold, ramp, q1, dwell, sweep, q2 = segs
    tol = 3 / fs
    assert q0.t0_s == 0.0 and q0.t1_s == pytest.approx(1.0, abs=tol)
    assert step.t0_s == pytest.approx(1.0, abs=tol) and math.degrees(step.amplitude_rad) == pytest.approx(0.5)
    assert math.degrees(hold.amplitude_rad) == pytest.approx(0.5)            # held at the step's level
    assert ramp.t0_s == pytest.approx(2.0, abs=tol) and ramp.t1_s == pytest.approx(2.5, abs=tol)
    assert q1.t0_s == pytest.approx(2.5, abs=tol) and q1.t1_s == pytest.approx(3.5, abs=tol)
    assert dwell.t0_s == pytest.approx(3.5, abs=tol) and dwell.t1_s == pytest.approx(7.5, abs=tol)
    assert dwell.freq_range_hz[0] == pytest.approx(2.0, rel=1e-3) and dwell.dwell.cycles >= 7
    assert sweep.t0_s == pytest.approx(7.5, abs=tol) and sweep.t1_s == pytest.approx(17.5, abs=tol)
    assert 1.0 <= sweep.freq_range_hz[0] < 1.5 and 9.0 < sweep.freq_range_hz[1] <= 10.0
    assert "logarithmic" in sweep.reason and [s.index for s in segs] == list(range(8))
    assert q2.t0_s == pytest.approx(17.5, abs=tol) and q2.t1_s == pytest.approx(t[-1])


def test_mixed_record_estimated_in_one_call_with_segments_reported(mixed, tmp_path):
    out = tmp_path / "est.json"
    r = run_cli("estimate", mixed, "--axis", "both", "--model", MODELS / "rs25_hotfire.toml", "--json", out)
    assert r.returncode == 0, r.stderr
    d = json.loads(out.read_text())
    segs = d["segments"]
    pitch = [s for s in segs if s["axis"] == "pitch"]
    yaw = [s for s in segs if s["axis"] == "yaw"]
    # pitch: the five dwells of the profile back to back, then quiet while yaw still sweeps
    t_end = 0.0
    for s, (f, c, a) in zip(pitch, _records.PITCH_DWELLS):
        assert s["kind"] == "dwell" and s["used"] and s["freq_range_hz"][0] == pytest.approx(f, rel=1e-3)
        assert s["t0_s"] == pytest.approx(t_end, abs=0.01) and s["t1_s"] == pytest.approx(t_end + c / f, abs=0.01)
        assert s["amplitude_deg"] == pytest.approx(a, rel=0.01)
        t_end += c / f
    assert pitch[-1]["kind"] == "quiet" and not pitch[-1]["used"] and len(pitch) == 6
    a, f0, f1, T = _records.YAW_SWEEP
    q = _records.YAW_QUIET_S
    assert [s["kind"] for s in yaw] == ["quiet", "sweep", "quiet"]
    assert yaw[1]["t0_s"] == pytest.approx(q, abs=0.01) and yaw[1]["t1_s"] == pytest.approx(q + T, abs=0.01)
    assert f0 <= yaw[1]["freq_range_hz"][0] < 0.8 and 13.0 < yaw[1]["freq_range_hz"][1] <= f1
    assert yaw[1]["amplitude_deg"] == pytest.approx(a, rel=0.03)
    rp, ry = d["responses"]
    assert (rp["axis"], rp["method"], ry["axis"], ry["method"]) == ("pitch", "sine-dwell", "yaw", "h1")
    assert rp["freq_hz"] == pytest.approx([f for f, _, _ in _records.PITCH_DWELLS], rel=1e-3)
    assert set(rp["point_segment"]) == {0, 1, 2, 3, 4} and set(ry["point_segment"]) == {1}
    assert rp["excitation"]["kind"] == "dwell" and ry["excitation"]["kind"] == "sweep"
    assert len(ry["freq_hz"]) > 15
    # two estimators on two excitations of identical axes agree below the notch: the pitch
    # dwells against the yaw sweep's H1 interpolated at the dwell frequencies
    for f in (1.0, 2.0, 4.0):
        gp = np.interp(f, rp["freq_hz"], rp["piston"]["gain_db"])
        gy = np.interp(f, ry["freq_hz"], ry["piston"]["gain_db"])
        pp = np.interp(f, rp["freq_hz"], rp["piston"]["phase_deg"])
        py = np.interp(f, ry["freq_hz"], ry["piston"]["phase_deg"])
        assert abs(gp - gy) < 0.5 and abs(pp - py) < 4.0, (f, gp, gy, pp, py)
    # the text report names each segment, axis, kind and span
    r = run_cli("estimate", mixed)
    assert r.returncode == 0, r.stderr
    row = r"^yaw +1 sweep +2\.0\d +22\.0\d +0\.7\d*-1[34]\.\d +0\.4\d* +yes$"
    assert re.search(row, r.stdout, re.M), r.stdout[:900]
    assert re.search(r"^pitch +5 quiet +2[01]\.\d\d +2[23]\.\d\d .* no$", r.stdout, re.M)


@pytest.mark.parametrize("axis, method", [("pitch", "sine-dwell"), ("yaw", "h1")])
def test_one_axis_of_a_mixed_record(mixed, axis, method):
    r = run_cli("estimate", mixed, "--axis", axis, "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert [x["axis"] for x in d["responses"]] == [axis] and d["responses"][0]["method"] == method
    assert {s["axis"] for s in d["segments"] if s["used"]} == {axis}


@pytest.mark.slow
def test_greenrun_uses_a_mixed_record(mixed, tmp_path):
    out = tmp_path / "gr"
    r = run_cli("greenrun", MODELS / "rs25_hotfire.toml", "--data", mixed, "--out", out, "--quiet")
    assert r.returncode == 0, r.stderr
    s = json.loads((out / "summary.json").read_text())["test_data"]["axes"]
    assert s["pitch"]["excitation"]["kind"] == "dwell" and s["yaw"]["excitation"]["kind"] == "sweep"
    assert [g["kind"] for g in s["yaw"]["excitation"]["segments"]] == ["quiet", "sweep", "quiet"]
    html = (out / "index.html").read_text()
    assert re.search(r"yaw: sweep \(instantaneous frequency rises .*\(#1, 2\.0\d-22\.0\d s; also #0 quiet", html)
    assert re.search(r"pitch: dwell \(6 segments \(5 dwell, 1 quiet\): #0 dwell 0\.00-6\.0\d s", html)


@pytest.mark.slow
def test_fit_of_a_mixed_record_recovers_the_hardware(mixed, tmp_path):
    """Pitch dwells and the yaw sweep's H1 points fitted together give back the hot-fire model's
    K_L (205,000 lbf/in) and Coulomb torque (117,525 in-lbf) within 3 standard errors."""
    out = tmp_path / "fit.json"
    r = run_cli("fit", mixed, "--model", MODELS / "rs25_hotfire.toml", "--free", "load_stiffness,coulomb_torque",
                "--starts", "1", "--json", out)
    assert r.returncode == 0, r.stderr
    d = json.loads(out.read_text())
    assert {(x["axis"], x["method"]) for x in d["data"]} == {("pitch", "sine-dwell"), ("yaw", "h1")}
    for name, true in (("load_stiffness", 205000.0), ("coulomb_torque", 117525.0)):
        p = d["parameters"][name]
        assert abs(p["value"] - true) < 3 * p["std_error"] and p["std_error"] < 0.005 * true, (name, p)


def _one_line(r):
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("taos:") and "Traceback" not in r.stderr, r.stderr
    return lines[0]


def test_an_axis_with_nothing_to_estimate_is_refused_in_one_line(tmp_path):
    """Pitch holds a step only (nothing with a frequency response), yaw dwells: --axis pitch and
    both refuse naming the pitch segments; --axis yaw works."""
    fs = 250.0
    t = np.arange(0, 12, 1 / fs)
    up = np.where(t > 3.0, 0.3, 0.0)
    uy = 0.4 * np.sin(2 * np.pi * 2.0 * t)
    rows = "\n".join(f"{a:.6f},{b:.6f},{0.01 * b:.6f},{c:.6f},{0.01 * c:.6f}" for a, b, c in zip(t, up, uy))
    p = tmp_path / "step_and_dwell.csv"
    p.write_text("time [s],pitch_command [deg],pitch_piston [in],yaw_command [deg],yaw_piston [in]\n" + rows + "\n")
    for axis in ("pitch", "both"):
        line = _one_line(run_cli("estimate", p, "--axis", axis))
        assert "pitch_command" in line and "(#1 step/ramp 3.00-3.0" in line and "force --method" in line
    r = run_cli("estimate", p, "--axis", "yaw", "--json", "-")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["responses"][0]["freq_hz"] == pytest.approx([2.0], rel=1e-3)


def test_series_bad_input_one_line_exit_2_and_nothing_written(mixed, tmp_path):
    out = tmp_path / "series"
    hot = MODELS / "rs25_hotfire.toml"
    assert "2 to 50 record files" in _one_line(run_cli("compare", "--model", hot, "--records", mixed, "--out", out))
    assert "not both" in _one_line(run_cli("compare", hot, hot, "--model", hot, "--records", mixed, mixed,
                                           "--out", out))
    assert "--model" in _one_line(run_cli("compare", "--records", mixed, mixed, "--out", out))
    assert "two models" in _one_line(run_cli("compare", hot, "--out", out))
    assert "--labels" in _one_line(run_cli("compare", "--model", hot, "--records", mixed, mixed, "--labels", "a",
                                           "--out", out))
    bad = tmp_path / "bad.csv"
    body = "".join(x for x in mixed.read_text().splitlines(keepends=True) if not x.startswith("#"))
    bad.write_text("# test_date = \"last tuesday\"\n" + body)
    assert "test_date" in _one_line(run_cli("compare", "--model", hot, "--records", mixed, bad, "--out", out))
    rev = tmp_path / "reversed.csv"
    rev.write_text("time [s],pitch_command [deg],pitch_piston [in]\n" +
                   "\n".join(f"{1 - 0.01 * i},{i % 3},{i % 3}" for i in range(40)) + "\n")
    assert "strictly increasing time" in _one_line(run_cli("compare", "--model", hot, "--records", mixed, rev,
                                                           "--out", out))
    assert not out.exists()
