"""The order tests run in: the modules holding the longest tests first (issue 28 item 5).

``make test`` runs two pytest-xdist workers, which take the tests in collection order; when a
30-second test starts last, one core works alone to the end while the other idles. So the test
modules are ordered by their longest test, the longest first: measured seconds from
``tests/durations.txt`` (``pytest --durations=0``), a test marked ``slow`` without a measurement
counting :data:`SLOW_DEFAULT_S`. Whole modules move, each keeping its own order: a module's
tests share module-scoped fixtures (computed once per worker only while its tests run
together) and the user guide's steps run in guide order (``view`` reads what ``simulate``
wrote). Under ``make test`` (``TAOS_TEST_DOCS_STATUS`` set) the modules that check what the
concurrent documentation build wrote (:data:`AFTER_DOCS`) run last, so that the build is done
by then. The order changes no result: every test still runs, on the same inputs.

The order needs ``--dist worksteal`` (``make test``/``make check``): xdist's default ``load``
hands each worker an eighth of the suite up front, which with the slow modules first puts them
all in worker 1's first batch. A simulation of xdist 3.8's two schedulers on the measured
durations (``benchmarks/sim_test_order.py``: each duration perturbed by a log-normal factor,
sigma 0.5, 200 draws) gives the wall time above the ideal (sum / 2): collection order with
``load`` (before) 12.3 s mean, 60 s worst; this order with ``load`` 94 s mean; this order with
``worksteal`` 4.4 s mean, 21 s worst.
"""

from __future__ import annotations

import os
from pathlib import Path

DURATIONS = Path(__file__).with_name("durations.txt")
#: seconds counted for a test marked slow that has no measurement
SLOW_DEFAULT_S = 10.0
#: modules reading the concurrent documentation build's output under ``make test``
AFTER_DOCS = ("tests/test_docs.py",)
#: the environment variable naming the docs build's status file (set by ``make test``)
DOCS_STATUS_ENV = "TAOS_TEST_DOCS_STATUS"


def measured_durations(path: Path = DURATIONS) -> dict[str, float]:
    """node id -> measured seconds (lines ``SECONDS NODEID``; ``#`` comments)."""
    out: dict[str, float] = {}
    if path.is_file():
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.strip() and not line.lstrip().startswith("#"):
                seconds, nodeid = line.split(maxsplit=1)
                out[nodeid.strip()] = float(seconds)
    return out


def slowest_modules_first(items: list, durations: dict[str, float], docs_last: bool) -> list:
    """``items`` grouped by module (each module's items in their order), the modules sorted by
    their longest item, the longest first (ties: collection order); with ``docs_last`` the
    modules of :data:`AFTER_DOCS` go last."""
    groups: dict[str, list] = {}
    for it in items:
        groups.setdefault(it.nodeid.split("::")[0], []).append(it)

    def cost(it) -> float:
        if it.nodeid in durations:
            return durations[it.nodeid]
        return SLOW_DEFAULT_S if it.get_closest_marker("slow") is not None else 0.0

    order = sorted(groups, key=lambda m: (docs_last and m in AFTER_DOCS, -max(cost(it) for it in groups[m])))
    return [it for m in order for it in groups[m]]


def pytest_collection_modifyitems(config, items):
    items[:] = slowest_modules_first(items, measured_durations(), bool(os.environ.get(DOCS_STATUS_ENV)))
