"""Property tests (hypothesis) over the model-file, profile and data loaders and the CLI options:
valid inputs run; invalid inputs end with exit 2 and one line naming the file or option; never a
traceback, an internal error or a hang. Examples are bounded so the file runs in CI in about a
minute."""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from taos.cli import main
from taos.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
AMBIENT = ROOT / "models" / "rs25_ambient.toml"
FUZZ = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

UNITS = ["deg", "rad", "Hz", "s", "lbf/in", "N/m", "in*lbf", "kg", "psi", "m", "in**2", "1/s", "", "furlong",
         "m/s/Pa", "kg*m**2", "N*m/rad"]
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                    st.sampled_from([0.0, -1.0, 1e-300, 1e300, 1e-9, 1e9, 0.4, 7.0, 10.5, 20.0]))
unit_strings = st.builds(lambda x, u: f"{x!r} {u}".strip(), numbers, st.sampled_from(UNITS))
toml_values = st.one_of(unit_strings, numbers.filter(math.isfinite), st.booleans(), st.integers(-10, 10 ** 13),
                        st.text(max_size=12), st.lists(st.integers(0, 3), max_size=3),
                        st.just({"a": 1}))


def toml_literal(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_literal(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_literal(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def one_line_exit_2(rc: int, err: str) -> None:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err and "internal error" not in err, err
    assert rc == 2, (rc, err)
    assert len(lines) == 1, err


# -- model files ----------------------------------------------------------------------------------
MODEL_TEXT = AMBIENT.read_text().replace('stiffness_file = "../fem_data/', f'stiffness_file = "{ROOT}/fem_data/')
KEY_LINES = [m.group(1) for m in re.finditer(r'(?m)^([a-z_]+) = ', MODEL_TEXT)]


@FUZZ
@given(key=st.sampled_from(KEY_LINES), value=toml_values)
def test_model_file_value_fuzz(key, value, tmp_path_factory, capsys):
    """Any value for any key: the model loads (exit 0) or the one-line refusal names the key."""
    tmp = tmp_path_factory.mktemp("m")
    text = re.sub(rf'(?m)^{key} = .*$', f"{key} = {toml_literal(value)}", MODEL_TEXT, count=1)
    p = tmp / "m.toml"
    p.write_text(text)
    rc = main(["info", str(p), "--json", str(tmp / "o.json")])
    err = capsys.readouterr().err
    if rc == 0:
        assert (tmp / "o.json").is_file()
    else:
        one_line_exit_2(rc, err)
        assert not (tmp / "o.json").exists()


@FUZZ
@given(cut=st.integers(0, len(MODEL_TEXT)), junk=st.text(max_size=20))
def test_model_file_truncated_or_corrupted(cut, junk, tmp_path_factory, capsys):
    tmp = tmp_path_factory.mktemp("m")
    p = tmp / "m.toml"
    p.write_text(MODEL_TEXT[:cut] + junk)
    rc = main(["info", str(p), "--json", str(tmp / "o.json")])
    err = capsys.readouterr().err
    if rc != 0:
        one_line_exit_2(rc, err)


# -- profiles -----------------------------------------------------------------------------------
TYPES = ["step", "sine_dwell", "sine_sweep", "multisine", "multi_ramp", "sequence", "square"]
KEYS = ["amplitude", "frequency", "cycles", "start", "hold", "start_frequency", "end_frequency", "duration",
        "levels", "rate", "frequencies", "logarithmic", "segments", "cycels", "amplitud"]
prof_values = st.one_of(
    st.builds(lambda x: f"{x:g} deg", st.floats(-15, 15)),
    st.builds(lambda x: f"{x:g} Hz", st.floats(1e-5, 2e3)),
    st.builds(lambda x: f"{x:g} s", st.floats(-1, 3)),
    st.integers(-2, 10 ** 13), toml_values)


@FUZZ
@given(kind=st.sampled_from(TYPES), table=st.dictionaries(st.sampled_from(KEYS), prof_values, max_size=5))
def test_profile_fuzz(kind, table, tmp_path_factory, capsys):
    """Loaded profiles are within the documented limits and short ones simulate; everything
    else is refused with exit 2 and one line."""
    from taos.bounds import GIMBAL_RANGE_RAD, MAX_DURATION_S
    from taos.profiles import load_profile

    tmp = tmp_path_factory.mktemp("p")
    p = tmp / "p.toml"
    p.write_text(f'type = "{kind}"\n' + "".join(f"{k} = {toml_literal(v)}\n" for k, v in table.items()))
    try:
        prof = load_profile(p)
    except InputError as e:
        assert "\n" not in str(e) and str(p) in str(e)
        rc = main(["simulate", str(AMBIENT), "--profile", str(p), "--out", str(tmp / "r.h5")])
        one_line_exit_2(rc, capsys.readouterr().err)
        assert not (tmp / "r.h5").exists()
        return
    assert prof.duration_s <= MAX_DURATION_S
    t = np.linspace(0, min(prof.duration_s, 50.0), 2001)
    assert np.all(np.abs(prof(t)) <= GIMBAL_RANGE_RAD * (1 + 1e-9))
    if prof.duration_s <= 2.0:
        rc = main(["simulate", str(AMBIENT), "--profile", str(p), "--out", str(tmp / "r.h5")])
        err = capsys.readouterr().err
        assert rc in (0, 2, 3) and "Traceback" not in err, err
        if rc == 0:
            assert (tmp / "r.h5").is_file()
        else:  # refused before the run (step limit) or stopped at the envelope: one line, no file
            assert len([ln for ln in err.splitlines() if ln.strip()]) == 1, err
            assert not (tmp / "r.h5").exists()


# -- data files ---------------------------------------------------------------------------------
def _good_rows(n=120):
    t = np.arange(n) * 0.01
    c = 0.4 * np.sin(2 * np.pi * 2 * t)
    return ["time [s],pitch_command [deg],pitch_piston [in]"] + [f"{a:.4f},{b:.6f},{b * 0.55:.6f}" for a, b in zip(t, c)]


cells = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.text(max_size=6),
                  st.sampled_from(["", "1e12", "-1", "nan", "0", "1,2", "#"]))


@FUZZ
@given(edits=st.lists(st.tuples(st.integers(0, 120), st.integers(0, 2), cells), max_size=4),
       drop=st.integers(0, 130))
def test_data_loader_fuzz(edits, drop, tmp_path_factory):
    """Mutated CSV records load (validated: increasing finite time) or raise a one-line InputError."""
    from taos.identify.data import load_test_data

    rows = _good_rows()
    for r, c, v in edits:
        cols = rows[r].split(",")
        cols[c] = v
        rows[r] = ",".join(cols)
    rows = rows[: max(1, len(rows) - drop)]
    p = tmp_path_factory.mktemp("d") / "d.csv"
    p.write_text("\n".join(rows) + "\n")
    try:
        d = load_test_data(p)
    except InputError as e:
        assert "\n" not in str(e)
        return
    assert np.all(np.diff(d.t_s) > 0) and np.all(np.isfinite(d.piston_m))


# -- command-line options ------------------------------------------------------------------------
option_text = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.text(max_size=8),
                        st.lists(st.floats(1e-6, 1e6).map(repr), min_size=1, max_size=3).map(",".join))


@FUZZ
@given(freq=option_text, amp=st.one_of(st.none(), option_text), axis=st.sampled_from(["pitch", "yaw", "roll"]))
def test_freqresp_option_fuzz(freq, amp, axis, capsys):
    argv = ["freqresp", str(AMBIENT), "--freq-hz", freq, "--axis", axis, "--json", "-"]
    if amp is not None:
        argv += ["--amplitude-deg", amp]
    try:
        rc = main(argv)
    except SystemExit as e:  # pragma: no cover - run() never lets argparse exit
        pytest.fail(f"SystemExit {e.code}")
    out = capsys.readouterr()
    if rc == 0:
        import json
        d = json.loads(out.out)
        # one amplitude: a gain per frequency; several: a list per amplitude (a JSON null, a
        # non-finite gain, is NaN here and fails)
        g = np.asarray(d["piston"]["gain_db"], dtype=float)
        assert g.size and np.all(np.isfinite(g))
    else:
        one_line_exit_2(rc, out.err)


@pytest.fixture(scope="module")
def short_inputs(tmp_path_factory):
    """(a 0.3 s pitch step profile, the first 2048 samples of the shipped ambient record with its
    header): the option fuzz below is about --dt and --nperseg, so a valid tiny step or a short
    segment costs a short run instead of the 3.5 s step and the 33 s record."""
    d = tmp_path_factory.mktemp("short")
    prof = d / "step_short.toml"
    prof.write_text('name = "Pitch step, 0.4 deg, short"\ntype = "step"\namplitude = "0.4 deg"\n'
                    'start = "0.05 s"\nhold = "0.25 s"\n')
    lines = (ROOT / "models" / "data" / "greenrun_ambient_synthetic.csv").read_text().splitlines(keepends=True)
    head = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))   # the column names
    rec = d / "record_short.csv"
    rec.write_text("".join(lines[:head + 1 + 2048]))
    return prof, rec


@pytest.mark.slow
@FUZZ
@given(dt=option_text, nperseg=st.one_of(st.integers(-10, 10 ** 9).map(str), st.text(max_size=5)))
def test_step_and_segment_option_fuzz(dt, nperseg, short_inputs, tmp_path_factory, capsys):
    prof, rec = short_inputs
    tmp = tmp_path_factory.mktemp("o")
    rc = main(["simulate", str(AMBIENT), "--profile", str(prof), "--out", str(tmp / "r.h5"), "--dt", dt])
    err = capsys.readouterr().err
    if rc != 0:
        one_line_exit_2(rc, err)
        assert not (tmp / "r.h5").exists()
    rc = main(["estimate", str(rec), "--method", "h1", "--nperseg", nperseg, "--json", str(tmp / "e.json")])
    err = capsys.readouterr().err
    if rc != 0:
        one_line_exit_2(rc, err)
        assert not (tmp / "e.json").exists()


def test_toml_literal_round_trips():
    assert tomllib.loads("x = " + toml_literal({"a": 1}))["x"] == {"a": 1}
