"""Compile and cache every numba kernel once (``python -m taos.cli.warmup``; run by ``make test``).

The integrator kernels take tens of seconds to compile on a cold cache and are cached on disk
after their first use. ``make demo`` does not warm up: the Green Run compiles just the
kernels it uses. ``make test`` warms every kernel first, so that no test pays a compile.
"""

from __future__ import annotations

import math
import time


def main() -> None:
    from taos.planar.freqresp import sine_dwell_grid
    from taos.model import load_model
    from taos.profiles import SineDwell
    from taos.planar.simulate import simulate

    t0 = time.perf_counter()
    model = load_model("rs25_hotfire")
    simulate(model, SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01)
    sine_dwell_grid(model, [math.radians(0.4)], [10.0], settle_s=0.0, settle_cycles=1, measure_cycles=1)
    # the exponential (ETDRK4) and RK4 dwell kernels, settled and shooting (both integrators'
    # shooting kernel compile together: minutes on a loaded machine if a test paid for it)
    sine_dwell_grid(model, [math.radians(0.4)], [10.0], settle_s=0.0, settle_cycles=1, measure_cycles=1,
                    integrator="rk4")
    sine_dwell_grid(model, [math.radians(0.4)], [10.0], settle_s=0.0, settle_cycles=1, measure_cycles=1,
                    method="shoot", max_cycles=1)
    model.friction.response([0.0, 0.1], 1e-3)
    from taos.friction.registry import load_all
    load_all()   # every built-in law's kernels (a command loads only its own law's)
    from taos.flight.lco_confirm import compile_kernel
    compile_kernel(model)   # the verdict map's confirmation runs (taos lco --sweep)
    from taos.taos3d import simulate_taos, taos_freqresp, taos_model
    tm = taos_model(model)
    simulate_taos(tm, SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01)
    taos_freqresp(tm, [10.0], math.radians(0.4))
    print(f"taos: numba kernels compiled and cached in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
