"""How long two pytest-xdist workers take on the test suite, by test order and scheduler: a
simulation of xdist 3.8's ``load`` and ``worksteal`` schedulers on the measured durations
(``tests/durations.txt``; tests not listed there count the rest of the measured total evenly),
each perturbed by a log-normal factor (sigma 0.5) over 200 draws, as a loaded machine does.

Prints the wall time above the ideal (sum / 2) for the collection order (before
``tests/_ordering.py``) and the order ``make test`` runs (slowest modules first). Run:
``.venv/bin/python benchmarks/sim_test_order.py`` (collects the tests: ~10 s; runs none).
"""

from __future__ import annotations

import collections
import heapq
import os
import random
import statistics
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests._ordering import DOCS_STATUS_ENV, measured_durations  # noqa: E402

#: seconds of the whole suite in the same measurement (sum of ``pytest --durations=0``)
MEASURED_TOTAL_S = 857.0


class _Orders:
    """The collected node ids before and after the project's ordering hook."""

    def __init__(self):
        self.before: list[str] = []
        self.after: list[str] = []


class _Before:
    def __init__(self, rec):
        self.rec = rec

    @pytest.hookimpl(tryfirst=True)
    def pytest_collection_modifyitems(self, items):
        self.rec.before = [it.nodeid for it in items]


class _After:
    def __init__(self, rec):
        self.rec = rec

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, items):
        self.rec.after = [it.nodeid for it in items]


def simulate(durations: list[float], mode: str, n: int = 2) -> float:
    """Wall time [s] of ``n`` xdist workers: ``load`` (xdist 3.8 LoadScheduling: an eighth of
    the suite each up front, refills as queues run low) or ``worksteal`` (the same start; an idle
    worker takes the back half of the longest queue)."""
    pending = list(range(len(durations)))
    queues = [collections.deque() for _ in range(n)]

    def send(k, num):
        queues[k].extend(pending[:num])
        del pending[:num]

    for k in range(n):
        send(k, max(len(durations) // n // 4, 2))
    events = [(0.0, k, None) for k in range(n)]
    end = [0.0] * n
    while events:
        now, k, done = heapq.heappop(events)
        if done is not None and pending:
            lo, hi = max(2, len(pending) // n // 4), max(2, len(pending) // n // 2)
            if len(queues[k]) < lo and not (done >= 0.1 and len(queues[k]) >= 2):
                send(k, hi - len(queues[k]))
        if not queues[k] and not pending and mode == "worksteal":
            victim = max(range(n), key=lambda j: len(queues[j]))
            for _ in range(len(queues[victim]) // 2):
                queues[k].appendleft(queues[victim].pop())
        if queues[k]:
            i = queues[k].popleft()
            heapq.heappush(events, (now + durations[i], k, durations[i]))
        else:
            end[k] = now
    return max(end)


def main() -> None:
    rec = _Orders()
    os.environ[DOCS_STATUS_ENV] = os.devnull     # the order make test runs (its docs modules last)
    code = pytest.main(["--collect-only", "-q", "-p", "no:cacheprovider", str(ROOT / "tests")],
                       plugins=[_Before(rec), _After(rec)])
    assert code == 0 and rec.before and sorted(rec.before) == sorted(rec.after), code
    measured = measured_durations()
    rest = [t for t in rec.before if t not in measured]
    other_s = max(MEASURED_TOTAL_S - sum(measured.values()), 0.0) / max(len(rest), 1)
    print(f"\n{len(rec.before)} tests, {len(measured)} with measured durations, the others {other_s * 1e3:.0f} ms each")
    print("wall time above the ideal (sum / 2), two workers, 200 perturbed draws [s]:")
    for name, order in (("collection order", rec.before), ("slowest modules first", rec.after)):
        for mode in ("load", "worksteal"):
            gaps = []
            for seed in range(200):
                rnd = random.Random(seed)
                d = [measured.get(t, other_s) * rnd.lognormvariate(0.0, 0.5) for t in order]
                gaps.append(simulate(d, mode) - sum(d) / 2)
            print(f"  {name:22s} --dist {mode:9s}: mean {statistics.mean(gaps):6.1f}  worst {max(gaps):6.1f}")


if __name__ == "__main__":
    main()
