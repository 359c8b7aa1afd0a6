"""Benchmark: the 12-point LCO verdict map (``taos lco --sweep``, time-domain confirmation) end to end.

The map of the issue: rs25_flight.toml (its friction, bounding avionics, default 11 x 10
describing-function grid) in models/flight/core_stage.toml over 4 load stiffnesses x 3 integral
gains (4 TVC variants, so 4 describing-function maps). Each configuration is the console script
in a fresh process (imports and kernel loading included), in the same run, in turn:

* ``predicted``: the confirmation started on the describing function's periodic solution
  (the default);
* ``rest``: the confirmation from rest (0.2 deg attitude error, 300 s, as ``taos lco`` without
  --sweep), the peer;
* ``prediction only``: ``--no-time-domain`` (the map as it was before confirmation).

Wall and CPU (user + system of the child) seconds; the verdicts of the two confirmations are
compared point by point. Run: ``PYTHONPATH=. .venv/bin/python benchmarks/bench_verdict_map.py
[--repeat N]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TAOS = str(Path(sys.executable).parent / "taos")
MAP = ["lco", "models/rs25_flight.toml", "--flight", "models/flight/core_stage.toml",
       "--sweep", "load_stiffness=60000 lbf/in,115000 lbf/in,160000 lbf/in,205000 lbf/in",
       "--sweep", "integral_gain=0.6,0.78,0.9"]
CONFIGS = {"predicted": [], "rest": ["--td-start", "rest"], "prediction only": ["--no-time-domain"]}


def run(extra: list[str], out: Path) -> tuple[float, float, dict]:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([TAOS, *MAP, *extra, "--json", str(out)], cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return wall, cpu, json.loads(out.read_text())["sweep"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=1)
    a = ap.parse_args()
    print("uptime:", os.popen("uptime").read().strip())
    print("PYTHONDONTWRITEBYTECODE:", os.environ.get("PYTHONDONTWRITEBYTECODE", "(unset)"))
    res = {k: [] for k in CONFIGS}
    maps = {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(a.repeat):
            for name, extra in CONFIGS.items():
                wall, cpu, d = run(extra, Path(tmp) / "m.json")
                res[name].append((wall, cpu))
                maps[name] = d
                print(f"  {name:16s} wall {wall:6.1f} s  cpu {cpu:6.1f} s", flush=True)
    print("uptime:", os.popen("uptime").read().strip())
    best = {k: min(v) for k, v in res.items()}
    print(f"\n| configuration | wall [s] (best of {a.repeat}) | CPU [s] | wall vs rest |")
    print("|---|---|---|---|")
    for k, (w, c) in best.items():
        print(f"| {k} | {w:.1f} | {c:.1f} | {best['rest'][0] / w:.2f}x |")
    p, r = maps["predicted"], maps["rest"]
    same = p["lco"] == r["lco"]
    print(f"\nverdicts predicted-start vs from-rest: {'identical' if same else 'DIFFER'}: {p['lco']}")
    td_p, td_r = p["time_domain"], r["time_domain"]
    for key in ("amplitude_deg", "engine_amplitude_deg", "frequency_hz"):
        rel = [abs(x / y - 1) for rx, ry in zip(td_p[key], td_r[key]) for x, y in zip(rx, ry)
               if x is not None and y is not None]
        print(f"  {key}: largest relative difference {max(rel, default=0):.4f} over {len(rel)} cycles")
    print("  simulated seconds per point (predicted start):", td_p["simulated_s"])


if __name__ == "__main__":
    main()
