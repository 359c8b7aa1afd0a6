"""Outputs never destroy what the program did not write; interrupted runs leave the previous
result whole and no temporary file; divergence is never passed off as a result; runs are
reproducible bit for bit; the viewer's server ends with its parent (issue "No silent wrong
answers and no lost files", points 1, 3 and 6)."""

from __future__ import annotations

import os
import re
import select
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import pytest

from taos.cli import main

from . import _forkserver
from .conftest import inline_actuator_set

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
AMBIENT = MODELS / "rs25_ambient.toml"
STEP = MODELS / "profiles" / "step_pitch.toml"

#: a short two-axis profile so that greenrun runs in seconds
SHORT_TWO_AXIS = """name = "short two-axis"
[pitch]
type = "sine_dwell"
amplitude = "0.4 deg"
frequency = "2 Hz"
cycles = 3
[yaw]
type = "sine_dwell"
amplitude = "0.4 deg"
frequency = "3 Hz"
cycles = 3
"""


def unstable_model(tmp: Path) -> Path:
    """The ambient model without dynamic pressure feedback and without friction (issue example)."""
    t = inline_actuator_set(AMBIENT.read_text(), AMBIENT).replace('stiffness_file = "../fem_data/', f'stiffness_file = "{ROOT}/fem_data/')
    t = re.sub(r'(?m)^pressure_feedback_gain\s*=.*$', 'pressure_feedback_gain = "0 m/s/Pa"', t)
    t = re.sub(r'(?m)^model\s*=.*$', 'model = "none"', t, count=1)
    p = tmp / "unstable.toml"
    p.write_text(t)
    return p


def temporaries(folder: Path) -> list[Path]:
    return [p for p in folder.iterdir() if p.name.endswith(".tmp")]


# -- foreign files ----------------------------------------------------------------------------

@pytest.mark.slow
def test_greenrun_and_compare_leave_foreign_files_untouched(tmp_path, capsys):
    out = tmp_path / "mydir"
    out.mkdir()
    thesis = out / "thesis.tex"
    thesis.write_text("\\chapter{mine}\n")
    prof = tmp_path / "short.toml"
    prof.write_text(SHORT_TWO_AXIS)
    for _ in range(2):  # the second run replaces the program's own files, and only those
        assert main(["greenrun", str(AMBIENT), "--profile", str(prof), "--out", str(out), "--quiet"]) == 0
    assert thesis.read_text() == "\\chapter{mine}\n"
    assert {"index.html", "summary.json", "greenrun.h5"} <= {p.name for p in out.iterdir()}
    assert main(["compare", str(AMBIENT), str(MODELS / "rs25_hotfire.toml"), "--out", str(out)]) == 0
    assert thesis.read_text() == "\\chapter{mine}\n"
    assert (out / "table.txt").is_file() and not temporaries(out)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "nothing hidden left beside the folder"


def test_output_file_in_place_of_a_folder_is_refused_and_kept(tmp_path, capsys):
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes")
    assert main(["greenrun", str(AMBIENT), "--out", str(notes), "--quiet"]) == 2
    assert notes.read_text() == "my notes"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


# -- interrupted runs -------------------------------------------------------------------------

#: run the CLI with a slow write: prints WRITING and sleeps inside the write (temporary file open)
SLOW = """
import sys, time
import taos.results as r
real = r.os.replace
def slow(src, dst, *a, **k):
    if str(src).endswith('.taos.tmp'):
        print('WRITING', flush=True)
        time.sleep(60)
    return real(src, dst, *a, **k)
r.os.replace = slow
from taos.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _start_slow(args, cwd):
    """``python -c SLOW ARGS`` in ``cwd``, forked from the test process's fork server
    (:mod:`tests._forkserver`: a ``subprocess.Popen``-like child; a real process where the fork
    server cannot run it)."""
    return _forkserver.popen([sys.executable, "-c", SLOW, *map(str, args)], cwd)


def _wait_for_writing(proc, timeout=240):
    t_end = time.time() + timeout
    while time.time() < t_end:
        r, _, _ = select.select([proc.stdout], [], [], 1.0)
        if r:
            line = proc.stdout.readline()
            if "WRITING" in line:
                return
            if not line and proc.poll() is not None:
                break
    proc.kill()
    raise AssertionError(f"never reached the write: {proc.stderr.read()}")


def _in_process(args, cwd) -> int:
    """The command line ``args`` run by :func:`taos.cli.main` in this process from ``cwd`` (as
    ``python -m taos`` would, without the start-up of another interpreter)."""
    old = os.getcwd()
    os.chdir(cwd)
    try:
        return main([str(a) for a in args])
    finally:
        os.chdir(old)


def _snapshot(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


@pytest.fixture(scope="module")
def previous_report(tmp_path_factory) -> Path:
    """A short Green Run's report folder, made in this process (the previous result the killed
    greenrun runs below must leave whole: the setup, not the process under test; made once and
    copied, mark included, into each test's folder)."""
    tmp = tmp_path_factory.mktemp("previous")
    prof = tmp / "short.toml"
    prof.write_text(SHORT_TWO_AXIS)
    assert _in_process(["greenrun", AMBIENT, "--profile", prof, "--out", tmp / "report", "--quiet"], tmp) == 0
    return tmp / "report"


@pytest.mark.slow
@pytest.mark.parametrize("command", ["simulate", "greenrun"])
def test_killed_during_write_keeps_previous_result_and_leaves_no_temporary(command, tmp_path, request):
    prof = tmp_path / "short.toml"
    prof.write_text(SHORT_TWO_AXIS)
    # the previous result: made in this process (it is the setup, not the process under test)
    if command == "simulate":
        folder = tmp_path / "runs"
        folder.mkdir()
        args = ["simulate", AMBIENT, "--profile", prof, "--out", folder / "run.h5"]
        assert _in_process(args, tmp_path) == 0
    else:
        folder = tmp_path / "report"
        args = ["greenrun", AMBIENT, "--profile", prof, "--out", folder, "--quiet"]
        shutil.copytree(request.getfixturevalue("previous_report"), folder)
    before = _snapshot(folder)
    assert before and not temporaries(folder)

    # SIGTERM: one line, exit 143, the temporary file removed at once
    proc = _start_slow(args, tmp_path)
    _wait_for_writing(proc)
    assert temporaries(folder), "the write was not in progress"
    proc.send_signal(signal.SIGTERM)
    rc = proc.wait(60)
    err = proc.stderr.read()
    assert rc == 143, err
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("taos: terminated")
    assert _snapshot(folder) == before and not temporaries(folder)

    # Ctrl-C (SIGINT): one line, exit 130, no traceback, nothing half-written
    proc = _start_slow(args, tmp_path)
    _wait_for_writing(proc)
    proc.send_signal(signal.SIGINT)
    rc = proc.wait(60)
    err = proc.stderr.read()
    assert rc == 130, err
    assert "Traceback" not in err and "interrupted" in err.strip().splitlines()[-1]
    assert _snapshot(folder) == before and not temporaries(folder)

    # SIGKILL: nothing can clean up, but the previous result is whole ...
    proc = _start_slow(args, tmp_path)
    _wait_for_writing(proc)
    proc.kill()
    proc.wait(60)
    assert temporaries(folder), "SIGKILL should leave the temporary file for the next run"
    # (the mark lists the temporary as pending: that is how the next run knows it is its own)
    mine = lambda snap: {k: v for k, v in snap.items() if not k.endswith(".tmp") and k != ".taos-output.json"}  # noqa: E731
    assert mine(_snapshot(folder)) == mine(before)
    # ... and the next run in that place removes the stale temporary file
    # (the program's own clean-up, not the process: run in this process as well)
    assert _in_process(args, tmp_path) == 0
    assert not temporaries(folder)
    assert '"pending": []' in (folder / ".taos-output.json").read_text()


# -- divergence -------------------------------------------------------------------------------

def test_unstable_servo_is_refused_before_the_run_unless_allowed(tmp_path, capsys):
    model = unstable_model(tmp_path)
    out = tmp_path / "run.h5"
    assert main(["simulate", str(model), "--profile", str(STEP), "--out", str(out)]) == 3
    line = capsys.readouterr().err.strip()
    assert len(line.splitlines()) == 1
    assert re.search(r"mode at [\d.]+ Hz has damping ratio -[\d.]+", line), line
    assert "pressure_feedback_gain" in line and "--allow-unstable" in line
    assert not out.exists()
    assert main(["greenrun", str(model), "--out", str(tmp_path / "rep"), "--quiet"]) == 3
    assert not (tmp_path / "rep").exists()
    assert main(["freqresp", str(model), "--freq-hz", "1", "--amplitude-deg", "0.4"]) == 3
    # the explicit opt-in runs it
    assert main(["simulate", str(model), "--profile", str(STEP), "--out", str(out), "--allow-unstable"]) == 0
    assert out.is_file()


def test_info_shows_the_unstable_mode(tmp_path, capsys):
    import json

    assert main(["info", str(unstable_model(tmp_path)), "--json", "-"]) == 0
    modes = json.loads(capsys.readouterr().out)["linear_modes"]
    assert min(m["damping_ratio"] for m in modes) < 0


def test_leaving_the_envelope_stops_with_exit_3_naming_time_state_and_cause(tmp_path, capsys):
    """A supply pressure far too low for the load (20 psi: stall force A P_s tiny, yet within the documented 1 bar lower bound): the load force
    leaves the envelope; the run stops with exit 3 and writes nothing."""
    t = inline_actuator_set(AMBIENT.read_text(), AMBIENT).replace('stiffness_file = "../fem_data/', f'stiffness_file = "{ROOT}/fem_data/')
    t = re.sub(r'(?m)^supply_pressure\s*=.*$', 'supply_pressure = "20 psi"', t)
    # the valve law off (with it on, a 20 psi supply makes the stall limit a stiff mode that the
    # step check refuses before the run: exit 2); the envelope check catches the load force
    t = re.sub(r'(?m)^pressure_limited\s*=.*$', 'pressure_limited = false', t)
    t = re.sub(r'(?m)^relief_pressure\s*=.*$', 'relief_pressure = "20 psi"', t)  # cracks at P_s
    model = tmp_path / "weak.toml"
    model.write_text(t)
    out = tmp_path / "run.h5"
    assert main(["simulate", str(model), "--profile", str(STEP), "--out", str(out)]) == 3
    line = capsys.readouterr().err.strip()
    assert len(line.splitlines()) == 1
    assert re.search(r"envelope at t = [\d.]+ s: pitch load force .* beyond .*stall force.*likely cause", line), line
    assert not out.exists()


def test_step_command_beyond_gimbal_range_is_refused_not_run(tmp_path, capsys):
    prof = tmp_path / "big.toml"
    prof.write_text('type = "step"\namplitude = "45 deg"\n')
    assert main(["simulate", str(AMBIENT), "--profile", str(prof), "--out", str(tmp_path / "r.h5")]) == 2
    assert "+-10.5 deg" in capsys.readouterr().err


def test_oversized_step_is_refused_with_the_step_limit(tmp_path, capsys):
    assert main(["simulate", str(AMBIENT), "--profile", str(STEP), "--out", str(tmp_path / "r.h5"),
                 "--dt", "0.005"]) == 2
    line = capsys.readouterr().err
    assert re.search(r"--dt: expected a step at most [\d.e-]+ s", line), line


# -- provenance and reproducibility ----------------------------------------------------------

def test_two_identical_runs_are_bit_identical_and_carry_full_provenance(tmp_path, capsys):
    a, b = tmp_path / "a.h5", tmp_path / "b.h5"
    for p in (a, b):
        assert main(["simulate", str(AMBIENT), "--profile", str(STEP), "--out", str(p)]) == 0
    assert a.read_bytes() == b.read_bytes()
    with h5py.File(a) as h5:
        attrs = dict(h5.attrs)
    for k in ("package_version", "git_revision", "model_file", "model_sha256", "profile_file", "profile_sha256",
              "solver", "seeds"):
        assert k in attrs, k
    assert len(attrs["profile_sha256"]) == 64 and len(attrs["model_sha256"]) == 64
    ja, jb = tmp_path / "a.json", tmp_path / "b.json"
    for p in (ja, jb):
        assert main(["freqresp", str(AMBIENT), "--freq-hz", "1,2", "--amplitude-deg", "0.4", "--json", str(p)]) == 0
    assert ja.read_bytes() == jb.read_bytes()


def test_3d_run_records_the_stiffness_file_hash(tmp_path, capsys):
    from taos.results import file_sha256

    out = tmp_path / "r.h5"
    assert main(["simulate", str(AMBIENT), "--engine", "taos", "--profile", str(STEP), "--out", str(out)]) == 0
    with h5py.File(out) as h5:
        assert h5.attrs["stiffness_sha256"] == file_sha256(ROOT / "fem_data" / "gimbal_hanging.npz")


# -- the viewer's server ----------------------------------------------------------------------

@pytest.mark.slow
def test_viewer_server_ends_when_its_parent_is_killed(tmp_path):
    from taos.model import load_model
    from taos.profiles import load_profile
    from taos.planar.simulate import simulate

    h5 = tmp_path / "run.h5"
    simulate(load_model(AMBIENT), load_profile(STEP)).to_hdf5(h5)
    # python -m taos as a new process, forked from the test process's fork server (Popen-like; the
    # package the fork server imported, as run_cli's commands: no checkout prepended to PYTHONPATH)
    proc = _forkserver.popen([sys.executable, "-m", "taos", "view", str(h5)], tmp_path)
    try:
        t_end, ok = time.time() + 60, False
        while time.time() < t_end and not ok:
            r, _, _ = select.select([proc.stdout], [], [], 1.0)
            ok = bool(r) and "serving" in proc.stdout.readline()
            assert proc.poll() is None, proc.stderr.read()
        assert ok, "taos view never served"
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
        assert children
    finally:
        proc.kill()  # SIGKILL: the parent cannot clean up
        proc.wait(10)

    def alive(pid):
        stat = Path(f"/proc/{pid}/stat")
        return stat.exists() and stat.read_text().split()[2] != "Z"

    t_end = time.time() + 10
    while time.time() < t_end and any(alive(c) for c in children):
        time.sleep(0.2)
    assert not any(alive(c) for c in children), "the meshcat server outlived its parent"


def test_stale_temporaries_of_dead_runs_are_removed_and_nothing_else(tmp_path):
    """Only a temporary this program listed in the folder's mark before making it is ever
    removed: a user's file with the same pattern, or the old pattern, is kept."""
    import json

    from taos.results import MARK, atomic_write

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".run.h5.{dead.pid}.{'ab' * 16}.taos.tmp"     # a killed run's, listed
    stale.write_text("half")
    lookalike = tmp_path / f".old.h5.{dead.pid}.{'cd' * 16}.taos.tmp"  # same pattern, not listed
    lookalike.write_text("user")
    mine = tmp_path / f".notes.{dead.pid}.taos.tmp"      # looks temporary, but not this program's
    mine.write_text("keep")
    (tmp_path / MARK).write_text(json.dumps({"written_by": "taos", "files": [], "pending": [stale.name]}))
    atomic_write(tmp_path / "run.json", lambda p: p.write_text("{}"))
    assert not stale.exists() and mine.read_text() == "keep" and lookalike.read_text() == "user"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([MARK, mine.name, lookalike.name, "run.json"])
    assert json.loads((tmp_path / MARK).read_text())["pending"] == []


def test_debug_shows_the_traceback_and_an_internal_error_is_still_one_line(tmp_path, capsys, monkeypatch):
    assert main(["info", str(tmp_path / "none.toml"), "--debug"]) == 2
    assert "Traceback" in capsys.readouterr().err
    import taos.cli.basic as basic

    def boom(args):
        raise RuntimeError("bug\nwith two lines")
    monkeypatch.setattr(basic, "model_summary", lambda m, steps=False: boom(None))
    assert main(["info", str(AMBIENT)]) == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "internal error" in err and "Traceback" not in err
