"""Start-up CPU of each ``taos`` command and of a Dask worker: what a process spends importing
before its first computation (CPU seconds, user + system, of a fresh interpreter).

Each command's import path is the ``taos`` parser (every command module, as ``taos CMD`` builds
it) plus the modules its ``run`` imports before computing (``taos/cli/*.py``); ``worker`` is
a Monte Carlo Dask worker: :func:`taos.montecarlo.engine.run_task` and the unpickled run kind
(:class:`taos.montecarlo.run.FlightRuns`, which imports :mod:`taos.montecarlo.campaign`).
``taos --help`` and ``taos info`` are run for real. Peers (fixed, for comparing runs taken at
different machine loads): ``python -c pass`` and ``python -c "import numpy, scipy"``.

    .venv/bin/python benchmarks/bench_startup.py [--repeat 7] [--only lco,worker]

Prints, per case, the median and minimum CPU over the repeats and the heavy packages the process
had loaded. The previous import set cannot run in the same process: compare against a run of
this script at the previous commit (``git stash`` / a worktree), with the peers as the yardstick.
Needs the .pyc written (``make .venv/.pyc``) so that no case pays bytecode compilation.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys

HEAVY = ("numba", "scipy.signal", "scipy.stats", "scipy.optimize", "scipy.interpolate", "scipy.linalg",
         "scipy.sparse", "h5py", "pint", "matplotlib", "plotly", "dask", "distributed", "casadi", "pinocchio",
         "meshcat", "xarray", "zarr", "tqdm")

#: command -> modules its ``run`` imports before computing (after the parser is built)
PATHS = {
    "freqresp": ["taos.model", "taos.planar.freqresp", "taos.planar.envelope", "taos.bounds", "taos.results"],
    "simulate": ["taos.model", "taos.planar.simulate", "taos.identify.replay", "taos.planar.envelope"],
    "greenrun": ["taos.model", "taos.report.analysis"],
    "fit": ["taos.identify.fit", "taos.identify.data", "taos.model"],
    "lco": ["taos.flight.vehicle", "taos.flight.lco", "taos.model", "taos.units"],
    "lco-map": ["taos.flight.lco_map", "taos.flight.lco_campaign", "taos.montecarlo.inputs"],
    "sweep": ["taos.montecarlo.sweep", "taos.montecarlo.sweep_define", "taos.montecarlo.sweep_metrics"],
    "montecarlo": ["taos.montecarlo.campaign", "taos.montecarlo.executor"],
    "ascent": ["taos.flight.ascent", "taos.flight.ascent_sim", "taos.flight.lco", "taos.model"],
}

PROBE = """
import json, sys
{body}
print(json.dumps([m for m in {heavy!r} if m in sys.modules]))
"""


def _case_code(name: str) -> str:
    if name == "pass":
        return ""
    if name == "numpy+scipy":
        return "import numpy, scipy"
    if name == "help":
        return ("import contextlib, io\nfrom taos.cli import main\n"
                "with contextlib.redirect_stdout(io.StringIO()):\n    try:\n        main(['--help'])\n"
                "    except SystemExit:\n        pass")
    if name == "info":
        return ("import contextlib, io\nfrom taos.cli import main\n"
                "with contextlib.redirect_stdout(io.StringIO()):\n    main(['info', 'rs25_hotfire'])")
    if name == "worker":   # a Dask worker: the task function, then the unpickled run kind
        return "import taos.montecarlo.engine\nimport taos.montecarlo.run"
    mods = "\n".join(f"import {m}" for m in PATHS[name])
    return f"from taos.cli import build_parser\nbuild_parser()\n{mods}"


def measure(name: str, repeat: int) -> dict:
    """CPU seconds (user + sys) of ``repeat`` fresh interpreters running case ``name``."""
    code = PROBE.format(body=_case_code(name), heavy=HEAVY)
    cpu, loaded = [], []
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=dict(os.environ))
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if r.returncode != 0:
            raise RuntimeError(f"{name}: {r.stderr[-2000:]}")
        cpu.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        loaded = json.loads(r.stdout.strip().splitlines()[-1])
    return {"median_s": statistics.median(cpu), "min_s": min(cpu), "loaded": loaded}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--only", default="", help="comma-separated cases (default: all)")
    args = ap.parse_args()
    cases = ["pass", "numpy+scipy", "help", "info", *PATHS, "worker"]
    if args.only:
        cases = [c for c in cases if c in args.only.split(",")]
    print(f"load {os.getloadavg()[0]:.2f}; CPU s over {args.repeat} runs")
    for c in cases:
        m = measure(c, args.repeat)
        print(f"{c:12s} median {m['median_s']:6.3f}  min {m['min_s']:6.3f}  {' '.join(m['loaded'])}", flush=True)


if __name__ == "__main__":
    main()
