"""Time the Green Run report's figures (matplotlib PNGs and plotly divs), one by one.

Runs ``greenrun`` once on a short profile (two 3-cycle dwells, no report folder), then renders
each figure of :mod:`taos.report.html` ``REPEAT`` times and prints the best and median CPU
time [s] per figure, and of ``render_html`` as a whole. With ``--png DIR`` also writes the
four PNGs there (to look at them).

``--fresh N``: what a ``taos greenrun`` process pays, N times: in a new process each, the run
and its summary, then the FIRST ``_static_figures``, ``_interactive_figures`` and
``render_html`` (each in its own process: the plotting libraries' imports, first figures and
the garbage collector's full scans of a fresh process included), and a whole ``taos greenrun``
process on the short profile (user + system CPU [s]). ``--baseline DIR``: the same rows for
the source tree DIR (e.g. ``git worktree add /tmp/base <commit>``, or a copy of ``taos`` and
``models`` with older files), each fresh process of the tree under test followed by the same
one of DIR, so that a change of machine load hits both alike; best and median per row.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_report_figs.py [--repeat 5] [--png DIR]
    PYTHONPATH=. .venv/bin/python benchmarks/bench_report_figs.py --fresh 5 [--baseline DIR]
"""

from __future__ import annotations

import argparse
import base64
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PROFILE = """name = "short"
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


def _time(fn, repeat: int) -> tuple[float, float, object]:
    ts, out = [], None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        ts.append(time.process_time() - t0)
    return min(ts), statistics.median(ts), out


#: one fresh process: the run and its summary untimed, then the first call of one function [CPU s]
_FIRST = """import sys, time
from taos.report import html as rh
from taos.report.analysis import greenrun
res = greenrun("models/rs25_ambient.toml", sys.argv[1]); s = res.summary()
fn = {"static": lambda: rh._static_figures(res), "interactive": lambda: rh._interactive_figures(res),
      "render_html": lambda: rh.render_html(res, s)}[sys.argv[2]]
t0 = time.process_time(); fn(); print(time.process_time() - t0)
"""


def _fresh_row(tree: Path, what: str, prof: Path, out: Path) -> float:
    """CPU [s] of one fresh-process measurement ``what`` with the sources of ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    if what == "greenrun process":
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, "-m", "taos", "greenrun", "models/rs25_ambient.toml", "--profile", str(prof),
                        "--out", str(out), "--quiet"], cwd=tree, env=env, check=True, capture_output=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    r = subprocess.run([sys.executable, "-c", _FIRST, str(prof), what], cwd=tree, env=env, check=True,
                       capture_output=True, text=True)
    return float(r.stdout.split()[-1])


def fresh(n: int, baseline: str | None) -> None:
    """The ``--fresh`` rows (module docstring), interleaved with ``baseline``'s when given."""
    trees = {"this tree": Path.cwd()}
    if baseline:
        trees["baseline"] = Path(baseline).resolve()
    rows = ("static", "interactive", "render_html", "greenrun process")
    got = {(w, k): [] for w in rows for k in trees}
    with tempfile.TemporaryDirectory() as d:
        prof = Path(d) / "short.toml"
        prof.write_text(PROFILE)
        for _ in range(n):
            for w in rows:
                for k, tree in trees.items():
                    got[w, k].append(_fresh_row(tree, w, prof, Path(d) / "out"))
    print(f"first call in a fresh process, CPU [s], {n} processes each")
    print(f"{'row':20s} {'tree':10s} {'best':>7s} {'median':>7s}")
    for (w, k), ts in got.items():
        print(f"{w:20s} {k:10s} {min(ts):7.3f} {statistics.median(ts):7.3f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--png", default=None, help="folder for the four PNGs")
    ap.add_argument("--fresh", type=int, default=0, help="fresh-process rows, this many processes each")
    ap.add_argument("--baseline", default=None, help="source tree to compare with (--fresh)")
    a = ap.parse_args()
    if a.fresh:
        fresh(a.fresh, a.baseline)
        return

    from taos.report import html as rh
    from taos.report.analysis import greenrun
    from taos.plotting import bode, timehist, interactive as ia

    with tempfile.TemporaryDirectory() as d:
        prof = Path(d) / "short.toml"
        prof.write_text(PROFILE)
        res = greenrun("models/rs25_ambient.toml", prof)
    R = res.model.actuator.moment_arm_m
    th = res.time_history

    def bode_png(ax):
        def f():
            fig = bode.plot_freqresp(
                [res.linear[ax]] + list(res.dwell[ax]), resonance_hz=res.load_resonance_hz[ax],
                notch_hz=res.notch_hz[ax], data=res.run.get(ax), data_label="two-axis run",
                title=rh._bode_title(res, ax))
            rh.decorate_bode(fig, res.spec.get(ax), res.measured, ax, res.linear[ax], R)
            return rh._png(fig)
        return f

    def th_png():
        return rh._png(timehist.plot_timehistory(rh.decimated(th, rh.MAX_PLOT_POINTS), "in", "deg"))

    def zoom_png():
        z = rh.decimated(th, rh.MAX_PLOT_POINTS, t_range_s=(0.0, 4.0))
        return rh._png(timehist.plot_timehistory(z, "in", "deg", t_range_s=(0.0, 4.0),
                                                 title="first 4 s (0.4 deg dwell, stick-slip onset)"))

    jobs = {"bode_pitch": bode_png("pitch"), "bode_yaw": bode_png("yaw"), "timehist": th_png,
            "timehist_zoom": zoom_png,
            "static (4 PNGs)": lambda: rh._static_figures(res),
            "interactive (3 plotly)": lambda: rh._interactive_figures(res),
            "render_html": lambda: rh.render_html(res)}
    jobs["bode_pitch"]()  # imports and font cache outside the timings
    print(f"{'figure':24s} {'best [s]':>9s} {'median [s]':>11s} {'size [kB]':>10s}")
    for name, fn in jobs.items():
        best, med, out = _time(fn, a.repeat)
        size = len(out) / 1e3 if isinstance(out, str) else sum(len(v) for v in out.values()) / 1e3
        print(f"{name:24s} {best:9.3f} {med:11.3f} {size:10.0f}")
        if a.png and name in ("bode_pitch", "bode_yaw", "timehist", "timehist_zoom"):
            Path(a.png).mkdir(parents=True, exist_ok=True)
            (Path(a.png) / f"{name}.png").write_bytes(base64.b64decode(out.split(",", 1)[1]))


if __name__ == "__main__":
    main()
