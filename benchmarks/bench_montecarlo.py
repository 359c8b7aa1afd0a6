"""Monte Carlo campaign speed and scaling.

    PYTHONPATH=. python benchmarks/bench_montecarlo.py [--runs 2000] [--peer-runs 32] [--big-runs 100000] [--out DIR]
        [--previous TREE]

One command, default parts ``peer,soft`` (add ``--with-big`` for the 100,000-run scaling part):

1. The peer: ``--peer-runs`` runs of the soft case (models/montecarlo/post_separation.toml, 200 s
   of flight, the campaign's integrator: ETDRK4 at 5 ms) as one batch in this process, no Dask:
   the one-run cost (wall and CPU seconds per run), the share of it spent in the compiled kernel
   (taos.planar._explanes.integrate_segments_lanes_exp or taos.planar.dynamics.integrate_segments_lanes,
   timed); the same batch through the RK4 lanes at 1 ms (the previous lockstep path, the campaign
   file's previous integrator and step); and the same runs through the
   previous per-run path (one dense RK4 call per 5 s segment at 1 ms with the plant rebuilt each time,
   ``--legacy-runs``; the tests' reference) for the ratio in the same run. Beside it, the same
   batch with the friction law called lane by lane (an indirect call of the scalar C callback per
   run and stage, the lockstep kernel's friction before the laws' lane form, issue 44 point 4):
   its CPU seconds per run, kernel share, and whether its results equal the lane form's bit for
   bit; then the lane form timed again, in the same warm state, for the comparison (the first
   timed batch pays a first-batch cost the later ones do not). Run from the project root with
   ``PYTHONPATH=.`` (it imports the reference from tests/).
2. The soft campaign, ``--runs`` runs on a LocalCluster of 2 workers, end to end (cluster start-up
   included), as ``taos montecarlo post_separation --runs N --case soft`` runs it; its LCO
   fraction. With ``--previous TREE`` (a checkout of the previous code, e.g. ``git worktree add
   /tmp/prev <base>``), the same campaign flown again by that code in its own process, end to end
   from its import of taos, and its store compared with this code's: array for array, and (the
   integrators differing) statistic by statistic with their sampling errors (LCO fraction with its
   Wilson interval and standard error; mean +- standard error, median and 95th percentile of the
   LCO runs' amplitudes, frequency and peak engine angle) and run by run (the same design rows and
   seeds: LCO flags changed, the largest difference of every output). Both
   report their CPU seconds in all (this process and its ended children: the workers), the
   measure that a shared machine's load does not inflate as it does the wall time.
3. Scaling (``--with-big``): ``--big-runs`` runs of models/montecarlo/scaling_short.toml (10 s of
   flight) on a loopback cluster (a scheduler and 2 workers as separate processes), the client
   being the ``taos montecarlo --scheduler`` command in its own process: its wall time and peak
   resident memory (getrusage of that process), and the cost of storing one batch at the start
   and at the end of the full store (O(1) per stored run).
Prints Markdown rows for benchmarks/RESULTS.md, with the machine load (os.getloadavg) at the start
and end: figures taken while other jobs share the cores are pessimistic. Python byte code is
compiled first (``compileall``, as an ordinary install leaves it): without it every worker
process compiles the sources again when PYTHONDONTWRITEBYTECODE is set.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from taos.montecarlo import load_campaign, run_campaign
from taos.montecarlo import store
from taos.montecarlo.executor import flight_runs, montecarlo_design

BIN = Path(sys.executable).parent
#: the RK4 step of the previous campaign (``dt = "1 ms"``, ``integrator = "rk4"``): the previous paths' step
RK4_DT_S = 1e-3


def _timed(mod, name: str, spent: list):
    """Wrap ``mod.name`` so that the wall and CPU seconds spent in it add up in ``spent[0]`` and
    ``spent[1]``; returns the undo."""
    orig = getattr(mod, name)

    def timed(*a):
        t, c = time.perf_counter(), time.process_time()
        try:
            return orig(*a)
        finally:
            spent[0] += time.perf_counter() - t
            spent[1] += time.process_time() - c
    setattr(mod, name, timed)
    return lambda: setattr(mod, name, orig)


def legacy_run(kind, names, factors, seed) -> float:
    """One soft run through the previous path (issue 26 before the lockstep kernel: a dense RK4
    call per 5 s segment with the plant rebuilt from scratch each time), as the tests' reference
    (tests/test_montecarlo.py::per_segment_reference) flies it."""
    from taos.montecarlo.campaign import apply_factors
    from tests.test_montecarlo import per_segment_reference
    c = kind.campaign
    asc, model, _ = apply_factors(kind.ascent, kind.model, c.cases["soft"], dict(zip(names, map(float, factors))))
    return float(per_segment_reference(asc, model, c.axis, c.start_s, c.start_s + c.duration_s, RK4_DT_S, seed)[-1])


def per_lane_calls(rates):
    """The previous path's friction: a lane form (registry ``LANES_SIG``) that calls the scalar C
    callback ``rates`` once per lane (the callback not inlined: what the lockstep kernel did
    before the laws' lane form)."""
    from numba import cfunc

    from taos.friction.registry import signatures

    def rates_lanes(v, z, t_app, P, dz, tf):
        for q in range(v.shape[0]):
            dz[q], tf[q] = rates(v[q], z[q], t_app[q], P[q])

    return cfunc(signatures()["LANES_SIG"])(rates_lanes)


def _batch(kind, d, spent: list, dyn) -> tuple:
    """Run the batch of design rows 1.. timed: (result, wall s, CPU s); the kernel's (RK4 or
    ETDRK4 lanes) wall and CPU seconds added into ``spent``."""
    import taos.planar._explanes as xl
    undo = [_timed(dyn, "integrate_segments_lanes", spent), _timed(xl, "integrate_segments_lanes_exp", spent)]
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        out = kind.run_batch(d.names, d.factors[1:], d.seeds[1:])
        return out, time.perf_counter() - t0, time.process_time() - c0
    finally:
        for u in undo:
            u()


def peer(n: int, n_legacy: int) -> dict:
    """One-run cost of n soft runs as one batch in this process, the kernel's share, and the
    previous per-run path on the first ``n_legacy`` of them."""
    import taos.planar.dynamics as dyn
    c = load_campaign("post_separation")
    kind, _ = flight_runs(c, "soft", None)
    d = montecarlo_design(c, n + 1)
    from dataclasses import replace

    from taos.friction import registry
    kind.run_batch(d.names, d.factors[:2], d.seeds[:2])  # load the compiled kernels
    spent = [0.0, 0.0]
    got, el, cpu = _batch(kind, d, spent, dyn)
    res = {"runs": n, "s_per_run": el / n, "cpu_s_per_run": cpu / n, "kernel_share": spent[0] / el,
           "kernel_cpu_s_per_run": spent[1] / n, "integrator": c.integrator, "dt_s": c.dt_s}
    # the previous lockstep path: the same batch by the RK4 lanes at the previous campaign step
    rk4 = replace(kind, campaign=replace(c, integrator="rk4", dt_s=RK4_DT_S))
    rk4.run_batch(d.names, d.factors[:2], d.seeds[:2])
    spent = [0.0, 0.0]
    _, el_r, cpu_r = _batch(rk4, d, spent, dyn)
    res.update(rk4_s_per_run=el_r / n, rk4_cpu_s_per_run=cpu_r / n, rk4_kernel_cpu_s_per_run=spent[1] / n)
    law = registry.get(kind.model.friction.name)   # the law the batch flies
    registry._REGISTRY[law.id] = replace(law, rates_lanes=per_lane_calls(law.rates))
    try:
        kind.run_batch(d.names, d.factors[:2], d.seeds[:2])   # compile the per-lane-call form
        spent = [0.0, 0.0]
        prev, el_p, cpu_p = _batch(kind, d, spent, dyn)
    finally:
        registry._REGISTRY[law.id] = law
    # the lane form again, now in the same warm state as the per-lane run: the first timed batch
    # pays a first-batch cost (about 0.003 s CPU a run in the kernel) that the later ones do not,
    # which made the lane-by-lane calls look faster when compared with the first batch
    spent = [0.0, 0.0]
    _, el_a, cpu_a = _batch(kind, d, spent, dyn)
    res.update(again_s_per_run=el_a / n, again_cpu_s_per_run=cpu_a / n, again_kernel_cpu_s_per_run=spent[1] / n)
    same = all(np.array_equal(np.asarray(got[k]), np.asarray(prev[k]), equal_nan=True)
               for k in got if isinstance(got[k], np.ndarray))
    res.update(law=law.id, per_lane_s_per_run=el_p / n, per_lane_cpu_s_per_run=cpu_p / n,
               per_lane_kernel_cpu_s_per_run=spent[1] / n, per_lane_bit_identical=bool(same))
    if n_legacy:
        legacy_run(kind, d.names, d.factors[0], int(d.seeds[0]))
        t0, c0 = time.perf_counter(), time.process_time()
        for i in range(1, n_legacy + 1):
            legacy_run(kind, d.names, d.factors[i], int(d.seeds[i]))
        res.update(legacy_runs=n_legacy, legacy_s_per_run=(time.perf_counter() - t0) / n_legacy,
                   legacy_cpu_s_per_run=(time.process_time() - c0) / n_legacy)
    return res


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def loopback(n: int = 2):
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    procs += [subprocess.Popen([str(BIN / "dask"), "worker", addr, "--nthreads", "1", "--nworkers", "1",
                                "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for _ in range(n)]
    from dask.distributed import Client
    deadline = time.time() + 120
    while True:
        try:
            with Client(addr, timeout="5s") as c:
                c.wait_for_workers(n, timeout=60)
            return addr, procs
        except Exception:
            if time.time() > deadline:
                raise
            time.sleep(0.5)


def stop(procs) -> None:
    """Workers first, then the scheduler; killed if SIGTERM is not enough in 20 s."""
    for q in procs[1:] + procs[:1]:
        if q.poll() is None:
            q.send_signal(signal.SIGTERM)
        try:
            q.wait(timeout=20)
        except subprocess.TimeoutExpired:
            q.kill()
            q.wait()


def big(n: int, root: Path) -> dict:
    addr, procs = loopback()
    out = root / "scaling"
    shutil.rmtree(out, ignore_errors=True)
    try:
        t0 = time.perf_counter()
        p = subprocess.Popen([str(BIN / "taos"), "montecarlo", "scaling_short", "--runs", str(n), "--scheduler", addr,
                              "--out", str(out), "--no-progress"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             text=True)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        text = p.stdout.read()
    finally:
        stop(procs)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(text)
    summary = json.loads((out / "summary.json").read_text())
    spath = out / "campaign.zarr"
    ds = store.open_store(spath)
    b = summary["timing"]["batch"]
    keys = ("status", "error", "cpu", "inputs_sha256", "trace", "lco",
            "amplitude_deg", "engine_amplitude_deg", "frequency_hz", "growth", "peak_engine_deg", "peak_engine_rate_deg_s",
            "peak_attitude_deg")
    cost = []
    for start in (0, (n // b - 1) * b):  # rewrite the first and the last full batch with what it holds
        batch = {k: ds[k].values[start:start + b] for k in keys}
        for k in ("error", "cpu", "inputs_sha256"):
            batch[k] = list(batch[k])
        t = time.perf_counter()
        store.write_batch(spath, start, batch)
        cost.append(time.perf_counter() - t)
    size = sum(f.stat().st_size for f in spath.rglob("*") if f.is_file())
    return {"runs": n, "wall_s": wall, "client_peak_rss_MiB": ru.ru_maxrss / 1024, "batch": b,
            "store_first_batch_s": cost[0], "store_last_batch_s": cost[1], "store_MiB": size / 2 ** 20,
            "runs_ok": summary["statistics"]["runs_ok"], "runs_failed": summary["statistics"]["runs_failed"],
            "runs_diverged": summary["statistics"]["runs_diverged"], "workers": summary["timing"]["workers"]}


def _cpu() -> float:
    """CPU seconds (user + system) of this process and of its children that ended (the cluster's
    workers once it is closed, a subprocess and its own children once it is done)."""
    return sum(getattr(resource.getrusage(w), f) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
               for f in ("ru_utime", "ru_stime"))


_PREVIOUS = """
import json, sys, time
from pathlib import Path
t0 = time.perf_counter()
from taos.montecarlo import load_campaign, run_campaign
r = run_campaign(load_campaign("post_separation"), Path(sys.argv[1]), runs=int(sys.argv[2]), case="soft",
                 workers=int(sys.argv[3]))
print(json.dumps({"wall_s": time.perf_counter() - t0, "taos": __import__("taos").__file__}))
"""


def previous_soft(tree: Path, n: int, root: Path) -> dict:
    """The soft campaign flown by the code in ``tree`` (its own process, ``PYTHONPATH=tree``,
    from the import of taos on: what the campaign costs a user of that code), and whether its
    store holds the same arrays as this code's (``root/soft``)."""
    out = root / "soft_previous"
    shutil.rmtree(out, ignore_errors=True)
    env = dict(os.environ, PYTHONPATH=str(tree.resolve()))
    import compileall
    compileall.compile_dir(str(tree / "taos"), quiet=2, workers=2)
    warm = subprocess.run([sys.executable, "-c", _PREVIOUS, str(root / "warm_previous"), "2", "0"], env=env,
                          capture_output=True, text=True, cwd=str(root))   # its compiled kernels cached first
    if warm.returncode != 0:
        raise RuntimeError(warm.stderr[-2000:])
    t0, c0 = time.perf_counter(), _cpu()
    p = subprocess.run([sys.executable, "-c", _PREVIOUS, str(out), str(n), "2"], env=env, capture_output=True, text=True,
                       cwd=str(root))
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    got = json.loads(p.stdout.strip().splitlines()[-1])
    same = True
    for group in (None, "nominal"):
        a, b = store.open_store(root / "soft" / "campaign.zarr", group), store.open_store(out / "campaign.zarr", group)
        for k in a.data_vars:
            x, y = np.asarray(a[k].values), np.asarray(b[k].values)
            same &= bool(np.array_equal(x, y, equal_nan=x.dtype.kind == "f"))
    return {"runs": n, "wall_s": wall, "cpu_s": cpu, "run_campaign_wall_s": got["wall_s"], "taos": got["taos"],
            "store_equal": same, "statistics": compare_stores(root / "soft" / "campaign.zarr", out / "campaign.zarr")}


STAT_KEYS = ("amplitude_deg", "engine_amplitude_deg", "frequency_hz", "peak_engine_deg")


def _stats(ds) -> dict:
    """A store's statistics and their sampling errors: the LCO fraction (Wilson 95 % interval,
    standard error sqrt(p (1 - p) / n)); per output over the LCO runs, the mean and its standard
    error s / sqrt(n), the median and the 95th percentile."""
    from taos.montecarlo import wilson_interval
    ok = np.asarray(ds["status"].values) == store.STATUS["ok"]
    lco = np.asarray(ds["lco"].values, bool) & ok
    n, k = int(ok.sum()), int(lco.sum())
    p = k / n
    lo, hi = wilson_interval(k, n)
    out = {"runs_ok": n, "lco_runs": k, "lco_fraction": p, "lco_ci95": [lo, hi], "lco_se": float(np.sqrt(p * (1 - p) / n))}
    for key in STAT_KEYS:
        v = np.asarray(ds[key].values, float)[lco]
        out[key] = {"mean": float(v.mean()), "se": float(v.std(ddof=1) / np.sqrt(v.size)),
                    "p50": float(np.median(v)), "p95": float(np.percentile(v, 95))}
    return out


def compare_stores(this: Path, previous: Path) -> dict:
    """Both stores' statistics (:func:`_stats`) and, run by run (the same design rows and seeds),
    how many LCO flags differ and the largest difference of each output."""
    a, b = store.open_store(this), store.open_store(previous)
    paired = {"lco_flags_differ": int(np.sum(np.asarray(a["lco"].values) != np.asarray(b["lco"].values))),
              "status_differ": int(np.sum(np.asarray(a["status"].values) != np.asarray(b["status"].values)))}
    for key in STAT_KEYS + ("peak_engine_rate_deg_s", "peak_attitude_deg", "growth", "trace", "engine_trace"):
        paired[f"max_abs_diff_{key}"] = float(np.nanmax(np.abs(np.asarray(a[key].values, float)
                                                                - np.asarray(b[key].values, float))))
    return {"this": _stats(a), "previous": _stats(b), "paired": paired}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--peer-runs", type=int, default=32)
    ap.add_argument("--legacy-runs", type=int, default=4)
    ap.add_argument("--big-runs", type=int, default=100_000)
    ap.add_argument("--with-big", action="store_true", help="also run the 100,000-run scaling part")
    ap.add_argument("--skip", default="", help="comma-separated parts to skip: peer,soft,big")
    ap.add_argument("--previous", default=None, help="a checkout of the previous code (e.g. the branch base in a "
                    "git worktree): the soft campaign flown again by it, end to end in its own process, for the "
                    "ratio in the same run, and its store compared with this one array for array")
    ap.add_argument("--out", default=None, help="keep the campaigns here (default: a temporary folder)")
    a = ap.parse_args()
    skip = set(a.skip.split(",")) | (set() if a.with_big else {"big"})
    import compileall
    import taos
    for d in {Path(taos.__file__).parent, Path(np.__file__).parent.parent}:
        compileall.compile_dir(str(d), quiet=2, workers=2)
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    root = Path(a.out) if a.out else Path(tempfile.mkdtemp(prefix="bench_mc_"))
    root.mkdir(parents=True, exist_ok=True)
    load0 = os.getloadavg()
    res: dict = {"cores": os.cpu_count(), "load_start": load0}
    if "peer" not in skip:
        res["peer"] = p = peer(a.peer_runs, a.legacy_runs)
        print(f"peer: {p['s_per_run']:.4f} s per run ({p['cpu_s_per_run']:.4f} s CPU), kernel "
              f"{100 * p['kernel_share']:.0f} %; friction per lane: {p['per_lane_cpu_s_per_run']:.4f} s CPU, "
              f"bit-identical {p['per_lane_bit_identical']}", flush=True)
    if "soft" not in skip:
        out = root / "soft"
        shutil.rmtree(out, ignore_errors=True)
        t0, c0 = time.perf_counter(), _cpu()
        r = run_campaign(load_campaign("post_separation"), out, runs=a.runs, case="soft", workers=2, progress=True)
        el, cpu = time.perf_counter() - t0, _cpu() - c0
        s = r.summary
        res["soft"] = {"runs": a.runs, "wall_s": el, "cpu_s": cpu, "batch": json.loads((out / "summary.json").read_text())["timing"]
                       ["batch"], "lco_fraction": s["lco_fraction"], "runs_ok": s["runs_ok"],
                       "runs_failed": s["runs_failed"], "runs_diverged": s["runs_diverged"]}
        print(f"soft: {a.runs} runs in {el:.1f} s", flush=True)
    if a.previous and "soft" not in skip:
        res["soft_previous"] = previous_soft(Path(a.previous), a.runs, root)
        print(f"soft, previous tree: {a.runs} runs in {res['soft_previous']['wall_s']:.1f} s; stores equal "
              f"{res['soft_previous']['store_equal']}", flush=True)
    if "big" not in skip:
        res["big"] = big(a.big_runs, root)
        print(f"big: {res['big']}", flush=True)
    res["load_end"] = os.getloadavg()
    res["bench_peak_rss_MiB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    (root / "bench.json").write_text(json.dumps(res, indent=1, default=float))
    print(json.dumps(res, indent=1, default=float))
    print(f"\nload average at start {load0[0]:.1f}, at end {res['load_end'][0]:.1f} on {os.cpu_count()} cores")
    if "peer" in res:
        p = res["peer"]
        print(f"| one soft run in-process, one batch (peer: {p['integrator']} at {p['dt_s'] * 1e3:g} ms) | {p['runs']} | 1 | "
              f"{p['s_per_run']:.4f} s/run "
              f"({p['cpu_s_per_run']:.4f} s CPU) | kernel {100 * p['kernel_share']:.0f} % of the wall, "
              f"{p['kernel_cpu_s_per_run']:.4f} s CPU per run |")
        print(f"| same batch, RK4 lanes at {RK4_DT_S * 1e3:g} ms (the previous lockstep path) | {p['runs']} | 1 | "
              f"{p['rk4_s_per_run']:.4f} s/run ({p['rk4_cpu_s_per_run']:.4f} s CPU) | kernel "
              f"{p['rk4_kernel_cpu_s_per_run']:.4f} s CPU per run; x{p['rk4_cpu_s_per_run'] / p['cpu_s_per_run']:.2f} "
              f"CPU against the peer |")
        print(f"| same batch, friction law called lane by lane | {p['runs']} | 1 | "
              f"{p['per_lane_s_per_run']:.4f} s/run ({p['per_lane_cpu_s_per_run']:.4f} s CPU) | kernel "
              f"{p['per_lane_kernel_cpu_s_per_run']:.4f} s CPU per run; results bit-identical: "
              f"{p['per_lane_bit_identical']} |")
        print(f"| same batch, lane form again (warm, after the lane-by-lane run) | {p['runs']} | 1 | "
              f"{p['again_s_per_run']:.4f} s/run ({p['again_cpu_s_per_run']:.4f} s CPU) | kernel "
              f"{p['again_kernel_cpu_s_per_run']:.4f} s CPU per run; lane by lane x"
              f"{p['per_lane_kernel_cpu_s_per_run'] / p['again_kernel_cpu_s_per_run']:.2f} of it |")
        if "legacy_runs" in p:
            print(f"| same, previous per-run path (dense RK4 per segment, plant rebuilt) | {p['legacy_runs']} | 1 | "
                  f"{p['legacy_s_per_run']:.4f} s/run ({p['legacy_cpu_s_per_run']:.4f} s CPU) | x"
                  f"{p['legacy_cpu_s_per_run'] / p['cpu_s_per_run']:.2f} CPU against the peer |")
    if "soft" in res:
        s = res["soft"]
        f = s["lco_fraction"]
        print(f"| soft campaign, LocalCluster 2 workers, end to end | {s['runs']} | 2 | {s['wall_s']:.1f} s | "
              f"{s['cpu_s']:.1f} CPU-s in all ({s['cpu_s'] / s['runs']:.4f} a run); batch "
              f"{s['batch']}; LCO {f['lco_runs']} of {s['runs_ok']} ok ({f['value']:.3f}, 95 % {f['ci_low']:.3f}-"
              f"{f['ci_high']:.3f}), {s['runs_failed']} failed, "
              f"{s['runs_diverged']} diverged |")
    if "soft_previous" in res:
        s, q = res["soft"], res["soft_previous"]
        print(f"| same campaign, previous code ({q['taos']}), its own process | {q['runs']} | 2 | {q['wall_s']:.1f} s | "
              f"{q['cpu_s']:.1f} CPU-s in all ({q['cpu_s'] / q['runs']:.4f} a run, x{q['cpu_s'] / s['cpu_s']:.2f} this "
              f"code's); wall x{q['wall_s'] / s['wall_s']:.2f} this code's; stores equal array for array: {q['store_equal']} |")
        st = q["statistics"]
        print("\n| statistic (LCO runs) | this code | previous code | difference / sampling error |\n|---|---|---|---|")
        a, b = st["this"], st["previous"]
        print(f"| LCO fraction | {a['lco_fraction']:.4f} ({a['lco_ci95'][0]:.3f}-{a['lco_ci95'][1]:.3f}) | "
              f"{b['lco_fraction']:.4f} ({b['lco_ci95'][0]:.3f}-{b['lco_ci95'][1]:.3f}) | "
              f"{(a['lco_fraction'] - b['lco_fraction']) / b['lco_se']:.3f} |")
        for key in STAT_KEYS:
            x, y = a[key], b[key]
            print(f"| {key} mean / median / p95 | {x['mean']:.5f} +- {x['se']:.5f} / {x['p50']:.5f} / {x['p95']:.5f} | "
                  f"{y['mean']:.5f} +- {y['se']:.5f} / {y['p50']:.5f} / {y['p95']:.5f} | "
                  f"{(x['mean'] - y['mean']) / y['se']:.2e} |")
        print(f"paired runs: {st['paired']}")
    if "big" in res:
        b = res["big"]
        print(f"| scaling_short, loopback cluster 2 workers, client in its own process | {b['runs']} | 2 | "
              f"{b['wall_s']:.1f} s | client peak RSS {b['client_peak_rss_MiB']:.0f} MiB; store "
              f"{b['store_MiB']:.0f} MiB; batch of {b['batch']} stored in {1e3 * b['store_first_batch_s']:.0f} ms "
              f"(first) / {1e3 * b['store_last_batch_s']:.0f} ms (last) |")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
