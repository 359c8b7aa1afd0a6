"""No source file of the packages grows past 600 lines (issue 38, point 6): a longer module is
split into small private modules, one concept each, re-exported where callers import them."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("taos", "masv")
MAX_LINES = 600


def test_no_source_file_exceeds_600_lines():
    files = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py") if "__pycache__" not in p.parts]
    assert len(files) > 50, "the packages were not found"
    long = {str(p.relative_to(ROOT)): n for p in files
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"source files over {MAX_LINES} lines (split them): {long}"
