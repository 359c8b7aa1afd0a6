"""The ``verify`` fixture: every verification test states its reference, its tolerance and the
error it measured; with ``TAOS_VERIFICATION_LOG=path`` each record is appended to that file as
one JSON line, from which ``scripts/verification_report.py`` writes ``docs/verification.md``
(``make verification``)."""

from __future__ import annotations

import json
import math
import os

import pytest


@pytest.fixture
def verify(request):
    """``verify(reference, tolerance, error, unit="relative", case=None)``: assert
    ``error <= tolerance`` and record the case (``case`` defaults to the test's id)."""
    def record(reference: str, tolerance: float, error: float, unit: str = "relative", case: str | None = None):
        error = float(error)
        row = {"case": case or request.node.name, "test": request.node.nodeid, "reference": reference,
               "tolerance": float(tolerance), "error": error, "unit": unit,
               "passed": bool(math.isfinite(error) and error <= tolerance)}
        path = os.environ.get("TAOS_VERIFICATION_LOG")
        if path:
            with open(path, "a") as f:
                f.write(json.dumps(row) + "\n")
        assert row["passed"], row
    return record
