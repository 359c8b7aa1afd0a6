"""The documentation's generated parts stay true: every user-guide command runs on the shipped
models and writes what the guide says it writes, the Python examples run, the CLI reference
covers every subcommand and option of the parsers, and the model-file key reference covers
every key the code reads and the shipped files use. (``make docs`` builds the site with -W.)"""

from __future__ import annotations

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

STEP_RE = re.compile(r"```\{taos-step\}\s+(\S+)")
LAYOUT_RE = re.compile(r"```\{taos-output-layout\}\s+(\S+)\s+(\S+)")


def _pages():
    return [p for p in DOCS.rglob("*.md") if "_generated" not in p.parts and "_build" not in p.parts]


def test_every_guide_command_is_shown_and_every_shown_command_exists():
    shown = [m.group(1) for p in _pages() for m in STEP_RE.finditer(p.read_text(encoding="utf-8"))]
    assert set(shown) == set(guide.STEP_BY_ID), "guide steps not on a page / pages naming unknown steps"
    for p in _pages():
        for m in LAYOUT_RE.finditer(p.read_text(encoding="utf-8")):
            step = guide.STEP_BY_ID[m.group(1)]
            assert m.group(2) in step.outputs or m.group(2).startswith("out/"), m.group(0)


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return guide.prepare_workdir(tmp_path_factory.mktemp("guide"))


@pytest.mark.parametrize("step", guide.STEPS, ids=[s.id for s in guide.STEPS])
def test_guide_command_runs_on_shipped_models(step, workdir):
    """Steps run in guide order (``view`` reads the run ``simulate`` wrote)."""
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


def test_python_examples_run(workdir):
    examples = guide.python_examples(DOCS)
    assert len(examples) >= 3
    for page, code in examples:
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
