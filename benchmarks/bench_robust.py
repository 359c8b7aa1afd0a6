#!/usr/bin/env python
"""Benchmark: outputs that scale (issue "No silent wrong answers and no lost files", point 5).

1. An 800 s two-axis Green Run (`taos greenrun`, simplex engine, hot-fire model): size of
   ``index.html`` (target under 15 MB: the 3-D view is capped at 4000 keyframes and the plotted
   traces at 20,000 samples; the HDF5 keeps every recorded sample) and peak memory.
2. `taos estimate` on a ~65 MB CSV vectoring record (the same 800 s run recorded every 1 ms):
   peak memory (target under 400 MB), beside the peer baseline of reading the same file the way
   the loader did before (``numpy.genfromtxt`` over the whole text in memory).

Peak memory and wall time are measured by ``/usr/bin/time -v`` (Debian package ``time``) on
separate processes.

Usage: .venv/bin/python benchmarks/bench_robust.py [--duration 800] [--work DIR]
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PITCH = [(0.4, 0.5), (0.4, 1.0), (0.4, 2.0), (0.4, 4.0), (0.4, 7.0), (0.8, 10.0), (0.8, 14.0)]
YAW = [(0.4, 0.7), (0.4, 1.5), (0.4, 3.0), (0.4, 5.0), (0.8, 8.0), (0.8, 12.0)]


def long_profile(duration_s: float) -> str:
    """Two-axis dwells at the Green Run amplitudes and frequencies, each segment
    ``duration_s / n`` long (whole cycles)."""
    out = [f'name = "Green Run two-axis, {duration_s:g} s (benchmark)"']
    for ax, segs in (("pitch", PITCH), ("yaw", YAW)):
        out += [f"[{ax}]", 'type = "sequence"']
        for a, f in segs:
            cycles = max(1, int(duration_s / len(segs) * f))
            out += [f"[[{ax}.segments]]", 'type = "sine_dwell"', f'amplitude = "{a} deg"',
                    f'frequency = "{f} Hz"', f"cycles = {cycles}"]
    return "\n".join(out) + "\n"


def timed(cmd: list[str], cwd: Path) -> dict:
    """Run ``cmd`` under /usr/bin/time -v; returns peak RSS [MB], wall time [s], return code."""
    r = subprocess.run(["/usr/bin/time", "-v", *cmd], cwd=cwd, capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": str(ROOT)})
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1)) / 1024
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", r.stderr).group(1)
    parts = [float(x) for x in wall.split(":")]
    sec = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
    if r.returncode != 0:
        print(r.stderr[-2000:], file=sys.stderr)
    return {"rss_mb": rss, "wall_s": sec, "rc": r.returncode}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=800.0)
    ap.add_argument("--work", default=None)
    args = ap.parse_args()
    if not Path("/usr/bin/time").exists():
        sys.exit("needs /usr/bin/time (apt-get install time)")
    work = Path(args.work or tempfile.mkdtemp(prefix="bench_robust_"))
    work.mkdir(parents=True, exist_ok=True)
    py = sys.executable
    prof = work / "long.toml"
    prof.write_text(long_profile(args.duration))
    model = str(ROOT / "models" / "rs25_hotfire.toml")

    rep = work / "report"
    g = timed([py, "-m", "taos", "greenrun", model, "--profile", str(prof), "--out", str(rep), "--quiet"], work)
    html_mb = (rep / "index.html").stat().st_size / 1e6
    h5_mb = (rep / "greenrun.h5").stat().st_size / 1e6

    from taos.identify.data import from_time_history
    from taos.model import load_model
    from taos.profiles import load_profile
    from taos.planar.simulate import simulate

    csv = work / "record.csv"
    th = simulate(load_model(model), load_profile(prof), record_every=5)
    from_time_history(th, engine_offset_rad=[0.01, -0.01], condition="hot fire").to_csv(csv, digits=9)
    del th
    csv_mb = csv.stat().st_size / 1e6
    e = timed([py, "-m", "taos", "estimate", str(csv), "--json", str(work / "est.json")], work)
    base = timed([py, "-c", "import io, numpy as np, sys; t = open(sys.argv[1]).read(); "
                  "body = '\\n'.join(l for l in t.splitlines() if not l.startswith('#'))"
                  ".split('\\n', 1)[1]; np.genfromtxt(io.StringIO(body), delimiter=',', ndmin=2)", str(csv)], work)
    skip = 1 + sum(1 for ln in open(csv) if ln.startswith("#"))
    lo = timed([py, "-c", f"import numpy as np, sys; np.loadtxt(sys.argv[1], delimiter=',', skiprows={skip}, "
                "ndmin=2)", str(csv)], work)

    print(f"\n## bench_robust ({args.duration:g} s run, work folder {work})\n")
    print("| job | size | peak memory | wall time | exit |")
    print("|---|---|---|---|---|")
    print(f"| `taos greenrun` {args.duration:g} s, simplex | index.html {html_mb:.1f} MB, greenrun.h5 {h5_mb:.1f} MB "
          f"| {g['rss_mb']:.0f} MB | {g['wall_s']:.0f} s | {g['rc']} |")
    print(f"| `taos estimate` CSV | {csv_mb:.1f} MB | {e['rss_mb']:.0f} MB | {e['wall_s']:.0f} s | {e['rc']} |")
    print(f"| peer: `numpy.genfromtxt` of the whole text (the old loader) | {csv_mb:.1f} MB | {base['rss_mb']:.0f} MB "
          f"| {base['wall_s']:.0f} s | {base['rc']} |")
    print(f"| peer: `numpy.loadtxt` alone (the new loader's reader) | {csv_mb:.1f} MB | {lo['rss_mb']:.0f} MB "
          f"| {lo['wall_s']:.0f} s | {lo['rc']} |")
    ok = g["rc"] == 0 and e["rc"] == 0 and html_mb < 15 and e["rss_mb"] < 400
    print(f"\ntargets (index.html < 15 MB, estimate < 400 MB): {'met' if ok else 'NOT met'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
