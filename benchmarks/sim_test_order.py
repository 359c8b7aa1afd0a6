"""How long two pytest-xdist workers take on the test suite, by test order and scheduler: a
simulation of xdist 3.8's ``load`` and ``worksteal`` schedulers on the measured durations
(``benchmarks/test_durations.txt``; tests not listed there count the rest of the measured total
evenly), each perturbed by a log-normal factor (sigma 0.5) over 200 draws, as a loaded machine
does.

Prints the wall time above the ideal (sum / 2) for the collection order and for the test modules
reordered slowest first (whole modules, by their longest test), with each scheduler. The
finding (2026-11-25): ``worksteal`` removes most of the idle tail (``make test`` uses it); the
slowest-first order adds nothing with ``worksteal`` and is much worse with ``load`` (which hands
worker 1 the first eighth of the suite: all the slow modules), so the tests keep their
collection order. Run: ``.venv/bin/python benchmarks/sim_test_order.py`` (collects the tests;
runs none).
"""

from __future__ import annotations

import collections
import heapq
import random
import statistics
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DURATIONS = Path(__file__).with_name("test_durations.txt")

#: seconds of the whole suite in the same measurement (sum of ``pytest --durations=0``)
MEASURED_TOTAL_S = 857.0


def measured_durations(path: Path = DURATIONS) -> dict[str, float]:
    """node id -> measured seconds (lines ``SECONDS NODEID``; ``#`` comments)."""
    out: dict[str, float] = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            seconds, nodeid = line.split(maxsplit=1)
            out[nodeid.strip()] = float(seconds)
    return out


def slowest_modules_first(order: list[str], durations: dict[str, float]) -> list[str]:
    """``order`` grouped by module (each module's tests in their order), the modules sorted by
    their longest measured test, the longest first."""
    groups: dict[str, list[str]] = {}
    for t in order:
        groups.setdefault(t.split("::")[0], []).append(t)
    mods = sorted(groups, key=lambda m: -max(durations.get(t, 0.0) for t in groups[m]))
    return [t for m in mods for t in groups[m]]


class _Collected:
    """Records the collected node ids."""

    def __init__(self):
        self.ids: list[str] = []

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, items):
        self.ids = [it.nodeid for it in items]


def simulate(durations: list[float], mode: str, n: int = 2) -> float:
    """Wall time [s] of ``n`` xdist workers: ``load`` (xdist 3.8 LoadScheduling: an eighth of
    the suite each up front, refills as queues run low) or ``worksteal`` (xdist 3.8
    WorkStealingScheduling: the suite split evenly up front, the first half to worker 1; a
    worker with fewer than 2 tests left takes the back half of the longest queue)."""
    pending = list(range(len(durations)))
    queues = [collections.deque() for _ in range(n)]

    def send(k, num):
        queues[k].extend(pending[:num])
        del pending[:num]

    if mode == "worksteal":
        for k in range(n):
            send(k, len(pending) // (n - k))
    else:
        for k in range(n):
            send(k, max(len(durations) // n // 4, 2))
    events = [(0.0, k, None) for k in range(n)]
    end = [0.0] * n
    while events:
        now, k, done = heapq.heappop(events)
        if mode == "load" and done is not None and pending:
            lo, hi = max(2, len(pending) // n // 4), max(2, len(pending) // n // 2)
            if len(queues[k]) < lo and not (done >= 0.1 and len(queues[k]) >= 2):
                send(k, hi - len(queues[k]))
        if mode == "worksteal" and len(queues[k]) < 2:
            victim = max(range(n), key=lambda j: len(queues[j]))
            take = min(len(queues[victim]) // 2, max(0, len(queues[victim]) - 2))
            stolen = [queues[victim].pop() for _ in range(take)]
            queues[k].extend(reversed(stolen))
        if queues[k]:
            i = queues[k].popleft()
            heapq.heappush(events, (now + durations[i], k, durations[i]))
        else:
            end[k] = now
    return max(end)


def main() -> None:
    rec = _Collected()
    code = pytest.main(["--collect-only", "-q", "-p", "no:cacheprovider", str(ROOT / "tests")], plugins=[rec])
    assert code == 0 and rec.ids, code
    measured = measured_durations()
    rest = [t for t in rec.ids if t not in measured]
    other_s = max(MEASURED_TOTAL_S - sum(measured.values()), 0.0) / max(len(rest), 1)
    print(f"\n{len(rec.ids)} tests, {len(measured)} with measured durations, the others {other_s * 1e3:.0f} ms each")
    print("wall time above the ideal (sum / 2), two workers, 200 perturbed draws [s]:")
    for name, order in (("collection order", rec.ids), ("slowest modules first", slowest_modules_first(rec.ids, measured))):
        for mode in ("load", "worksteal"):
            gaps = []
            for seed in range(200):
                rnd = random.Random(seed)
                d = [measured.get(t, other_s) * rnd.lognormvariate(0.0, 0.5) for t in order]
                gaps.append(simulate(d, mode) - sum(d) / 2)
            print(f"  {name:22s} --dist {mode:9s}: mean {statistics.mean(gaps):6.1f}  worst {max(gaps):6.1f}")


if __name__ == "__main__":
    main()
