"""Result files: HDF5 with provenance, written atomically (no half-written output)."""

from __future__ import annotations

import json
import os
import tempfile
from importlib import metadata
from pathlib import Path
from typing import Callable

import h5py


def package_version() -> str:
    try:
        return metadata.version("taos-tvc")
    except metadata.PackageNotFoundError:
        return "0+unknown"


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> None:
    """Call ``write(tmp)`` on a temporary path beside ``path`` and rename it into place only
    if it succeeds, so a failed run leaves no partial file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_json(path: str, payload: dict) -> None:
    """JSON to ``path`` ('-' is standard output), atomically for files."""
    text = json.dumps(payload, indent=2, allow_nan=False)
    if path == "-":
        print(text)
        return
    atomic_write(path, lambda p: p.write_text(text + "\n"))


def write_provenance(h5: h5py.File, provenance: dict) -> None:
    """Store provenance as attributes of the root group (JSON for nested values)."""
    for k, v in provenance.items():
        h5.attrs[k] = v if isinstance(v, (str, int, float)) else json.dumps(v)


def toml_set(doc, section: str, key: str, value, comment: str | None = None) -> None:
    """Set ``key`` of ``[section]`` ('' for the top level, dots for sub-tables) in a tomlkit
    document to ``value`` with a trailing ``comment`` (None: no comment), keeping the line's
    indentation and its comment column (a new key goes at the end of its section). Every other
    line, comments included, is left as it was. KeyError when the section does not exist."""
    import tomlkit

    table = doc
    for part in filter(None, section.split(".")):
        table = table[part]
    item = tomlkit.item(value)
    old = table.item(key) if key in table else None
    if old is not None:
        item.trivia.indent, item.trivia.trail = old.trivia.indent, old.trivia.trail
    if comment:
        item.comment(comment)
        ws = 2
        if old is not None and old.trivia.comment:
            column = len(old.as_string()) + len(old.trivia.comment_ws)
            ws = max(2, column - len(item.as_string()))
        item.trivia.comment_ws = " " * ws
    table[key] = item
