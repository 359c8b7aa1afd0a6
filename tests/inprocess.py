"""The ``taos`` console script's entry (:func:`taos.cli.main`) called in this test process.

For tests whose subject is a command's figures or files, not the process: the call pays none of
the 1-1.5 s of imports and kernel loading a new ``taos`` process pays before any work. Start-up,
signals, exit statuses of refused input and the printed text stay subprocess tests
(:func:`tests.conftest.run_cli`)."""

from __future__ import annotations

import contextlib
import json
from pathlib import Path

from tests.conftest import ROOT


def taos_main(*args) -> int:
    """``taos ARGS`` through :func:`taos.cli.main`, in the folder :func:`run_cli` runs in;
    returns its exit status."""
    from taos.cli import main

    with contextlib.chdir(ROOT):
        return main([str(a) for a in args])


def taos_json(out: Path, *args) -> dict:
    """``taos ARGS --json OUT`` in this process: exit 0 asserted, the JSON written returned."""
    rc = taos_main(*args, "--json", out)
    assert rc == 0, f"taos {' '.join(map(str, args))}: exit {rc}"
    return json.loads(Path(out).read_text())
