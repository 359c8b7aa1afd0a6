"""First-use compile time of the kernels `make demo` needs (what a fresh clone pays).

Runs in a child interpreter with an empty numba cache (NUMBA_CACHE_DIR in a temporary
folder): load the hot-fire model, then the first `simulate_taos` (3-D time-domain kernel) and
the first `taos_freqresp` sine dwell (3-D dwell kernel); wall and CPU (process) seconds of
each (on a shared machine compare the CPU). Peer: the plain interpreter's own start-up, in
the same run.

Run:  .venv/bin/python benchmarks/bench_compile.py
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

CHILD = """
import math, time
t = [(time.perf_counter(), time.process_time())]
from taos.model import load_model
from taos.profiles import SineDwell
from taos.taos3d import simulate_taos, taos_freqresp, taos_model
tm = taos_model(load_model("rs25_hotfire"))
t.append((time.perf_counter(), time.process_time()))
simulate_taos(tm, SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01)
t.append((time.perf_counter(), time.process_time()))
taos_freqresp(tm, [10.0], math.radians(0.4))
t.append((time.perf_counter(), time.process_time()))
for k, name in enumerate(("load the model (3-D right-hand side: calibration)",
                          "first simulate_taos (3-D time-domain kernel)", "first taos_freqresp (3-D sine-dwell kernel)")):
    print(f"| {name} | {t[k + 1][0] - t[k][0]:.1f} | {t[k + 1][1] - t[k][1]:.1f} |")
"""


def main() -> None:
    print(f"load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores\n")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    print(f"| step (empty numba cache) | wall [s] | CPU [s] |\n|---|---|---|\n| python -c pass (peer) | "
          f"{time.perf_counter() - t0:.2f} | |")
    with tempfile.TemporaryDirectory() as cache:
        subprocess.run([sys.executable, "-c", CHILD], check=True, env=dict(os.environ, NUMBA_CACHE_DIR=cache))


if __name__ == "__main__":
    main()
