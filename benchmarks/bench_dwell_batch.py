"""Benchmark: warm speed of the sine-dwell batches on the threads (RS-25 hot fire), and a
fingerprint of their numbers.

The four dwell batches (ETDRK4 and RK4 settled dwells, shooting, the 3-D model's two-axis
dwells) each run one grid, once to load or compile the kernels, then ``--repeat`` times; the
line of a case gives the best wall time [s], the process CPU time of that repeat [s] and a
SHA-256 prefix of the complex gains (the same prefix before and after a change: the same bits).
Compare two source trees with the same command, alternately, on the same machine:

    .venv/bin/python benchmarks/bench_dwell_batch.py [--repeat 3]
    PYTHONPATH=/other/tree .venv/bin/python /other/tree/benchmarks/bench_dwell_batch.py

(the thread count is numba's: ``NUMBA_NUM_THREADS``, default the number of cores).
"""

from __future__ import annotations

import argparse
import hashlib
import math
import time

import numpy as np

DEG = math.pi / 180
AMPS = np.array([0.05, 0.2, 0.4]) * DEG
FREQ = np.logspace(np.log10(0.5), np.log10(20.0), 8)


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:12]


def cases(model):
    """(name, function of no arguments returning the gains) of each dwell batch."""
    from taos.planar.freqresp import sine_dwell_grid
    from taos.taos3d import taos_freqresp_family, taos_model

    tm = taos_model(model)

    def grid(**kw):
        return lambda: sine_dwell_grid(model, AMPS, FREQ, settle_s=1.0, **kw)

    def family():
        fam = taos_freqresp_family(tm, FREQ[:6], AMPS[1:], settle_s=0.5)
        return tuple(np.concatenate([getattr(f, q) for f in fam]) for q in ("piston", "engine"))

    return [("planar ETDRK4 settled (3 x 8)", grid()),
            ("planar RK4 settled (3 x 8)", grid(integrator="rk4")),
            ("planar shooting (3 x 8)", grid(method="shoot")),
            ("3-D two-axis dwells (2 x 6)", family)]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    import numba

    from taos.model import load_model

    model = load_model("rs25_hotfire")
    print(f"threads {numba.get_num_threads()}, repeat {args.repeat}")
    for name, run in cases(model):
        run()   # load (or compile) the kernels
        best = None
        for _ in range(args.repeat):
            c0, t0 = time.process_time(), time.perf_counter()
            res = run()
            t, c = time.perf_counter() - t0, time.process_time() - c0
            if best is None or t < best[0]:
                best = (t, c)
        print(f"{name:32s} wall {best[0]:7.3f} s  cpu {best[1]:7.3f} s  gains {_digest(*res)}")


if __name__ == "__main__":
    main()
