"""Where a cold start's numba compile time goes: the tree of compilations (kernel, the kernels
and numba library functions it compiles on the way) of one ``taos`` command, with the wall and
CPU (process) seconds of each (numba's ``numba:compile`` events; entries under 0.2 s wall left
out; on a shared machine compare the CPU seconds).

Run it with an empty kernel cache, else it shows only what the cache lacks:

    rm -rf /tmp/nbc; NUMBA_CACHE_DIR=/tmp/nbc .venv/bin/python benchmarks/compile_tree.py \\
        greenrun rs25_hotfire --out /tmp/gr --quiet

Lines are printed as compilations end (a callee before its caller), indented by depth.
"""

from __future__ import annotations

import sys
import time

from numba.core import event as ev

_stack: list[tuple[str, float, float]] = []
_done: list[tuple[int, str, float, float]] = []


class _Listener(ev.Listener):
    def on_start(self, event):
        f = event.data["dispatcher"].py_func
        _stack.append((f"{f.__module__.split('.')[-1]}.{f.__qualname__}", time.perf_counter(), time.process_time()))

    def on_end(self, event):
        name, t0, c0 = _stack.pop()
        _done.append((len(_stack), name, time.perf_counter() - t0, time.process_time() - c0))


def main(argv: list[str]) -> int:
    ev.register("numba:compile", _Listener())
    from taos.cli import main as taos_main

    t0, c0 = time.perf_counter(), time.process_time()
    rc = taos_main(argv)
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    for depth, name, dt, dc in _done:
        if dt > 0.2:
            print("  " * depth + f"{dt:6.2f} s ({dc:6.2f} CPU-s)  {name}")
    top = [(d, c) for k, _, d, c in _done if k == 0]
    print(f"command: {total:.2f} s ({cpu:.2f} CPU-s), of which top-level compiles {sum(d for d, _ in top):.2f} s "
          f"({sum(c for _, c in top):.2f} CPU-s)")
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
