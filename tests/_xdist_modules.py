"""pytest-xdist's work stealing (``--dist worksteal``) with every hand-over at a test-module
boundary where there is one.

xdist deals the tests out in halves and, when a worker runs dry, moves half of the other
worker's queue to it. Both cuts fall at a test count, often inside a module; the module's
``scope="module"`` fixtures (a whole Green Run report, six limit-cycle analyses, a Dask
cluster) are then built on both workers: seen in `make test` as the report fixture of
tests/test_report.py made twice (about 8 CPU-s). Here each cut moves to the module boundary
nearest to xdist's own cut, within the range xdist allows; when the queue holds one module
only, the cut stays where xdist put it (a split module beats an idle core).

The scheduler is xdist 3.x's ``WorkStealingScheduling`` with its ``check_schedule`` restated
(the choice of the cut is the only change); tests/test_xdist_modules.py checks the cut rule
and a whole schedule on stand-in workers.
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest

try:
    from xdist.scheduler.worksteal import MIN_PENDING, NodePending, WorkStealingScheduling
except ImportError:  # pytest-xdist absent: plain pytest runs without it
    WorkStealingScheduling = None


def module_of(nodeid: str) -> str:
    """The test file of a pytest node id (``tests/test_x.py::test_y[z]`` -> ``tests/test_x.py``)."""
    return nodeid.split("::", 1)[0]


def module_cut(nodeids: Sequence[str], want: int, lo: int, hi: int) -> int:
    """The cut ``k`` (``nodeids[:k]`` | ``nodeids[k:]``) in ``lo <= k <= hi`` nearest to ``want``
    that falls between two modules (or at an end of ``nodeids``); ``want`` when there is none.
    Ties go to the smaller ``k``."""
    n = len(nodeids)
    best = None
    for k in range(max(lo, 0), min(hi, n) + 1):
        if k in (0, n) or module_of(nodeids[k - 1]) != module_of(nodeids[k]):
            if best is None or abs(k - want) < abs(best - want):
                best = k
    return want if best is None else best


if WorkStealingScheduling is not None:
    class ModuleWorkStealing(WorkStealingScheduling):
        """Work stealing whose deals and steals cut between test modules (module docstring)."""

        def _ids(self, indices: Sequence[int]) -> list[str]:
            assert self.collection is not None
            return [self.collection[i] for i in indices]

        def _send_tests(self, node, num: int) -> None:
            if 0 < num < len(self.pending):
                num = module_cut(self._ids(self.pending), num, 1, len(self.pending))
            super()._send_tests(node, num)

        def check_schedule(self) -> None:
            """xdist's ``WorkStealingScheduling.check_schedule`` (3.8), the steal cut at a
            module boundary."""
            nodes_up = [NodePending(node, pending) for node, pending in self.node2pending.items()
                        if not node.shutting_down]

            def idle_nodes():
                return [node for node, pending in nodes_up if len(pending) < MIN_PENDING]

            idle = idle_nodes()
            if not idle:
                return
            if self.pending:
                for i, node in enumerate(idle):
                    self._send_tests(node, len(self.pending) // (len(idle) - i))
                idle = idle_nodes()
                if not idle:
                    return
            if self.steal_requested_from_node is not None:
                return
            victim = max(nodes_up, key=lambda np_: len(np_.pending), default=None)
            num = 0
            if victim is not None:
                max_steal = max(0, len(victim.pending) - MIN_PENDING)
                num = min(len(victim.pending) // 2, max_steal)
            if num == 0:
                for node in idle:
                    node.shutdown()
                return
            # the stolen tail is pending[len - num:]; its start may not be a running test
            n = len(victim.pending)
            start = module_cut(self._ids(victim.pending), n - num, n - max_steal, n - 1)
            victim.node.send_steal(victim.pending[start:])
            self.steal_requested_from_node = victim.node


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist worksteal`` cuts between modules; every other mode is xdist's own (None: the
    next implementation, xdist's, decides)."""
    if WorkStealingScheduling is not None and config.getvalue("dist") == "worksteal":
        return ModuleWorkStealing(config, log)
    return None
