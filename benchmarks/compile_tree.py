"""Where a cold start's numba compile time goes: the tree of compilations (kernel, the kernels
and numba library functions it compiles on the way) of one ``taos`` command, with the seconds of
each (numba's ``numba:compile`` events; entries under 0.2 s left out).

Run it with an empty kernel cache, else it shows only what the cache lacks:

    rm -rf /tmp/nbc; NUMBA_CACHE_DIR=/tmp/nbc .venv/bin/python benchmarks/compile_tree.py \\
        greenrun rs25_hotfire --out /tmp/gr --quiet

Lines are printed as compilations end (a callee before its caller), indented by depth.
"""

from __future__ import annotations

import sys
import time

from numba.core import event as ev

_stack: list[tuple[str, float]] = []
_done: list[tuple[int, str, float]] = []


class _Listener(ev.Listener):
    def on_start(self, event):
        f = event.data["dispatcher"].py_func
        _stack.append((f"{f.__module__.split('.')[-1]}.{f.__qualname__}", time.perf_counter()))

    def on_end(self, event):
        name, t0 = _stack.pop()
        _done.append((len(_stack), name, time.perf_counter() - t0))


def main(argv: list[str]) -> int:
    ev.register("numba:compile", _Listener())
    from taos.cli import main as taos_main

    t0 = time.perf_counter()
    rc = taos_main(argv)
    total = time.perf_counter() - t0
    for depth, name, dt in _done:
        if dt > 0.2:
            print("  " * depth + f"{dt:6.2f} s  {name}")
    print(f"command: {total:.2f} s, of which top-level compiles {sum(d for k, _, d in _done if k == 0):.2f} s")
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
