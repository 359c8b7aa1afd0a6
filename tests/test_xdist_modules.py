"""The test runner's work stealing cuts between test modules (tests/_xdist_modules.py), so a
module's ``scope="module"`` fixtures are built on one worker only: the cut rule, and whole
schedules on stand-in workers against xdist's own scheduler."""

from __future__ import annotations

import pytest

from tests._xdist_modules import module_cut

xdist_ws = pytest.importorskip("xdist.scheduler.worksteal")
from tests._xdist_modules import ModuleWorkStealing  # noqa: E402


def ids(*sizes: int) -> list[str]:
    """Node ids of modules m0, m1, ... with ``sizes`` tests each."""
    return [f"tests/test_m{m}.py::test_{i}" for m, n in enumerate(sizes) for i in range(n)]


def test_cut_moves_to_the_nearest_module_boundary_within_its_range():
    n = ids(4, 3, 5)                       # boundaries at 0, 4, 7, 12
    assert module_cut(n, 6, 1, 12) == 7
    assert module_cut(n, 5, 1, 12) == 4    # 4 and 7 are 1 and 2 away
    assert module_cut(n, 2, 1, 12) == 4    # 0 is outside the range
    assert module_cut(n, 9, 8, 11) == 9    # no boundary in 8..11: xdist's cut stays
    assert module_cut(ids(10), 5, 1, 9) == 5


class _Node:
    """A stand-in xdist worker: runs its queue in order, ``cost`` time units a test."""

    def __init__(self, name: str, cost: int):
        self.name, self.cost = name, cost
        self.gateway = type("Gateway", (), {"id": name})()
        self.shutting_down = False
        self.queue: list[int] = []
        self.steal: list[int] | None = None

    def send_runtest_some(self, indices):
        self.queue.extend(indices)

    def send_steal(self, indices):
        self.steal = list(indices)

    def shutdown(self):
        self.shutting_down = True


def _run(sched_cls, collection, costs, monkeypatch) -> dict[str, str]:
    """Each test's worker (node name) in a whole run of ``sched_cls`` on stand-in workers of
    the given ``costs``; a steal is answered at once with the asked tests not yet started."""
    monkeypatch.setattr(xdist_ws, "parse_tx_spec_config", lambda config: ["popen"] * len(costs))
    sched = sched_cls(config=None, log=None)
    nodes = [_Node(f"gw{i}", c) for i, c in enumerate(costs)]
    for nd in nodes:
        sched.add_node(nd)
        sched.add_node_collection(nd, collection)
    sched.schedule()
    ran: dict[str, str] = {}
    running: dict[str, tuple[int, int] | None] = {nd.name: None for nd in nodes}   # (test, end time)
    for clock in range(10_000):
        for nd in nodes:
            if nd.steal is not None:
                now = running[nd.name][0] if running[nd.name] else None
                give = [i for i in nd.steal if i in nd.queue and i != now]
                nd.queue = [i for i in nd.queue if i not in give]
                nd.steal = None
                sched.remove_pending_tests_from_node(nd, give)
            if running[nd.name] and running[nd.name][1] <= clock:
                i = running[nd.name][0]
                running[nd.name] = None
                nd.queue.remove(i)
                sched.mark_test_complete(nd, i)
            if running[nd.name] is None and nd.queue:
                running[nd.name] = (nd.queue[0], clock + nd.cost)
                ran[collection[nd.queue[0]]] = nd.name
        if sched.tests_finished and not any(nd.queue for nd in nodes):
            break
    assert sched.tests_finished and not any(nd.queue for nd in nodes)
    return ran


def _split_modules(ran: dict[str, str]) -> set[str]:
    where: dict[str, set[str]] = {}
    for nodeid, node in ran.items():
        where.setdefault(nodeid.split("::")[0], set()).add(node)
    return {m for m, nodes in where.items() if len(nodes) > 1}


def test_whole_schedule_runs_every_test_once_and_splits_only_a_lone_module(monkeypatch):
    """Eight modules on a fast and a slow worker. xdist's own scheduler splits m3 at its deal
    (test 23 of 47) and m6 at a steal; this one deals 24 | 23 (between m3 and m4), steals m7
    whole from a queue holding m6 and m7, and splits m6 only at the last steal, when m6 is all
    the slow worker has left (a split module beats an idle core). Every test runs once."""
    collection = ids(7, 5, 9, 3, 6, 4, 8, 5)
    theirs = _run(xdist_ws.WorkStealingScheduling, collection, (1, 3), monkeypatch)
    ours = _run(ModuleWorkStealing, collection, (1, 3), monkeypatch)
    assert set(theirs) == set(ours) == set(collection)
    assert _split_modules(theirs) == {"tests/test_m3.py", "tests/test_m6.py"}
    assert _split_modules(ours) == {"tests/test_m6.py"}
    assert {ours[i] for i in collection if "test_m7" in i} == {"gw0"}          # stolen whole
    assert [ours[i] for i in collection].index("gw1") == 24                    # the deal
