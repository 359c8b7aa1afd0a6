"""The documentation's generated parts stay true: every user-guide command runs on the shipped
models and writes what the guide says it writes, the Python examples run, the CLI reference
covers every subcommand and option of the parsers, and the model-file key reference covers
every key the code reads and the shipped files use. (``make docs`` builds the site with -W.)

The guide's commands and Python examples run once per ``make test``: in its documentation build,
which runs them (``taosdocs.guide.run_step``/``run_python``, as here) while the tests run and
records each result in ``docs/_generated/records``. Under ``make test`` (``TAOS_TEST_DOCS_STATUS``
names the file the build's exit status goes to; make test runs this file right after that
build, and the tests wait for the file in any case) these tests check the same assertions on what it ran and wrote, when it succeeded and recorded every current command;
otherwise (``make check``, plain pytest, a failed or stale build) they run the commands here."""

from __future__ import annotations

import os
import re
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

from taosdocs import guide, reference  # noqa: E402
from taosdocs.docstrings import escape_docstring  # noqa: E402

from .conftest import docs_build_succeeded  # noqa: E402

STEP_RE = re.compile(r"```\{taos-step\}\s+(\S+)")
LAYOUT_RE = re.compile(r"```\{taos-output-layout\}\s+(\S+)\s+(\S+)")


def _pages():
    """The docs' markdown pages (not the build's output: it may be changing while this runs)."""
    out = []
    for folder, subs, files in os.walk(DOCS):
        subs[:] = sorted(d for d in subs if d not in ("_generated", "_build"))
        out += [Path(folder, f) for f in sorted(files) if f.endswith(".md")]
    return out


def test_every_guide_command_is_shown_and_every_shown_command_exists():
    shown = [m.group(1) for p in _pages() for m in STEP_RE.finditer(p.read_text(encoding="utf-8"))]
    assert set(shown) == set(guide.STEP_BY_ID), "guide steps not on a page / pages naming unknown steps"
    for p in _pages():
        for m in LAYOUT_RE.finditer(p.read_text(encoding="utf-8")):
            step = guide.STEP_BY_ID[m.group(1)]
            assert m.group(2) in step.outputs or m.group(2).startswith("out/"), m.group(0)


def _docs_build_records():
    """The records folder of this ``make test``'s documentation build, once it has finished
    successfully and recorded every current guide command and Python example; else None."""
    if not docs_build_succeeded():
        return None
    records, work = DOCS / "_generated" / "records", DOCS / "_generated" / "work"
    if any(guide.read_step_record(s, records, work) is None for s in guide.STEPS):
        return None
    if any(guide.python_record_error(code, records) == "not run by the docs build"
           for _, code in guide.python_examples(DOCS)):
        return None
    return records


@pytest.fixture(scope="module")
def docs_records():
    return _docs_build_records()


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, docs_records):
    if docs_records is not None:
        return DOCS / "_generated" / "work"
    return guide.prepare_workdir(tmp_path_factory.mktemp("guide"))


@pytest.mark.parametrize("step", guide.STEPS, ids=[s.id for s in guide.STEPS])
def test_guide_command_runs_on_shipped_models(step, workdir, docs_records):
    """Steps run in guide order (``view`` reads the run ``simulate`` wrote); under ``make test``
    the docs build ran them (its result, its outputs and pictures as they are now)."""
    if docs_records is not None:
        res = guide.read_step_record(step, docs_records, workdir)
    else:
        res = guide.run_step(step, workdir)
    assert res.exit_code == 0, res.stderr[-2000:]
    assert not res.missing
    for f in res.figures:
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f.stat().st_size > 5000, f
    assert len(res.figures) >= len(step.figures)
    if step.report_html:
        assert res.figures, "the report has no pictures"
    if step.show_stdout:
        assert res.stdout.strip()


def test_python_examples_run(workdir, docs_records):
    examples = guide.python_examples(DOCS)
    assert len(examples) >= 3
    for page, code in examples:
        if docs_records is not None:
            assert guide.python_record_error(code, docs_records) is None, page   # ran there without an exception
        else:
            guide.run_python(code, workdir)
    assert (workdir / "out" / "flight_loop_nichols.png").is_file()


@pytest.mark.parametrize("prog", ["taos", "masv"])
def test_cli_reference_covers_every_subcommand_and_option(prog):
    text = reference.cli_markdown(prog)
    if prog == "taos":
        from taos.cli import build_parser
    else:
        from masv.cli import build_parser
    subs = reference._subparsers(build_parser())
    assert subs
    for name, sp in subs.items():
        assert f"### {prog} {name}\n" in text
        for a in sp._actions:
            for opt in a.option_strings:
                assert opt in text, (name, opt)


def test_model_key_reference_is_complete():
    missing: list[str] = []
    text = reference.model_keys_markdown(missing)
    assert missing == [] and reference.stale_meanings() == []
    shipped = ROOT / "models"
    for f, sections in ((shipped / "rs25_hotfire.toml", None), (shipped / "flight" / "core_stage.toml", None)):
        doc = tomllib.loads(f.read_text(encoding="utf-8"))
        for sec, table in doc.items():
            if isinstance(table, dict):
                for key in table:
                    assert f"| `{key}` |" in text, (f.name, sec, key)


def test_docstring_notation_is_escaped_outside_literals():
    lines = ["Gain 20 log10 |H| [dB], ``|x|`` kept.", "", "Equations::", "", "    |v| < v_s", "", "After |L|."]
    escape_docstring(lines)
    assert lines[0] == r"Gain 20 log10 \|H\| [dB], ``|x|`` kept."
    assert lines[4] == "    |v| < v_s"
    assert lines[6] == r"After \|L\|."
