"""Hostile run files, records, sidecars, flags and environments (issue 40): each refused with one
line naming the file's dataset, attribute or option and exit 2 (or handled correctly), nothing
written, no input changed (SHA-256 before and after), no numpy warning leaked.

Run files are the layout ``taos simulate`` writes (:meth:`TimeHistory.to_hdf5`), corrupted one
way each; ``taos view --html`` and ``taos estimate`` read them through one reader
(:mod:`taos.planar.runfile`)."""

from __future__ import annotations

import hashlib
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from .conftest import ROOT, run_cli

RECORD = ROOT / "models/data/greenrun_hotfire_synthetic.csv"


def sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def base_run(path: Path) -> Path:
    """A valid two-axis run file: pitch 4 deg sin(pi t), yaw 3 deg cos(pi t), 0.8 m arm."""
    from taos.planar.simulate import TimeHistory

    t = np.linspace(0.0, 4.0, 2001)
    th = np.vstack([math.radians(4) * np.sin(np.pi * t), math.radians(3) * np.cos(np.pi * t)])
    delta = 5e-4 * np.vstack([np.sin(np.pi * t - 0.3), np.cos(np.pi * t - 0.3)])
    TimeHistory(t_s=t, axes=("pitch", "yaw"), command_rad=th, command_avionics_rad=th, piston_m=0.8 * th + delta,
                engine_rad=th, friction_torque_Nm=np.full_like(th, 100.0), friction_state_rad=np.zeros_like(th),
                load_force_N=3.6e7 * delta, moment_arm_m=0.8,
                provenance={"engine": "simplex", "model_name": "synthetic", "profile": "test"}).to_hdf5(path)
    return path


def _replace(key, fn):
    def edit(f, d):
        v = f[key][()]
        del f[key]
        f[key] = fn(v)
    return edit


def _link(kind):
    def edit(f, d):
        import h5py
        del f["pitch/engine_rad"]
        if kind == "loop":
            f["pitch/engine_rad"] = h5py.SoftLink("/pitch/other")
            f["pitch/other"] = h5py.SoftLink("/pitch/engine_rad")
        elif kind == "text":
            (d / "notes.txt").write_text("not HDF5\n")
            f["pitch/engine_rad"] = h5py.ExternalLink(str(d / "notes.txt"), "/x")
        else:   # a real HDF5 file elsewhere: still not this file's data
            with h5py.File(d / "other.h5", "w") as g:
                g["x"] = np.zeros(2001)
            f["pitch/engine_rad"] = h5py.ExternalLink(str(d / "other.h5"), "/x")
    return edit


def _attr(name, value):
    return lambda f, d: f.attrs.__setitem__(name, value)


#: corruption -> (edit(h5 file, folder), text the one line names)
RUNS = {
    "2-D time": (_replace("t_s", lambda v: np.vstack([v, v])), "/t_s"),
    "short array": (_replace("pitch/engine_rad", lambda v: v[:100]), "/pitch/engine_rad"),
    "short time": (_replace("t_s", lambda v: v[:100]), "samples like the time column"),
    "string dtype": (_replace("pitch/piston_m", lambda v: np.array([b"x"] * v.size)), "/pitch/piston_m"),
    "complex data": (_replace("pitch/engine_rad", lambda v: v * (1 + 1j)), "/pitch/engine_rad"),
    "a group for a dataset": (lambda f, d: (f.__delitem__("pitch/piston_m"), f.create_group("pitch/piston_m")),
                              "/pitch/piston_m"),
    "time not increasing": (_replace("t_s", lambda v: v[::-1]), "/t_s"),
    "huge engine angle": (_replace("pitch/engine_rad", lambda v: v * 1e300), "/pitch/engine_rad"),
    "huge piston": (_replace("pitch/piston_m", lambda v: v * 1e300), "/pitch/piston_m"),
    "NaN load force": (_replace("yaw/load_force_N", lambda v: v * np.nan), "/yaw/load_force_N"),
    "link loop": (_link("loop"), "/pitch/engine_rad"),
    "external link to a text file": (_link("text"), "/pitch/engine_rad"),
    "external link to another HDF5 file": (_link("h5"), "/pitch/engine_rad"),
    "NaN moment arm": (_attr("moment_arm_m", float("nan")), "moment_arm_m"),
    "zero moment arm": (_attr("moment_arm_m", 0.0), "moment_arm_m"),
    "moment arm as text": (_attr("moment_arm_m", "0.8 m"), "moment_arm_m"),
    "engine mujoco": (_attr("engine", "mujoco"), "engine"),
    "engine taos without its group": (_attr("engine", "taos"), "engine"),
    "unknown axis": (_attr("axes", "pitch,roll"), "axes"),
    "one axis twice": (_attr("axes", "pitch,pitch"), "axes"),
}


def _assert_one_line(p, *names):
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and all(n in lines[0] for n in names), p.stderr
    assert "Warning" not in p.stderr and "internal error" not in p.stderr


@pytest.mark.parametrize("command", ["view", "estimate"])
@pytest.mark.parametrize("case", sorted(RUNS))
def test_a_malformed_run_file_is_one_line_and_exit_2(case, command, tmp_path):
    import h5py

    edit, name = RUNS[case]
    run = base_run(tmp_path / "run.h5")
    with h5py.File(run, "r+") as f:
        edit(f, tmp_path)
    before = {q: sha(q) for q in tmp_path.iterdir()}
    out = tmp_path / "view.html"
    argv = ["view", run, "--html", out] if command == "view" else ["estimate", run, "--json", out.with_suffix(".json")]
    p = run_cli(*argv, timeout=120)
    _assert_one_line(p, str(run), name)
    assert {q: sha(q) for q in tmp_path.iterdir()} == before     # nothing written, nothing changed


def test_the_valid_run_file_is_viewed_and_the_python_reader_refuses_as_the_command_does(tmp_path):
    """The base of the corruptions is a good run (so each refusal above is the corruption's), and
    TimeHistory.from_hdf5 (the Python API) refuses with the same InputError."""
    import h5py

    from taos.errors import InputError
    from taos.planar.simulate import TimeHistory

    run = base_run(tmp_path / "run.h5")
    p = run_cli("view", run, "--html", tmp_path / "v.html", timeout=120)
    assert p.returncode == 0 and (tmp_path / "v.html").stat().st_size > 1000, p.stderr
    th = TimeHistory.from_hdf5(run)
    assert th.axes == ("pitch", "yaw") and th.moment_arm_m == 0.8 and th.engine_rad.shape == (2, 2001)
    with h5py.File(run, "r+") as f:
        f.attrs["engine"] = "mujoco"
    with pytest.raises(InputError, match="engine"):
        TimeHistory.from_hdf5(run)


def _record_variant(path: Path, time_factor: float = 1.0, col: int | None = None, value=None) -> Path:
    lines = RECORD.read_text().splitlines()
    out = []
    k = 0
    for ln in lines:
        if ln.startswith("#") or ln.startswith("time"):
            out.append(ln)
            continue
        c = ln.split(",")
        c[0] = repr(float(c[0]) * time_factor)
        if col is not None and k == 5:
            c[col] = value
        out.append(",".join(c))
        k += 1
    path.write_text("\n".join(out) + "\n")
    return path


RECORDS = {
    "time in microseconds labelled seconds": (dict(time_factor=1e6), ("time [s]", "sample rate")),
    "time in milliseconds labelled seconds": (dict(time_factor=1e3), ("time [s]", "sample rate")),
    "huge command": (dict(col=1, value="1e300"), ("pitch_command [deg]", "at most")),
    "huge pressure": (dict(col=4, value="1e300"), ("pitch_load_pressure [psi]", "at most")),
    "infinite piston": (dict(col=2, value="inf"), ("pitch_piston [in]", "finite")),
}


@pytest.mark.parametrize("case", sorted(RECORDS))
def test_a_record_in_the_wrong_unit_or_beyond_reason_is_refused(case, tmp_path):
    kw, names = RECORDS[case]
    rec = _record_variant(tmp_path / "r.csv", **kw)
    before = sha(rec)
    p = run_cli("estimate", rec, "--json", tmp_path / "e.json", timeout=120)
    _assert_one_line(p, str(rec), *names)
    assert sha(rec) == before and not (tmp_path / "e.json").exists()


def test_a_time_span_beyond_float_range_is_one_line_without_a_numpy_warning(tmp_path):
    t = [(i - 100) * 1.7e306 for i in range(200)]     # each time finite, the span overflows a float
    rec = tmp_path / "span.csv"
    rec.write_text("time [s],pitch_command [deg],pitch_piston [in]\n"
                   + "".join(f"{t[i]!r},{math.sin(i / 5):.5f},{0.01 * math.sin(i / 5):.6f}\n" for i in range(200)))
    p = run_cli("estimate", rec, timeout=120)
    _assert_one_line(p, str(rec), "time [s]")


def test_a_command_profile_beside_a_record_is_not_its_sidecar(tmp_path):
    """``mixed.toml`` (a command profile) beside ``mixed.csv``: the record is read from its own
    ``signal [unit]`` header, as if the profile were not there (the same estimate)."""
    alone = tmp_path / "alone"
    mixed = tmp_path / "mixed"
    alone.mkdir()
    mixed.mkdir()
    (alone / "mixed.csv").write_bytes(RECORD.read_bytes())
    (mixed / "mixed.csv").write_bytes(RECORD.read_bytes())
    (mixed / "mixed.toml").write_bytes((ROOT / "models/profiles/step_pitch.toml").read_bytes())
    for d in (alone, mixed):
        p = run_cli("estimate", d / "mixed.csv", "--json", d / "e.json", timeout=300)
        assert p.returncode == 0, p.stderr
    import json
    a, b = (json.loads((d / "e.json").read_text()) for d in (alone, mixed))
    for x in (a, b):
        x.pop("provenance", None)
        x.pop("data", None)
        x.pop("source", None)
    assert json.dumps(a, sort_keys=True, default=str).replace(str(alone), "") == \
        json.dumps(b, sort_keys=True, default=str).replace(str(mixed), "")


def test_an_unmarked_toml_beside_a_record_without_signal_headers_says_why(tmp_path):
    (tmp_path / "s.csv").write_text("t,c,x\n" + "".join(f"{i / 100},{math.sin(i / 5):.5f},0\n" for i in range(64)))
    (tmp_path / "s.toml").write_text('[columns]\nt = {signal = "time", unit = "s"}\n')
    p = run_cli("estimate", tmp_path / "s.csv", timeout=120)
    _assert_one_line(p, "s.csv", "sidecar_for", "s.toml")


def test_a_sidecar_naming_another_record_is_refused(tmp_path):
    (tmp_path / "s.csv").write_text("t,c,x\n" + "".join(f"{i / 100},{math.sin(i / 5):.5f},0\n" for i in range(64)))
    (tmp_path / "s.toml").write_text('sidecar_for = "other.csv"\n[columns]\nt = {signal = "time", unit = "s"}\n')
    p = run_cli("estimate", tmp_path / "s.csv", timeout=120)
    _assert_one_line(p, "s.toml", "sidecar_for", "'s.csv'")


# -- outputs against inputs however named ------------------------------------------------------

@pytest.mark.parametrize("name", ["models/flight/ascent.toml", "./models/flight/ascent.toml",
                                  "models/flight/../flight/ascent.toml", "{root}/models/flight/ascent.toml",
                                  "{t}/link.toml"])
def test_ascent_json_never_replaces_its_own_input(name, tmp_path):
    (tmp_path / "link.toml").symlink_to(ROOT / "models/flight/ascent.toml")
    shipped = {q: sha(q) for q in (ROOT / "models").rglob("*.toml")}
    p = run_cli("ascent", "ascent", "--start", "120", "--end", "121", "--out", tmp_path / "a",
                "--json", name.format(root=ROOT, t=tmp_path), "--force", timeout=120)
    _assert_one_line(p, "--json")
    assert {q: sha(q) for q in (ROOT / "models").rglob("*.toml")} == shipped
    assert not (tmp_path / "a").exists()


def test_lco_resume_without_a_stored_map_is_refused(tmp_path):
    p = run_cli("lco", "--flight", "core_stage", "rs25_flight", "--sweep", "integral_gain=0.6,0.7",
                "--out", tmp_path / "map", "--resume", timeout=120)
    _assert_one_line(p, "--resume")
    assert not (tmp_path / "map").exists() or not any((tmp_path / "map").iterdir())


def test_a_flight_file_whose_tvc_model_is_itself_is_refused_on_the_command_line(tmp_path):
    text = (ROOT / "models/flight/core_stage.toml").read_text()
    f = tmp_path / "self.toml"
    f.write_text("\n".join('tvc_model = "self.toml"' if ln.startswith("tvc_model") else ln
                           for ln in text.splitlines()) + "\n")
    p = run_cli("lco", "--flight", f, "rs25_flight", "--no-time-domain", timeout=120)
    _assert_one_line(p, "tvc_model")


# -- environment ------------------------------------------------------------------------------

def _taos_env(env: dict, *args, cwd=ROOT):
    exe = Path(sys.executable).parent / "taos"
    full = {k: v for k, v in os.environ.items() if k not in ("LC_ALL", "LANG", "LC_CTYPE")}
    full.update(env)
    return subprocess.run([os.fsencode(str(exe)), *[a if isinstance(a, bytes) else os.fsencode(str(a)) for a in args]],
                          capture_output=True, cwd=cwd, env=full, timeout=300)


@pytest.mark.parametrize("env", [{"LANG": "C"}, {"LC_ALL": "C", "PYTHONCOERCECLOCALE": "0", "PYTHONUTF8": "0"}],
                         ids=["LANG=C", "LC_ALL=C-no-coercion"])
@pytest.mark.parametrize("raw", [False, True], ids=["utf8-name", "latin1-bytes-name"])
def test_a_non_ascii_path_under_the_c_locale(env, raw, tmp_path):
    d = os.fsencode(str(tmp_path)) + (b"/d\xe9" if raw else "/dé".encode())
    os.mkdir(d)
    rec, js, png = d + b"/r\xc3\xa9c.csv", d + b"/\xf6.json", d + b"/\xf6.png"
    with open(rec, "wb") as f:
        f.write(RECORD.read_bytes())
    p = _taos_env(env, "estimate", rec, "--json", js)
    assert p.returncode == 0 and os.path.getsize(js) > 100, p.stderr
    p = _taos_env(env, "freqresp", "rs25_hotfire", "--freq-hz", "1,2", "--linear", "--plot", png)
    assert p.returncode == 0 and os.path.getsize(png) > 1000, p.stderr


def test_an_unknown_matplotlib_backend_does_not_stop_a_plot(tmp_path):
    p = _taos_env({"MPLBACKEND": "nonsense"}, "freqresp", "rs25_hotfire", "--freq-hz", "1,2", "--linear",
                  "--plot", tmp_path / "b.png")
    assert p.returncode == 0 and (tmp_path / "b.png").stat().st_size > 1000, p.stderr


@pytest.mark.parametrize("value", ["0", "-1", "abc", ""])
def test_a_bad_numba_thread_count_is_one_line(value, tmp_path):
    p = _taos_env({"NUMBA_NUM_THREADS": value}, "freqresp", "rs25_hotfire", "--freq-hz", "1", "--linear",
                  "--json", tmp_path / "f.json")
    err = p.stderr.decode()
    assert p.returncode == 2 and len(err.strip().splitlines()) == 1 and "NUMBA_NUM_THREADS" in err, err
    assert not (tmp_path / "f.json").exists()


# -- the other HDF5 readers: flight records (taos pti) and describing-function maps ---------------

def _flight_record(path: Path) -> Path:
    import h5py
    t = np.arange(200) * 0.01
    with h5py.File(path, "w") as f:
        f["t_s"] = t
        f.attrs["axes"] = "pitch"
        for name, x in (("pti_rad", 1e-3 * np.sin(t)), ("command_rad", 2e-3 * np.sin(t)), ("piston_m", 1e-3 * np.sin(t))):
            f[f"pitch/{name}"] = x
    return path


@pytest.mark.parametrize("case", ["link loop", "external link to a text file", "string dtype", "complex data",
                                  "huge piston", "2-D time"])
def test_a_malformed_flight_record_is_one_line(case, tmp_path):
    import h5py

    from taos.errors import InputError
    from taos.flight.pti_record import load_flight_record

    p = _flight_record(tmp_path / "rec.h5")
    assert load_flight_record(p).axes == ("pitch",)          # the base is a good record
    with h5py.File(p, "r+") as f:
        if case == "2-D time":
            _replace("t_s", lambda v: np.vstack([v, v]))(f, tmp_path)
        elif case in ("link loop", "external link to a text file"):
            del f["pitch/piston_m"]
            if case == "link loop":
                f["pitch/piston_m"] = h5py.SoftLink("/pitch/x")
                f["pitch/x"] = h5py.SoftLink("/pitch/piston_m")
            else:
                (tmp_path / "notes.txt").write_text("text\n")
                f["pitch/piston_m"] = h5py.ExternalLink(str(tmp_path / "notes.txt"), "/x")
        else:
            fn = {"string dtype": lambda v: np.array([b"x"] * v.size), "complex data": lambda v: v * 1j,
                  "huge piston": lambda v: v * 1e300}[case]
            _replace("pitch/piston_m", fn)(f, tmp_path)
    with pytest.raises(InputError) as e:
        load_flight_record(p)
    msg = str(e.value)
    assert "\n" not in msg and ("/t_s" if case == "2-D time" else "piston_m") in msg, msg


def _df_map(path: Path) -> Path:
    import json

    import h5py
    with h5py.File(path, "w") as f:
        f["amplitude_rad"] = np.array([1e-3, 2e-3])
        f["freq_hz"] = np.array([0.5, 1.0, 2.0])
        f["engine"] = np.full((2, 3), 0.9 - 0.1j)
        f["piston"] = np.full((2, 3), 0.95 - 0.05j)
        f.attrs["friction_model"] = "dahl"
        f.attrs["axis"] = "pitch"
        f.attrs["load_stiffness_N_per_m"] = float("nan")
        f.attrs["provenance"] = json.dumps({"provenance": {}})
    return path


@pytest.mark.parametrize("case, field", [("engine 1-D", "/engine"), ("engine as text", "/engine"),
                                         ("axis roll", "axis"), ("negative amplitude", "/amplitude_rad"),
                                         ("provenance not JSON", "load_stiffness_N_per_m"),
                                         ("infinite stiffness", "load_stiffness_N_per_m")])
def test_a_malformed_describing_function_map_is_one_line(case, field, tmp_path):
    import h5py

    from taos.errors import InputError
    from taos.flight.describing import DescribingFunctionMap

    p = _df_map(tmp_path / "df.h5")
    assert DescribingFunctionMap.from_hdf5(p).engine.shape == (2, 3)     # the base is a good map
    with h5py.File(p, "r+") as f:
        edit = {"engine 1-D": _replace("engine", lambda v: v[0]),
                "engine as text": _replace("engine", lambda v: np.array([[b"a"] * 3] * 2)),
                "axis roll": _attr("axis", "roll"),
                "negative amplitude": _replace("amplitude_rad", lambda v: -v),
                "provenance not JSON": _attr("provenance", "{not json"),
                "infinite stiffness": _attr("load_stiffness_N_per_m", float("inf"))}[case]
        edit(f, tmp_path)
    with pytest.raises(InputError) as e:
        DescribingFunctionMap.from_hdf5(p)
    assert "\n" not in str(e.value) and field in str(e.value), str(e.value)


@pytest.mark.parametrize("option", ["--angle-scale", "--deflection-scale"])
def test_a_view_scale_that_draws_beyond_reason_is_one_line_not_an_overflow(option, tmp_path):
    run = base_run(tmp_path / "run.h5")
    p = run_cli("view", run, "--html", tmp_path / "v.html", option, "1e300", timeout=120)
    _assert_one_line(p, option)
    assert not (tmp_path / "v.html").exists()


@pytest.mark.parametrize("case, field", [("2-D column", "/pitch_piston"), ("unit not text", "unit"),
                                         ("external link", "/pitch_command"), ("complex column", "/time")])
def test_a_malformed_hdf5_record_of_named_signals_is_one_line(case, field, tmp_path):
    """The other HDF5 record layout (root datasets named by signal, a unit attribute each)."""
    import h5py

    from taos.errors import InputError
    from taos.identify.data import load_test_data

    p = tmp_path / "r.h5"
    t = np.arange(400) * 0.01
    with h5py.File(p, "w") as f:
        for name, x, unit in (("time", t, "s"), ("pitch_command", np.sin(t), "deg"),
                              ("pitch_piston", 0.1 * np.sin(t), "in")):
            f[name] = x
            f[name].attrs["unit"] = unit
    assert load_test_data(p).axes == ("pitch",)                  # the base is a good record
    with h5py.File(p, "r+") as f:
        if case == "2-D column":
            _replace("pitch_piston", lambda v: v[:, None])(f, tmp_path)
            f["pitch_piston"].attrs["unit"] = "in"
        elif case == "unit not text":
            f["pitch_command"].attrs["unit"] = np.array([1.0, 2.0])
        elif case == "external link":
            with h5py.File(tmp_path / "o.h5", "w") as g:
                g["x"] = np.zeros(400)
            del f["pitch_command"]
            f["pitch_command"] = h5py.ExternalLink(str(tmp_path / "o.h5"), "/x")
        else:
            _replace("time", lambda v: v + 0j)(f, tmp_path)
    with pytest.raises(InputError) as e:
        load_test_data(p)
    assert "\n" not in str(e.value) and field in str(e.value), str(e.value)


@pytest.mark.parametrize("text", ["time [s],pitch_command [deg],pitch_piston [in]\n", "\0\0\0\0"],
                         ids=["header only", "NUL bytes"])
def test_a_record_without_rows_is_one_line_without_a_numpy_warning(text, tmp_path):
    rec = tmp_path / "empty.csv"
    rec.write_text(text)
    p = run_cli("estimate", rec, timeout=120)
    _assert_one_line(p, str(rec))
