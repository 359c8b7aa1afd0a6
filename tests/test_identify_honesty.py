"""Identification never hides a bad answer (issue 17, point 1): the excitation detector says
what it found and why and refuses when unsure; a log sweep made by the model is a sweep, not
a dwell; every fit reports its normalised residual, a chi-square adequacy verdict and any
parameter at a bound; a deliberately wrong model structure is flagged inadequate."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from taos.errors import InputError
from taos.identify.data import TestData, from_time_history
from taos.identify.estimation import choose_method, classify_excitation, detect_dwells, estimate

from .conftest import MODELS, ROOT, run_cli

DEG = math.pi / 180
HOTFIRE_DATA = ROOT / "models" / "data" / "greenrun_hotfire_synthetic.csv"


@pytest.fixture(scope="module")
def sweep_record(tmp_path_factory):
    """A 0.4 deg logarithmic sweep 0.5 -> 14 Hz over 30 s through the hot-fire model, as CSV."""
    from taos.model import load_model
    from taos.profiles import SineSweep
    from taos.planar.simulate import simulate

    th = simulate(load_model(MODELS / "rs25_hotfire.toml"), SineSweep(0.4 * DEG, 0.5, 14.0, 30.0))
    path = tmp_path_factory.mktemp("sweep") / "sweep.csv"
    from_time_history(th, engine_offset_rad=[0.01]).to_csv(path)
    return path


def test_model_made_log_sweep_is_detected_as_a_sweep_not_a_dwell(sweep_record):
    from taos.identify.data import load_test_data
    d = load_test_data(sweep_record)
    assert detect_dwells(d.t_s, d.command_rad[0]) == []          # no 8 Hz "dwell" in a sweep any more
    e = classify_excitation(d.t_s, d.command_rad[0])
    assert e.kind == "sweep" and e.method == "h1" and "logarithmic" in e.reason
    assert 0.5 <= e.freq_range_hz[0] < 0.8 and 13 < e.freq_range_hz[1] <= 14.1
    assert abs(math.degrees(e.amplitude_rad) - 0.4) < 0.01
    r = estimate(d)[0]
    assert r.method == "h1" and len(r) > 20
    assert np.allclose(np.degrees(r.amplitude_rad), 0.4, atol=0.01)   # the sweep's amplitude, not a bin's share
    p = run_cli("estimate", sweep_record)
    assert p.returncode == 0, p.stderr
    assert "pitch: sweep -- instantaneous frequency rises" in p.stdout


def test_a_sweeps_estimate_points_lie_in_its_excited_band(sweep_record):
    """Issue 40: the window's leakage put H1 points below a sweep's start (then a fit's bounds)."""
    from taos.identify.data import load_test_data
    from taos.identify.estimation import estimate_h1
    d = load_test_data(sweep_record)
    f0, f1 = classify_excitation(d.t_s, d.command_rad[0]).freq_range_hz
    assert estimate_h1(d, nperseg=4096)[0].freq_hz.min() < f0       # the leakage this guards against
    for r in (estimate(d)[0], estimate(d, "h1")[0], estimate(d, "h1", nperseg=4096)[0]):
        assert len(r) > 10 and f0 <= r.freq_hz.min() and r.freq_hz.max() <= f1, (r.freq_hz.min(), f0)
    with pytest.raises(InputError, match="excited band"):
        estimate_h1(d, band_hz=(3.0, 3.01))


def test_green_run_dwells_and_a_multisine_are_named_with_their_evidence():
    from taos.identify.data import load_test_data
    d = load_test_data(HOTFIRE_DATA)
    method, exc = choose_method(d)
    assert method == "dwell" and [e.kind for e in exc] == ["dwell", "dwell"]
    assert "7 constant-period segment(s) at 0.5, 1, 2, 4, 7, 10, 14 Hz" in exc[0].reason
    t = np.arange(0, 40, 1 / 200)
    u = 0.4 * DEG * sum(np.cos(2 * np.pi * f * t - math.pi * k * (k - 1) / 6)
                        for k, f in enumerate([0.5, 1.25, 2.5, 4.0, 6.25, 9.0], start=1)) / 4
    e = classify_excitation(t, u)
    assert e.kind == "multisine" and e.method == "h1" and "6 spectral lines" in e.reason


def test_unsure_classification_refuses_and_force_method_overrides():
    rng = np.random.default_rng(3)
    t = np.arange(0, 20, 1 / 200)
    u = 0.2 * DEG * np.convolve(rng.standard_normal(t.size), np.ones(15) / 15, "same")   # band-limited noise
    d = TestData("noise.csv", t, ("pitch",), u[None], (0.01 * u)[None], None)
    assert classify_excitation(t, u).kind == "unknown"
    with pytest.raises(InputError, match=r"pitch_command.*force --method.*unsure: not dwells"):
        estimate(d)
    assert estimate(d, method="h1")[0].meta["method_forced"] is True


@pytest.fixture(scope="module")
def wrong_inertia_model(tmp_path_factory):
    """The hot-fire model with the engine inertia held 1.5 x too large (a wrong structure)."""
    text = (MODELS / "rs25_hotfire.toml").read_text()
    import re
    out = []
    for line in text.splitlines():
        m = re.match(r'^(inertia_(pitch|yaw)\s*=\s*")([0-9.eE+-]+)(\s*[^"]*")(.*)$', line)
        out.append(f"{m.group(1)}{float(m.group(3)) * 1.5:g}{m.group(4)}" if m else line)
    p = tmp_path_factory.mktemp("wrong") / "hotfire_wrong_inertia.toml"
    p.write_text("\n".join(out) + "\n")
    return p


def test_fit_with_wrong_engine_inertia_is_flagged_inadequate_and_strict_exits_4(wrong_inertia_model, tmp_path):
    from taos.model import load_model
    assert load_model(wrong_inertia_model).engine.inertia_pitch_kgm2 == pytest.approx(
        1.5 * load_model(MODELS / "rs25_hotfire.toml").engine.inertia_pitch_kgm2)
    out = tmp_path / "fit.json"
    p = run_cli("fit", HOTFIRE_DATA, "--model", wrong_inertia_model, "--free", "load_stiffness,coulomb_torque",
                "--starts", "1", "--json", out, "--strict")
    assert p.returncode == 4, p.stderr
    assert "WARNING: model adequacy: INADEQUATE" in p.stderr
    a = json.loads(out.read_text())["adequacy"]
    print(a["message"])
    assert a["verdict"] == "inadequate" and a["normalised_residual_rms"] > 10 and a["p_value"] < 1e-6


def test_fit_with_the_right_model_is_not_inadequate_and_reports_bounds(tmp_path):
    out = tmp_path / "fit.json"
    p = run_cli("fit", HOTFIRE_DATA, "--model", MODELS / "rs25_hotfire.toml", "--free",
                "load_stiffness,coulomb_torque", "--starts", "1", "--json", out)
    assert p.returncode == 0, p.stderr
    d = json.loads(out.read_text())
    a = d["adequacy"]
    print(a["message"])
    assert a["verdict"] in ("adequate", "marginal") and a["normalised_residual_rms"] < 2 and not a["at_bound"]
    ks = d["parameters"]["load_stiffness"]
    # physical bounds (taos.identify.physbounds), not multiples of the start: the upper puts the load
    # resonance sqrt((K_L R^2 + K_n) / J) at twice the record's top frequency (14 Hz), here from the
    # model file's public/notional R, K_n, J (0.8 m, 5e5 N m/rad, 12396 kg m^2)
    k_hi = ((2 * math.pi * 28.0) ** 2 * 12396 - 5e5) / 0.8 ** 2 / (4.4482216152605 / 0.0254)
    assert ks["bounds"][1] == pytest.approx(k_hi, rel=1e-3) and ks["bounds"][0] < 0.1 * 115000
    assert "load resonance" in ks["bounds_basis"] and ks["at_bound"] is False
    assert "model adequacy:" in p.stdout and "bounds" in p.stdout


@pytest.mark.slow
def test_parameter_held_at_a_set_bound_is_flagged(tmp_path):
    out = tmp_path / "fit.json"
    p = run_cli("fit", HOTFIRE_DATA, "--model", MODELS / "rs25_hotfire.toml", "--free", "load_stiffness",
                "--bounds", "load_stiffness=150000 lbf/in:170000 lbf/in", "--starts", "1", "--no-correction",
                "--start", "load_stiffness=160000 lbf/in", "--json", out)
    assert p.returncode == 0, p.stderr
    d = json.loads(out.read_text())
    assert d["parameters"]["load_stiffness"]["at_bound"] is True
    assert d["adequacy"]["verdict"] == "inadequate" and d["adequacy"]["at_bound"] == ["load_stiffness"]
    assert "AT BOUND" in p.stderr + p.stdout
    bad = run_cli("fit", HOTFIRE_DATA, "--model", MODELS / "rs25_hotfire.toml", "--free", "load_stiffness",
                  "--bounds", "load_stiffness=150000 lbf/in")
    assert bad.returncode == 2 and "--bounds" in bad.stderr and "Traceback" not in bad.stderr
