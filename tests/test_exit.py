"""The ``taos``/``masv`` scripts end through :func:`taos.cli._exit.exit_process`: the
interpreter's exit (``Py_FinalizeEx``: threads joined, atexit callbacks, standard streams
flushed, status 120 when that flush fails) without its release of the loaded modules.

Each case runs a new interpreter twice, once ending with ``sys.exit(status)`` (the reference:
CPython's own exit) and once with ``exit_process(status)``, and requires the same outcome."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

BODY = """
import atexit, ctypes, sys, threading, time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
out = Path(sys.argv[1])
atexit.register(lambda: (out / "atexit").write_text("ran"))
def late():
    time.sleep(0.3)
    (out / "thread").write_text("joined")
threading.Thread(target=late).start()                  # non-daemon: joined before the exit
pool = ThreadPoolExecutor(2)                            # never shut down: its atexit hook stops it
fut = pool.submit(lambda: (time.sleep(0.2), (out / "pool").write_text("done")))
print("python text")                                   # left in sys.stdout's buffer (a pipe)
ctypes.CDLL(None).printf(b"C text\\n")                 # left in the C library's buffer (a pipe)
"""


def _run(tmp_path: Path, end: str, name: str, stdout=subprocess.PIPE) -> tuple[subprocess.CompletedProcess, dict]:
    out = tmp_path / name
    out.mkdir()
    code = textwrap.dedent(BODY) + end
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}   # sys.stdout buffered
    r = subprocess.run([sys.executable, "-c", code, str(out)], cwd=ROOT, stdout=stdout,
                       stderr=subprocess.PIPE, timeout=60, env=env)
    return r, {p.name: p.read_text() for p in sorted(out.iterdir())}


@pytest.mark.parametrize("status", [0, 3, 130])
def test_exit_process_ends_as_sys_exit_does(tmp_path, status):
    ref, ref_files = _run(tmp_path, f"sys.exit({status})\n", "ref")
    new, new_files = _run(tmp_path, f"from taos.cli._exit import exit_process\nexit_process({status})\n", "new")
    assert ref.returncode == new.returncode == status
    assert ref_files == new_files == {"atexit": "ran", "pool": "done", "thread": "joined"}
    # both buffers written out (their order is not part of the exit: CPython's puts C's first)
    assert sorted(ref.stdout.splitlines()) == sorted(new.stdout.splitlines()) == [b"C text", b"python text"]
    assert ref.stderr == new.stderr == b""


def test_a_failed_final_flush_is_status_120_as_in_the_interpreters_exit(tmp_path):
    """Standard output a pipe closed by its reader: the flush fails; CPython reports it and
    exits 120, and so does exit_process (it hands the exit back to the interpreter)."""
    end = "import os; r, w = os.pipe(); os.close(r); os.dup2(w, 1)\n"   # fd 1: a pipe nobody reads
    ref, ref_files = _run(tmp_path, end + "sys.exit(0)\n", "ref")
    new, new_files = _run(tmp_path, end + "from taos.cli._exit import exit_process\nexit_process(0)\n", "new")
    assert ref.returncode == new.returncode == 120
    assert ref_files == new_files == {"atexit": "ran", "pool": "done", "thread": "joined"}
    assert b"Exception ignored" in ref.stderr and b"Exception ignored" in new.stderr


def test_the_installed_scripts_end_through_exit_process():
    """pyproject's console scripts are taos.cli:console and masv.cli:console, and ``python -m
    taos`` ends the same way: each ends with exit_process (a run with bad input: status 2)."""
    import tomllib

    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts == {"taos": "taos.cli:console", "masv": "masv.cli:console"}
    probe = ("import sys, taos.cli._exit as e\n"
             "real = e.exit_process\n"
             "def spy(status):\n"
             "    print('exit_process', status, file=sys.stderr)\n"
             "    real(status)\n"
             "e.exit_process = spy\n"
             "sys.argv = [sys.argv[1], 'simulate', 'no-such-model.toml', '--profile', 'x', '--out', 'y']\n"
             "import runpy; runpy.run_module(sys.argv[0], run_name='__main__')\n")
    for module in ("taos", "masv.cli"):
        r = subprocess.run([sys.executable, "-c", probe, module], cwd=ROOT, capture_output=True, text=True,
                           timeout=120)
        assert r.returncode == 2, (module, r.stderr)
        assert r.stderr.splitlines()[-1] == "exit_process 2", (module, r.stderr)
