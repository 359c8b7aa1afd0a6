"""First-use compile time of the kernels `make demo` needs (what a fresh clone pays).

Runs in a child interpreter with an empty numba cache (NUMBA_CACHE_DIR in a temporary
folder): load the hot-fire model, then the first `simulate_taos` (3-D time-domain kernel) and
the first `taos_freqresp` sine dwell (3-D parallel dwell kernel). Peer: the plain
interpreter's own start-up, in the same run.

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
t0 = time.perf_counter()
from taos.model import load_model
from taos.profiles import SineDwell
from taos.taos3d import simulate_taos, taos_freqresp, taos_model
tm = taos_model(load_model("rs25_hotfire"))
t1 = time.perf_counter()
simulate_taos(tm, SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01)
t2 = time.perf_counter()
taos_freqresp(tm, [10.0], math.radians(0.4))
t3 = time.perf_counter()
print(f"| load the model | {t1 - t0:.1f} |")
print(f"| first simulate_taos (3-D time-domain kernel) | {t2 - t1:.1f} |")
print(f"| first taos_freqresp (3-D sine-dwell kernel) | {t3 - t2:.1f} |")
"""


def main() -> None:
    print(f"load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores\n")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    print(f"| step (empty numba cache) | wall [s] |\n|---|---|\n| python -c pass (peer) | {time.perf_counter() - t0:.2f} |")
    with tempfile.TemporaryDirectory() as cache:
        subprocess.run([sys.executable, "-c", CHILD], check=True, env=dict(os.environ, NUMBA_CACHE_DIR=cache))


if __name__ == "__main__":
    main()
