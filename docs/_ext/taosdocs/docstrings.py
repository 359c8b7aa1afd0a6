"""The project writes its docstrings as plain text with an engineer's notation: ``|H|`` for a
magnitude, ``x_p / (R theta_c)``, indented ``::`` blocks for equations. reStructuredText would
read ``|H|`` as a substitution; this hook escapes the bars outside literal text so the
docstrings render as written (nothing else is changed)."""

from __future__ import annotations

import re

_LITERAL_SPAN = re.compile(r"(``.+?``|`[^`]+`)")


def _escape_bars(text: str) -> str:
    parts = _LITERAL_SPAN.split(text)
    return "".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def escape_docstring(lines: list[str]) -> None:
    """Escape '|' in place, leaving literal blocks (after '::') and inline literals alone."""
    literal_indent = None   # indentation of the paragraph that opened a literal block
    opening = False
    for k, line in enumerate(lines):
        if literal_indent is not None:
            if line.strip() and _indent(line) <= literal_indent and not opening:
                literal_indent = None
            else:
                if line.strip():
                    opening = False
                continue
        if line.rstrip().endswith("::"):
            literal_indent = _indent(line)
            opening = True
        lines[k] = _escape_bars(line)


def process_docstring(app, what, name, obj, options, lines) -> None:
    escape_docstring(lines)
