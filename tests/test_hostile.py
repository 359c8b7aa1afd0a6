"""The hostile-input suite of issue 25: every case of :mod:`tests.hostile_cases` (grouped by
the contract it checks) runs the command line in-process and must end with its documented exit
status, one line on standard error naming the field or option, no traceback, and not one file
of the user's changed (SHA-256 of every file before and after, the shipped inputs included).
The count of the whole suite (this table, the API and signal cases and the fuzzing of
``tests/test_hostile_fuzz.py``) is in docs/verification.md."""

from __future__ import annotations

import functools
import hashlib
import os
import stat
from collections import Counter
from pathlib import Path

import pytest

from .hostile_cases import AMBIENT, ASCENT, CASES, DATA, FLIGHT, MASV, MODELS, PROFILE, Case

SHIPPED = [AMBIENT, PROFILE, DATA, FLIGHT, MASV, ASCENT, MODELS / "rs25_flight.toml",
           MODELS / "actuators" / "tvc_actuator.toml", MODELS / "friction" / "rs25_gimbal.toml"]


#: files larger than this (only the sparse oversized inputs of the ``files`` group) are compared
#: by size and modification time rather than hashed: reading gigabytes of zeros would only cost time
BIG = 64 * 2 ** 20


def shipped_hashes() -> dict:
    """Path -> SHA-256 of the shipped inputs."""
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in SHIPPED}


#: the shipped inputs as the module found them: every case's "before" (its "after" hashes them
#: again, so a case that changed one fails, as does every later case)
shipped_at_start = functools.cache(shipped_hashes)


def fingerprint(folder: Path, shipped: dict | None = None) -> dict:
    """Path -> SHA-256 of every regular file under ``folder`` (links and special files by kind;
    files above :data:`BIG` by size and modification time), and of the shipped inputs (hashed
    now, or ``shipped``)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        st = os.lstat(p)
        if stat.S_ISREG(st.st_mode) and st.st_size > BIG:   # the sparse "oversized input" files
            out[str(p.relative_to(folder))] = f"{st.st_size} bytes, modified {st.st_mtime_ns}"
        elif stat.S_ISREG(st.st_mode):
            with open(p, "rb") as f:
                out[str(p.relative_to(folder))] = hashlib.sha256(f.read()).hexdigest()
        elif stat.S_ISLNK(st.st_mode):
            out[str(p.relative_to(folder))] = "link -> " + os.readlink(p)
        elif not stat.S_ISDIR(st.st_mode):
            out[str(p.relative_to(folder))] = f"special {stat.S_IFMT(st.st_mode)}"
    out.update(shipped_hashes() if shipped is None else shipped)
    return out


def _main(prog: str):
    if prog == "masv":
        from masv.cli import main
    else:
        from taos.cli import main
    return main


def test_the_table_is_large_named_once_and_covers_every_group():
    names = [c.name for c in CASES]
    dup = [n for n, k in Counter(names).items() if k > 1]
    assert not dup, dup
    groups = Counter(c.group for c in CASES)
    assert set(groups) == {"outputs", "bounds", "units", "files", "data", "flags"}, groups
    assert len(CASES) >= 400, len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[f"{c.group}: {c.name}" for c in CASES])
def test_hostile_input(case: Case, tmp_path, capsys, monkeypatch):
    work = tmp_path / "user"
    work.mkdir()
    argv = [str(a) for a in case.build(work)]
    monkeypatch.chdir(work)
    before = fingerprint(work, shipped_at_start())
    rc = _main(case.prog)(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == case.rc, (rc, err)
    assert "Traceback" not in err
    if case.rc != 0:
        assert len(lines) == 1, err
        for word in case.expect:
            assert word in lines[0], (word, lines[0])
        assert "internal error" not in lines[0]
    after = fingerprint(work)
    changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
    if case.rc != 0:
        # a refusal writes nothing at all: not even a new file
        assert not changed, f"files changed by a refused run: {sorted(changed)}"
    else:
        new_or_changed = {k for k in changed if k in before}
        assert new_or_changed <= set(case.changes), f"user files changed: {sorted(new_or_changed - set(case.changes))}"


def test_the_bounds_page_lists_every_bound():
    """docs/reference/bounds.md stays true: every bounded field is in its tables."""
    from taos.bounds import ASCENT_BOUNDS, CAMPAIGN_BOUNDS, FLIGHT_BOUNDS, MODEL_BOUNDS, PROFILE_BOUNDS

    text = (Path(__file__).resolve().parents[1] / "docs" / "reference" / "bounds.md").read_text()
    tables = [MODEL_BOUNDS, FLIGHT_BOUNDS, CAMPAIGN_BOUNDS, ASCENT_BOUNDS, PROFILE_BOUNDS]
    missing = [f for t in tables for f in t if f"`{f}`" not in text]
    assert not missing, missing
