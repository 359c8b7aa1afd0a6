"""The examples gallery's runs, recorded for ``tests/test_examples.py`` under ``make test``.

sphinx-gallery (docs/conf.py) runs every ``examples/plot_*.py`` inside the Sphinx process, each
code block with the working folder set to the example's own folder (``examples/``; not
configurable). :func:`reset_example` is its ``reset_modules`` hook, called before and after
each example it runs (``reset_modules_order = "both"``; an example skipped as unchanged is not
run and gets no call). It

* puts back the friction-law registry: a law the example registered
  (:func:`taos.friction.register`) is removed after it, so no example sees another's law, as
  in a fresh interpreter;
* lists ``examples/`` (every file and folder with its size and modification time) before and
  after the example, for the test's check that examples write nothing into their working folder;
* writes ``docs/_generated/records/gallery_<example>.json``: the example's source hash, whether
  it failed, the output the gallery captured and shows (read back from the page it just
  wrote: the example's standard output and standard error together, as shown) and both listings.

The records folder is emptied at the start of every ``make test`` and ``make docs``, and every
build runs every example (``run_stale_examples``: an example unchanged since the previous
build's ``docs/gallery`` too), so after a successful build each record is this build's; one
missing, or of another source (:func:`read_record` checks its hash), makes the test run the
example itself. A page left in ``docs/gallery`` by an earlier build is never read by the tests.
sphinx-gallery's ``parallel`` option must stay off (the hook keeps its "before" state in this
process).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from .guide import _record_path

#: what :func:`reset_example` saw before the example now running: (working-folder listing, laws)
_BEFORE: dict[str, tuple[list, set]] = {}


def source_hash(path: Path) -> str:
    """SHA-256 of an example's source (bytes), hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def folder_listing(folder: Path) -> list[list]:
    """Every file and folder under ``folder``, recursively: [relative path, size in bytes (None
    for a folder), modification time in ns], sorted by path. Symbolic links are not followed."""
    out = []
    for dirpath, dirs, files in os.walk(folder):
        dirs.sort()
        for name in sorted(dirs + files):
            p = Path(dirpath, name)
            st = p.lstat()
            out.append([p.relative_to(folder).as_posix(), None if name in dirs else st.st_size, st.st_mtime_ns])
    return sorted(out)


def _runtime_laws() -> set[str]:
    """The friction laws registered at run time (not built in; read without loading any law)."""
    import sys

    registry = sys.modules.get("taos.friction.registry")
    if registry is None:
        return set()
    return {k for k, e in registry._REGISTRY.items() if not e.builtin}


def _folders(gallery_conf: dict, fname: str) -> tuple[Path, Path]:
    """(examples folder holding ``fname``, gallery folder its page goes to)."""
    src = Path(gallery_conf["src_dir"])
    ex, gal = gallery_conf["examples_dirs"], gallery_conf["gallery_dirs"]
    pairs = list(zip(ex if isinstance(ex, list) else [ex], gal if isinstance(gal, list) else [gal]))
    for e, g in pairs:
        if (src / e / fname).is_file():
            return src / e, src / g
    raise FileNotFoundError(f"gallery example {fname!r} in none of {pairs}")


_OUT_START = ".. rst-class:: sphx-glr-script-out\n\n .. code-block:: none\n\n"


def captured_output(page: str) -> str:
    """The text of every captured-output block of a sphinx-gallery page (its 4-space indent
    removed), blocks joined by newlines."""
    blocks = []
    for part in page.split(_OUT_START)[1:]:
        lines = []
        for line in part.splitlines():
            if line.startswith("    "):
                lines.append(line[4:])
            elif line.strip():
                break
            else:
                lines.append("")
        blocks.append("\n".join(lines).strip("\n"))
    return "\n".join(blocks)


def records_dir(docs_dir: Path) -> Path:
    return Path(docs_dir) / "_generated" / "records"


def reset_example(gallery_conf: dict, fname, when: str) -> None:
    """sphinx-gallery ``reset_modules`` hook (see the module docstring); ``fname`` the example's
    file name, ``when`` "before" or "after" it runs."""
    if fname is None:
        return
    fname = str(fname)
    examples, gallery = _folders(gallery_conf, fname)
    if when == "before":
        _BEFORE[fname] = (folder_listing(examples), _runtime_laws())
        return
    listing, laws = _BEFORE.pop(fname)
    after = folder_listing(examples)
    added = _runtime_laws() - laws
    if added:
        from taos import friction
        for law in added:
            friction.unregister(law)
    src = examples / fname
    error = gallery_conf.get("failing_examples", {}).get(os.path.normpath(src))
    page = (gallery / fname).with_suffix(".rst")
    rec = {"example": fname, "source_sha256": source_hash(src), "error": error,
           "output": captured_output(page.read_text(encoding="utf-8")) if page.is_file() else None,
           "folder_before": listing, "folder_after": after, "laws_registered": sorted(added)}
    records = records_dir(gallery_conf["src_dir"])
    records.mkdir(parents=True, exist_ok=True)
    _record_path(records, "gallery", fname).write_text(json.dumps(rec), encoding="utf-8")


def read_record(example: Path, records: Path) -> dict | None:
    """What the docs build recorded for ``example`` (see :func:`reset_example`), or None when it
    has no record of this very source."""
    p = _record_path(records, "gallery", Path(example).name)
    if not p.is_file():
        return None
    rec = json.loads(p.read_text(encoding="utf-8"))
    if rec["source_sha256"] != source_hash(example) or rec["output"] is None:
        return None
    return rec

