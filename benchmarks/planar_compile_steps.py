"""Cold compile of the planar warm-up steps (issue 44 point 1): each planar step of
``taos.cli.warmup`` run in one process, in order, with its wall and CPU time and the load
average, and with ``--tree`` the compilations under it (numba's ``numba:compile`` events:
kernel, argument types, seconds; entries under 0.3 s left out; a callee before its caller).

Run it with an empty kernel cache, else it shows only what the cache lacks; compare two trees
in consecutive runs:

    rm -rf /tmp/nbc; NUMBA_CACHE_DIR=/tmp/nbc PYTHONPATH=<tree> .venv/bin/python \\
        benchmarks/planar_compile_steps.py [--tree] [STEP ...]
"""

from __future__ import annotations

import os
import sys
import time

from numba.core import event as ev

_stack: list[tuple[str, str, float]] = []
_done: list[tuple[int, str, str, float]] = []


class _Listener(ev.Listener):
    def on_start(self, event):
        f = event.data["dispatcher"].py_func
        _stack.append((f"{f.__module__.split('.')[-1]}.{f.__qualname__}", str(event.data.get("args")),
                       time.perf_counter()))

    def on_end(self, event):
        name, args, t0 = _stack.pop()
        _done.append((len(_stack), name, args, time.perf_counter() - t0))


def main(argv: list[str]) -> None:
    tree = "--tree" in argv
    names = [a for a in argv if a != "--tree"]
    ev.register("numba:compile", _Listener())
    from taos.cli import warmup

    steps = [s for s in warmup.STEPS if (s.name in names if names else s.group == "planar")]
    total = 0.0
    for s in steps:
        _done.clear()
        t, c = time.perf_counter(), time.process_time()
        s.run()
        dw, dc = time.perf_counter() - t, time.process_time() - c
        total += dc
        print(f"== {s.name}: wall {dw:.1f} s cpu {dc:.1f} s load {os.getloadavg()[0]:.2f}", flush=True)
        if tree:
            for depth, name, args, dt in _done:
                if dt > 0.3:
                    print("  " * (depth + 1) + f"{dt:6.2f} {name} {args[:160]}")
    print(f"TOTAL cpu {total:.1f} s")


if __name__ == "__main__":
    main(sys.argv[1:])
