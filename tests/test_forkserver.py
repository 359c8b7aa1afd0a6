"""The fork server of :func:`tests.conftest.run_cli` (:mod:`tests._forkserver`) against real
processes: for each command the same exit status, standard output, standard error and files
written; the same process state when a command starts (signal handlers, open descriptors,
threads, warnings filters, standard streams, ``sys.path``, environment, umask, process group);
a crash, an uncaught exception, ``sys.exit(text)`` and a timeout reported as ``subprocess.run``
reports them; and what it refuses to run. Likewise ``python -c`` and ``python -m`` children and a
command with its own environment (a zygote started with it)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tests import _forkserver, _forkserver_io
from tests.conftest import MODELS

TAOS = str(Path(sys.executable).parent / "taos")


@pytest.fixture
def zygote():
    z = _forkserver.zygote(TAOS)
    assert z is not None, "the fork server did not start"
    return z


def both(zygote, argv, cwd, timeout=300):
    """(fork server, real process) results of one command, run in two copies of ``cwd``'s
    content (``cwd/fork``, ``cwd/real``) when ``cwd`` is a fresh folder."""
    argv = [str(a) for a in argv]
    return (zygote.run(argv, cwd[0], timeout), subprocess.run(argv, capture_output=True, text=True, cwd=cwd[1],
                                                              timeout=timeout))


def same(a: subprocess.CompletedProcess, b: subprocess.CompletedProcess) -> None:
    assert (a.args, a.returncode, a.stdout, a.stderr) == (b.args, b.returncode, b.stdout, b.stderr)


def folders(tmp_path):
    (tmp_path / "fork").mkdir()
    (tmp_path / "real").mkdir()
    return tmp_path / "fork", tmp_path / "real"


def files(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("args", [
    ["info", MODELS / "rs25_ambient.toml"],
    ["info", "nope.toml"],                          # refused: exit 2 and one line
    ["--help"],
    ["bogus"],                                      # an unknown subcommand
    ["freqresp", MODELS / "rs25_ambient.toml", "--linear", "--freq-hz", "0.5,2,7", "--json", "out.json"],
    ["masv", "--help"],                             # the other console script, through the same zygote
], ids=["info", "refused", "help", "unknown", "freqresp-json", "masv-help"])
def test_a_command_through_the_fork_server_is_the_real_process(zygote, tmp_path, args):
    cwd = folders(tmp_path)
    argv = [str(Path(TAOS).with_name("masv")), *args[1:]] if args[0] == "masv" else [TAOS, *args]
    a, b = both(zygote, argv, cwd)
    same(a, b)
    assert files(cwd[0]) == files(cwd[1])
    if args[-1] == "nope.toml":
        assert a.returncode == 2 and len(a.stderr.splitlines()) == 1
    if args[0] == "freqresp":
        assert a.returncode == 0 and json.loads((cwd[0] / "out.json").read_text())


PROBE = '''
import json, os, signal, sys, threading, warnings
from taos.cli import build_parser, main
build_parser()   # the command modules, as main() imports them before a command runs
def name(h):
    return getattr(h, "__qualname__", repr(h)) if callable(h) else repr(h)
def fd(n):
    try:
        t = os.readlink(f"/proc/self/fd/{n}")
    except OSError:
        return "?"
    return t.split("[")[0]
print(json.dumps({
    "argv": sys.argv, "path": sys.path, "cwd": os.getcwd(), "umask": os.umask(0o22), "env": dict(os.environ),
    "signals": {str(int(s)): name(signal.getsignal(s)) for s in signal.valid_signals()},
    "blocked": sorted(int(s) for s in signal.pthread_sigmask(signal.SIG_BLOCK, [])),
    "fds": {n: fd(n) for n in sorted(os.listdir("/proc/self/fd"), key=int)},
    "threads": [t.name for t in threading.enumerate()],
    "warnings": [str(f) for f in warnings.filters],
    "stdio": [[s.encoding, s.errors, s.line_buffering, s.write_through, s.seekable(), s.isatty(), s.fileno(),
               type(s.buffer).__name__] for s in (sys.stdin, sys.stdout, sys.stderr)],
    "main": [__name__, globals().get("__file__"), getattr(__loader__, "__name__", type(__loader__).__name__),
             sorted(k for k in globals() if k.startswith("__"))],
    "process": [os.getpgrp(), os.getsid(0), str(sys.flags), sys.dont_write_bytecode, sys.getrecursionlimit()],
}))
'''


def script(folder: Path, body: str, name: str = "taos") -> str:
    """A Python script named like the console script (its start-up signal handlers installed)."""
    folder.mkdir(exist_ok=True)
    p = folder / name
    p.write_text(f"#!{_forkserver._interpreter(TAOS)}\n{body}")
    p.chmod(0o755)
    return str(p)


def test_a_command_starts_in_the_state_of_a_new_process(zygote, tmp_path):
    exe = script(tmp_path / "bin", PROBE)
    a, b = both(zygote, [exe, "x"], (tmp_path, tmp_path))
    same(a, b)
    state = json.loads(a.stdout)
    stop = "_startup_signals.<locals>.stop"   # Ctrl-C / SIGTERM during start-up: the one-line message
    assert stop in state["signals"]["15"]
    # SIGINT too, unless this test process was handed it ignored (a background job without job
    # control), which a new process inherits and keeps
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        assert state["signals"]["2"] == "<Handlers.SIG_IGN: 1>"
    else:
        assert stop in state["signals"]["2"]
    assert state["threads"] == ["MainThread"]
    assert set(state["fds"]) <= {"0", "1", "2", "3"}   # 3: the listing's own descriptor


def test_python_c_starts_in_the_state_of_a_new_python_c(zygote, tmp_path):
    """``python -c CODE ARGS`` (the fmpy and slow-write children of test_fmu.py and
    test_output_safety.py): argv ``['-c', ARGS]``, ``sys.path[0]`` the empty string, the
    interpreter's own signal handlers (no console script's), no ``__file__``."""
    argv = [sys.executable, "-c", PROBE, "x", "y"]
    a, b = zygote.run(argv, tmp_path, 300), subprocess.run(argv, capture_output=True, text=True, cwd=tmp_path)
    same(a, b)
    state = json.loads(a.stdout)
    assert state["argv"] == ["-c", "x", "y"] and state["path"][0] == "" and state["main"][1] is None
    assert not any("_startup_signals" in h for h in state["signals"].values())
    assert state["threads"] == ["MainThread"]
    z, why = _forkserver._zygote_for(argv, tmp_path)
    assert z is zygote and why is None


def test_python_m_starts_in_the_state_of_a_new_python_m(zygote, tmp_path):
    """``python -m MODULE ARGS`` of a plain module of the working folder: argv ``[its file,
    ARGS]``, ``sys.path[0]`` the folder, runpy's ``__main__`` (``__file__``, its loader), the
    interpreter's own signal handlers (the module is no ``taos`` command line)."""
    (tmp_path / "probe_m.py").write_text(PROBE)
    argv = [sys.executable, "-m", "probe_m", "x"]
    a, b = zygote.run(argv, tmp_path, 300), subprocess.run(argv, capture_output=True, text=True, cwd=tmp_path)
    same(a, b)
    state = json.loads(a.stdout)
    assert state["argv"] == [str(tmp_path / "probe_m.py"), "x"] and state["path"][0] == str(tmp_path)
    assert state["main"][:2] == ["__main__", str(tmp_path / "probe_m.py")]
    assert not any("_startup_signals" in h for h in state["signals"].values())
    assert state["threads"] == ["MainThread"]
    assert _forkserver._zygote_for(argv, tmp_path) == (zygote, None)


@pytest.mark.parametrize("args", [
    ["taos", "--help"],
    ["taos", "info", "nope.toml"],                  # refused: exit 2 and one line
    ["taos", "freqresp", MODELS / "rs25_ambient.toml", "--linear", "--freq-hz", "0.5,7", "--json", "out.json"],
    ["masv.cli", "coupling", "nope.toml"],
], ids=["help", "refused", "freqresp-json", "masv-cli"])
def test_python_m_of_the_package_through_the_fork_server_is_the_real_process(zygote, tmp_path, args):
    """``python -m taos``/``python -m masv.cli``: the start-up handlers installed as importing
    taos installs them under ``-m`` (one line, the program named ``taos``), the same output."""
    cwd = folders(tmp_path)
    argv = [sys.executable, "-m", *map(str, args)]
    assert _forkserver._zygote_for(argv, cwd[0]) == (zygote, None)
    a, b = both(zygote, argv, cwd)
    same(a, b)
    assert files(cwd[0]) == files(cwd[1])
    assert a.returncode == (0 if args[-1] in ("--help", "out.json") else 2)


def test_python_m_the_fork_server_refuses(zygote, tmp_path):
    """A module a new process would find elsewhere, or that runpy would find imported already."""
    z = zygote
    assert _forkserver.module_refused("taos", tmp_path, z.info()) is None
    assert "imported" in _forkserver.module_refused("taos.model", tmp_path, z.info())   # runpy would warn
    assert _forkserver.module_refused("nothere", tmp_path, z.info())                   # no nothere.py
    (tmp_path / "os.py").write_text("print('mine')\n")                                 # frozen: never this file
    (tmp_path / "json.py").write_text("print('mine')\n")
    assert _forkserver.module_refused("os", tmp_path, z.info())
    assert ("json" in z.info()["modules"]) == bool(_forkserver.module_refused("json", tmp_path, z.info()))
    assert _forkserver.folder_refused(tmp_path, z.info()) is None
    assert _forkserver.folder_refused(os.path.dirname(z.info()["packages"]["taos"]), z.info()) is None
    (tmp_path / "taos").mkdir()                                                         # another taos first
    assert "another taos" in _forkserver.folder_refused(tmp_path, z.info())
    z2, why = _forkserver._zygote_for([sys.executable, "-c", "pass"], tmp_path)
    assert z2 is None and "another taos" in why


def test_a_command_with_its_own_environment_runs_in_a_zygote_of_that_environment(zygote, tmp_path):
    """``run(..., env=E)``/``popen``: a zygote started with E (kept for the next command with E,
    the test process's own zygote untouched), the child as a new process with E starts."""
    exe = script(tmp_path / "bin", PROBE)
    env = {**os.environ, "TAOS_TEST_SIDE": "1", "PYTEST_CURRENT_TEST": "side"}
    starts = _forkserver.STATS.get("side zygotes", 0)
    a = _forkserver.run([exe, "x"], tmp_path, env=env)
    same(a, subprocess.run([exe, "x"], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300))
    assert json.loads(a.stdout)["env"]["TAOS_TEST_SIDE"] == "1"
    side = _forkserver._side.z
    argv = [sys.executable, "-c", "import os; print(os.environ['PYTEST_CURRENT_TEST'], os.environ['TAOS_TEST_SIDE'])"]
    p = _forkserver.popen(argv, tmp_path, env={**env, "PYTEST_CURRENT_TEST": "again"})
    assert isinstance(p, _forkserver_io.Child) and p.wait(60) == 0 and p.stdout.read() == "again 1\n"
    p.stdout.close()
    p.stderr.close()
    assert _forkserver._side.z is side and _forkserver.STATS["side zygotes"] == starts + 1
    assert _forkserver.zygote(TAOS) is zygote and "TAOS_TEST_SIDE" not in zygote.env
    assert _forkserver._zygote_for([exe], tmp_path, dict(os.environ)) == (zygote, None)   # the own environment
    _forkserver.end_side()   # (the test process's own zygote goes on)
    assert side.proc.returncode == 0 and _forkserver._side is None and zygote.alive()


@pytest.mark.parametrize("mode", ["script", "python -c", "python -m"])
@pytest.mark.parametrize("body, code", [
    ("import os\nos.abort()\n", -6),
    ("import os, signal\nos.kill(os.getpid(), signal.SIGKILL)\n", -9),
    ("import sys\nprint('out')\nsys.exit('a message to standard error')\n", 1),
    ("print('out')\ndef f():\n    raise ValueError('uncaught')\nf()\n", 1),
    ("import sys\nsys.stdout.write('no newline')\nsys.exit(7)\n", 7),
], ids=["abort", "killed", "exit-text", "traceback", "exit-7"])
def test_a_crash_is_reported_as_subprocess_run_reports_it(zygote, tmp_path, body, code, mode):
    argv = [script(tmp_path / "bin", body)] if mode == "script" else [sys.executable, "-c", body]
    if mode == "python -m":   # a traceback through runpy's frames, as the interpreter's
        (tmp_path / "crash_m.py").write_text(body)
        argv = [sys.executable, "-m", "crash_m"]
    a, b = both(zygote, argv, (tmp_path, tmp_path))
    same(a, b)
    assert a.returncode == code


def test_a_timeout_kills_the_command_as_subprocess_run_does(zygote, tmp_path):
    exe = script(tmp_path / "bin", "import sys, time\nprint('started', flush=True)\ntime.sleep(120)\n")
    got = []
    for run in (lambda: zygote.run([exe], tmp_path, 1.0),
                lambda: subprocess.run([exe], capture_output=True, text=True, cwd=tmp_path, timeout=1.0)):
        with pytest.raises(subprocess.TimeoutExpired) as e:
            run()
        got.append((e.value.cmd, e.value.timeout, e.value.stdout, e.value.stderr, str(e.value)))
    assert got[0] == got[1]
    assert got[0][2] == b"started\n"


#: prints a line, then waits: SIGINT ends it with 130 (its handler), SIGTERM with the default
WAITER = """
import signal, sys, time
signal.signal(signal.SIGINT, lambda s, f: sys.exit(130))
print("started", sys.argv[1:], flush=True)
sys.stderr.write("to stderr\\n")
time.sleep(120)
"""


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, -15), (signal.SIGINT, 130), (signal.SIGKILL, -9)],
                         ids=["SIGTERM", "SIGINT", "SIGKILL"])
def test_a_forked_child_behaves_as_subprocess_popen(zygote, tmp_path, sig, code):
    """:func:`tests._forkserver.popen` (the slow-write children of test_output_safety.py): a line
    read as it is printed, ``poll`` None while it runs, ``wait`` with a timeout raising
    ``TimeoutExpired`` as Popen's, a signal's exit status, the rest of standard error after it."""
    argv = [sys.executable, "-c", WAITER, "a"]
    got = []
    for p in (zygote.popen(argv, tmp_path),
              subprocess.Popen(argv, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)):
        line = p.stdout.readline()
        assert p.poll() is None
        with pytest.raises(subprocess.TimeoutExpired) as e:
            p.wait(0.2)
        p.send_signal(sig)
        rc = p.wait(60)
        got.append((line, str(e.value), rc, p.returncode, p.poll(), p.stderr.read(), p.stdout.read(), p.args))
        p.stdout.close()
        p.stderr.close()
    assert got[0] == got[1]
    assert got[0][:3] == ("started ['a']\n", f"Command '{argv}' timed out after 0.2 seconds", code)
    assert isinstance(zygote.popen([sys.executable, "-c", "pass"], tmp_path), _forkserver_io.Child)


def test_what_the_fork_server_refuses_runs_as_a_real_process(monkeypatch, tmp_path):
    monkeypatch.delenv("TAOS_TEST_NO_FORKSERVER", raising=False)
    assert _forkserver.eligible(TAOS, tmp_path) is None
    assert "masv" not in str(_forkserver.eligible(str(Path(TAOS).with_name("masv")), tmp_path))
    assert "console script" in _forkserver.eligible(sys.executable, tmp_path)
    other = "/usr/bin/python3"   # python -c with another interpreter than the zygote's
    if os.path.exists(other) and os.path.realpath(other) != os.path.realpath(sys.executable):
        z, why = _forkserver._zygote_for([other, "-c", "pass"], tmp_path)
        assert z is None and why
    (tmp_path / ".numba_config.yaml").write_text("")
    assert ".numba_config.yaml" in _forkserver.eligible(TAOS, tmp_path)
    monkeypatch.setenv("TAOS_TEST_NO_FORKSERVER", "1")
    assert "TAOS_TEST_NO_FORKSERVER" in _forkserver.eligible(TAOS, os.getcwd())


def test_a_changed_environment_restarts_the_fork_server(zygote, monkeypatch, tmp_path):
    """A key outside the allowed one (read at import by the preloaded modules, as numba reads
    ``NUMBA_OPT``) starts a zygote with the new environment; the allowed key is set in the child."""
    exe = script(tmp_path / "bin", "import os\nprint(os.environ.get('NUMBA_OPT'), os.environ['PYTEST_CURRENT_TEST'])\n")
    monkeypatch.delenv("TAOS_TEST_NO_FORKSERVER", raising=False)   # (the suite run the old way)
    first = _forkserver.zygote(TAOS)
    monkeypatch.setenv("PYTEST_CURRENT_TEST", "another")
    assert _forkserver.env_change() == []
    monkeypatch.setenv("NUMBA_OPT", "0")
    assert _forkserver.env_change() == ["NUMBA_OPT"]
    restarts = _forkserver.STATS.get("restarts", 0)
    a = _forkserver.run([exe], tmp_path)
    same(a, subprocess.run([exe], capture_output=True, text=True, cwd=tmp_path, timeout=300))
    assert a.stdout == "0 another\n"
    assert _forkserver.STATS["restarts"] == restarts + 1 and _forkserver.zygote(TAOS) is not first
    assert first.proc.returncode == 0   # the old zygote ended
    monkeypatch.undo()
    _forkserver.shutdown(final=False)   # the next command starts one with the test process's environment


def test_the_fork_server_ends_with_its_caller_and_leaves_no_child(tmp_path):
    z = _forkserver_io._Zygote(TAOS)
    exe = script(tmp_path / "bin", "print('ok')\n")
    assert z.run([exe], tmp_path, 300).stdout == "ok\n"
    z.close()
    assert z.proc.returncode == 0, z.log
