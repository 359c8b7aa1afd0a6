"""The end of a ``taos`` command: the interpreter's own exit (``sys.exit(main())``, the previous
console script) against :func:`taos.cli._exit.exit_process` (the console script now: the same
steps without releasing the loaded modules), the same command in the same run, alternating.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_exit.py [--repeat 5]

Two ways a command starts, each measured: a new process (``python -c``: CPU of the waited-for
child, user + system) and a child forked from a process that has imported what ``taos`` imports
(the test suite's fork server, ``tests/_forkserver.py``: there the release of the modules also
copies the parent's memory pages it writes to). Commands: ``taos simulate`` of the shipped
hot-fire model's step profile, and ``taos fit`` of the shipped hot-fire record (load stiffness
free), whose CasADi and scipy.optimize add to what the exit releases. Prints the median CPU
seconds a command of each kind and the difference.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _commands(out: Path) -> dict[str, list[str]]:
    m = ROOT / "models"
    return {
        "simulate": ["simulate", str(m / "rs25_hotfire.toml"), "--profile", str(m / "profiles/step_pitch.toml"),
                     "--out", str(out / "sim.h5"), "--force"],
        "fit": ["fit", str(m / "data/greenrun_hotfire_synthetic.csv"), "--model", str(m / "rs25_hotfire.toml"),
                "--free", "load_stiffness", "--out", str(out / "fit"), "--force"],
    }


def _code(args: list[str], how: str) -> str:
    if how == "sys.exit":
        return f"import sys; from taos.cli import main; sys.exit(main({args!r}))"
    return f"from taos.cli import main; from taos.cli._exit import exit_process; exit_process(main({args!r}))"


def _new_process(code: str) -> float:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit(f"bench_exit: the command failed: {r.stderr.strip()[-300:]}")
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def _forked(fs, code: str) -> float:
    fs.STATS.pop("child_cpu_s", None)
    r = fs.run([sys.executable, "-c", code], cwd=ROOT)
    if r.returncode != 0:
        raise SystemExit(f"bench_exit: the command failed: {r.stderr.strip()[-300:]}")
    return fs.STATS.get("child_cpu_s", 0.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    opts = ap.parse_args()
    from tests import _forkserver as fs

    with tempfile.TemporaryDirectory() as tmp:
        cmds = _commands(Path(tmp))
        for args in cmds.values():   # kernels cached, bytecode written, the zygote started
            _new_process(_code(args, "exit_process"))
            _forked(fs, _code(args, "exit_process"))
        print(f"CPU seconds a command, median of {opts.repeat} (load {os.getloadavg()[0]:.2f})")
        print(f"{'command':10s} {'start':13s} {'sys.exit':>9s} {'exit_process':>13s} {'saved':>7s}")
        for name, args in cmds.items():
            for start, run in (("new process", _new_process), ("forked", lambda c: _forked(fs, c))):
                cpu: dict[str, list[float]] = {"sys.exit": [], "exit_process": []}
                for _ in range(opts.repeat):
                    for how in cpu:
                        cpu[how].append(run(_code(args, how)))
                a, b = (statistics.median(cpu[h]) for h in ("sys.exit", "exit_process"))
                print(f"{name:10s} {start:13s} {a:9.3f} {b:13.3f} {a - b:7.3f}")
    fs.shutdown()


if __name__ == "__main__":
    main()
