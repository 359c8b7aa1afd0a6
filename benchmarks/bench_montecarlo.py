"""Monte Carlo campaign speed and scaling.

    python benchmarks/bench_montecarlo.py [--runs 2000] [--peer-runs 20] [--big-runs 100000] [--out DIR]

1. The peer: ``--peer-runs`` runs of the soft case (models/montecarlo/post_separation.toml, 200 s
   of flight, 1 ms RK4) one after another in this process, no Dask: the one-run cost, and the
   share of it spent in the compiled kernel (taos.planar.dynamics.integrate_samples, timed).
2. The soft campaign, ``--runs`` runs on a LocalCluster of 2 workers, end to end (cluster start-up
   included), as ``taos montecarlo post_separation --runs N --case soft`` runs it.
3. Scaling: ``--big-runs`` runs of models/montecarlo/scaling_short.toml (10 s of flight) on a
   loopback cluster (a scheduler and 2 workers as separate processes), the client being the
   ``taos montecarlo --scheduler`` command in its own process: its wall time and peak resident
   memory (getrusage of that process), and the cost of storing one batch at the start and at the
   end of the full store (O(1) per stored run).
Prints Markdown rows for benchmarks/RESULTS.md, with the machine load (os.getloadavg) at the start
and end: figures taken while other jobs share the cores are pessimistic.
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


def peer(n: int) -> tuple[float, float]:
    """(seconds per run, kernel share) of n soft runs in this process."""
    import taos.planar.dynamics as dyn
    c = load_campaign("post_separation")
    kind, _ = flight_runs(c, "soft", None)
    d = montecarlo_design(c, n + 1)
    kind.run_batch(d.names, d.factors[:1], d.seeds[:1])  # load the compiled kernels
    spent = [0.0]
    orig = dyn.integrate_samples

    def timed(*a):
        t = time.perf_counter()
        try:
            return orig(*a)
        finally:
            spent[0] += time.perf_counter() - t
    dyn.integrate_samples = timed
    try:
        t0 = time.perf_counter()
        kind.run_batch(d.names, d.factors[1:], d.seeds[1:])
        el = time.perf_counter() - t0
    finally:
        dyn.integrate_samples = orig
    return el / n, spent[0] / el


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--peer-runs", type=int, default=20)
    ap.add_argument("--big-runs", type=int, default=100_000)
    ap.add_argument("--skip", default="", help="comma-separated parts to skip: peer,soft,big")
    ap.add_argument("--out", default=None, help="keep the campaigns here (default: a temporary folder)")
    a = ap.parse_args()
    skip = set(a.skip.split(","))
    root = Path(a.out) if a.out else Path(tempfile.mkdtemp(prefix="bench_mc_"))
    root.mkdir(parents=True, exist_ok=True)
    load0 = os.getloadavg()
    res: dict = {"cores": os.cpu_count(), "load_start": load0}
    if "peer" not in skip:
        per_run, share = peer(a.peer_runs)
        res["peer"] = {"runs": a.peer_runs, "s_per_run": per_run, "kernel_share": share}
        print(f"peer: {per_run:.3f} s per run, kernel {100 * share:.0f} %", flush=True)
    if "soft" not in skip:
        out = root / "soft"
        shutil.rmtree(out, ignore_errors=True)
        t0 = time.perf_counter()
        r = run_campaign(load_campaign("post_separation"), out, runs=a.runs, case="soft", workers=2, progress=True)
        el = time.perf_counter() - t0
        s = r.summary
        res["soft"] = {"runs": a.runs, "wall_s": el, "batch": json.loads((out / "summary.json").read_text())["timing"]
                       ["batch"], "lco_fraction": s["lco_fraction"], "runs_ok": s["runs_ok"],
                       "runs_failed": s["runs_failed"], "runs_diverged": s["runs_diverged"]}
        print(f"soft: {a.runs} runs in {el:.1f} s", flush=True)
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
        print(f"| one soft run in-process (peer) | {p['runs']} | 1 | {p['s_per_run']:.3f} s/run | kernel "
              f"{100 * p['kernel_share']:.0f} % |")
    if "soft" in res:
        s = res["soft"]
        f = s["lco_fraction"]
        print(f"| soft campaign, LocalCluster 2 workers, end to end | {s['runs']} | 2 | {s['wall_s']:.1f} s | batch "
              f"{s['batch']}; LCO {f['lco_runs']}/{s['runs_ok']} ok, {s['runs_failed']} failed, "
              f"{s['runs_diverged']} diverged |")
    if "big" in res:
        b = res["big"]
        print(f"| scaling_short, loopback cluster 2 workers, client in its own process | {b['runs']} | 2 | "
              f"{b['wall_s']:.1f} s | client peak RSS {b['client_peak_rss_MiB']:.0f} MiB; store "
              f"{b['store_MiB']:.0f} MiB; batch of {b['batch']} stored in {1e3 * b['store_first_batch_s']:.0f} ms "
              f"(first) / {1e3 * b['store_last_batch_s']:.0f} ms (last) |")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
