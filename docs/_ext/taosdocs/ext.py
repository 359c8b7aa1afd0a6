"""Sphinx extension of the taos docs (conf.py loads ``taosdocs.ext``).

* ``autodoc-process-docstring``: the docstrings' plain-text notation (:mod:`.docstrings`);
* ``{taos-step} ID``: runs the user-guide command ``ID`` (:mod:`.guide`) and shows the command,
  what it printed and the pictures it made; a command that fails stops the build;
* ``{taos-cli} taos|masv``: the command-line reference, from the argparse parsers;
* ``{taos-model-keys}``: the model-file and flight-file keys, from the code's key tables;
* ``{taos-verification}``: ``docs/verification.md`` (written by the verification suite) when it
  is there, else a note saying how to make it;
* the Python domain's cross-reference look-ups memoised while the pages are written
  (:mod:`.xrefmemo`).
"""

from __future__ import annotations

import shutil
from pathlib import Path

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

from . import guide

from . import layouts

from . import reference, xrefmemo
from .docstrings import process_docstring

logger = logging.getLogger(__name__)
GEN = "_generated"


def _wrap(command: str, width: int = 88) -> str:
    """A long command split before its options with shell line continuations."""
    if len(command) <= width:
        return command
    parts = command.split(" --")
    lines, cur = [], parts[0]
    for p in parts[1:]:
        if len(cur) + len(p) + 3 > width:
            lines.append(cur)
            cur = "    --" + p
        else:
            cur += " --" + p
    lines.append(cur)
    return " \\\n".join(lines)


class _MarkdownDirective(SphinxDirective):
    has_content = False

    def _render(self, text: str, titles: bool = False) -> list[nodes.Node]:
        box = nodes.container()
        self.state.nested_parse(StringList(text.splitlines()), self.content_offset, box, match_titles=titles)
        return box.children if titles else [box]


class TaosStep(_MarkdownDirective):
    required_arguments = 1

    def run(self):
        step_id = self.arguments[0]
        step = guide.STEP_BY_ID.get(step_id)
        if step is None:
            raise self.error(f"taos-step: no guide step {step_id!r} (docs/_ext/taosdocs/guide.py)")
        app = self.env.app
        srcdir = Path(app.srcdir)
        work = srcdir / GEN / "work"
        res = guide.run_step(step, work)
        guide.write_step_record(res, srcdir / GEN / "records")   # for tests/test_docs.py under make test
        self.env.note_dependency(str(Path(guide.__file__)))
        if res.exit_code != 0 or res.missing:
            raise self.error(f"guide step {step_id!r} ({step.command}) exited {res.exit_code}, missing "
                             f"{res.missing}: {res.stderr.strip()[-500:]}")
        md = [f"```console\n$ {_wrap(step.command)}\n```\n"]
        if step.show_stdout and res.stdout.strip():
            lines = res.stdout.rstrip().splitlines()
            more = len(lines) > step.show_stdout
            shown = "\n".join(lines[: step.show_stdout]) + ("\n..." if more else "")
            md.append(f"```text\n{shown}\n```\n")
        figdir = srcdir / GEN / "fig"
        figdir.mkdir(parents=True, exist_ok=True)
        for k, f in enumerate(res.figures):
            dest = figdir / f"{step_id}_{k + 1}{f.suffix}"
            shutil.copyfile(f, dest)
            md.append(f"```{{figure}} /{GEN}/fig/{dest.name}\n:width: 95%\n\n`{f.relative_to(work).as_posix()}`\n```\n")
        for d in step.downloads:
            dest = figdir / f"{step_id}_{Path(d).name}"
            shutil.copyfile(work / d, dest)
            md.append(f"Open the result: {{download}}`{Path(d).name} </{GEN}/fig/{dest.name}>` (made by this build).\n")
        return self._render("\n".join(md))


class TaosCli(_MarkdownDirective):
    required_arguments = 1

    def run(self):
        return self._render(reference.cli_markdown(self.arguments[0]), titles=True)


class TaosModelKeys(_MarkdownDirective):
    def run(self):
        missing: list[str] = []
        text = reference.model_keys_markdown(missing)
        for key in missing:
            logger.warning(f"model-file key {key!r} has no meaning in docs/_ext/taosdocs/reference.py MEANINGS "
                           "(a [friction] key: in its law's taos.friction.param(..., meaning=...))",
                           location=(self.env.docname, self.lineno))
        for key in reference.stale_meanings():
            logger.warning(f"MEANINGS names {key!r}, a key the code does not read",
                           location=(self.env.docname, self.lineno))
        return self._render(text, titles=True)


class TaosVerification(_MarkdownDirective):
    def run(self):
        p = Path(self.env.app.srcdir) / "verification.md"
        if p.is_file():
            self.env.note_dependency(str(p))
            text = p.read_text(encoding="utf-8")
            lines = text.splitlines()
            if lines and lines[0].startswith("# "):   # this page has its own title
                lines = lines[1:]
            # headings become rubrics: sections made inside a directive would land out of order
            md = [f"```{{rubric}} {ln.lstrip('#').strip()}\n```" if ln.startswith("#") else ln for ln in lines]
            return self._render("\n".join(md))
        return self._render("The verification table (`docs/verification.md`) is written by the verification "
                            "suite; it was not present when this site was built.")


class TaosOutputLayout(_MarkdownDirective):
    """``{taos-output-layout} STEP_ID PATH``: the layout of a file that guide step made."""

    required_arguments = 2

    def run(self):
        step_id, rel = self.arguments
        work = Path(self.env.app.srcdir) / GEN / "work"
        path = work / rel
        if not path.exists():
            step = guide.STEP_BY_ID.get(step_id)
            if step is None:
                raise self.error(f"taos-output-layout: no guide step {step_id!r}")
            res = guide.run_step(step, work)
            guide.write_step_record(res, Path(self.env.app.srcdir) / GEN / "records")
            if res.exit_code != 0 or not path.exists():
                raise self.error(f"guide step {step_id!r} did not write {rel}: {res.stderr.strip()[-300:]}")
        text = layouts.h5_layout(path) if path.suffix == ".h5" else layouts.json_layout(path)
        cmd = guide.STEP_BY_ID[step_id].command
        return self._render(f"`{rel}` as written by `{cmd}`:\n\n```text\n{text}\n```\n")


class TaosPython(_MarkdownDirective):
    """A Python example run at build time from the work folder; shows the code and what it printed
    (and the picture it saved, with ``:figure: out/NAME.png``)."""

    has_content = True
    option_spec = {"figure": str}

    def run(self):
        code = "\n".join(self.content)
        work = guide.prepare_workdir(Path(self.env.app.srcdir) / GEN / "work")
        (work / "out").mkdir(exist_ok=True)
        records = Path(self.env.app.srcdir) / GEN / "records"
        try:
            printed = guide.run_python(code, work)
        except Exception as e:  # a failing example stops the build
            guide.write_python_record(self.env.docname, code, f"{type(e).__name__}: {e}", records)
            raise self.error(f"python example failed: {type(e).__name__}: {e}") from None
        guide.write_python_record(self.env.docname, code, None, records)
        md = [f"```python\n{code}\n```\n"]
        if printed.strip():
            md.append(f"```text\n{printed.rstrip()}\n```\n")
        fig = self.options.get("figure")
        if fig:
            figdir = Path(self.env.app.srcdir) / GEN / "fig"
            figdir.mkdir(parents=True, exist_ok=True)
            dest = figdir / f"py_{self.env.docname.replace('/', '_')}_{self.lineno}{Path(fig).suffix}"
            shutil.copyfile(work / fig, dest)
            md.append(f"```{{figure}} /{GEN}/fig/{dest.name}\n:width: 80%\n```\n")
        return self._render("\n".join(md))


def setup(app):
    app.connect("autodoc-process-docstring", process_docstring)
    app.add_directive("taos-step", TaosStep)
    app.add_directive("taos-cli", TaosCli)
    app.add_directive("taos-model-keys", TaosModelKeys)
    app.add_directive("taos-verification", TaosVerification)
    app.add_directive("taos-output-layout", TaosOutputLayout)
    app.add_directive("taos-python", TaosPython)
    xrefmemo.setup(app)
    return {"parallel_read_safe": False, "version": "1"}
