"""Every file an input load reads, and one content hash of them all.

The campaign's inputs are loaded once, on the client, inside :func:`recording`: a Python audit
hook (PEP 578, event ``open``) notes every file opened by this thread while it is active, so
files named by other files (the flight file an ascent names, the parameter sets and stiffness
file a model names, ...) are counted without each loader having to declare them. Python code,
compiled caches, taos's own cache folder (:func:`taos.units.cache_folder`) and files of installed packages other than taos's own shipped data are left out.
:func:`digest` hashes the contents (not the paths: a moved project with the same files resumes)
together with the settings that shape the runs.
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

_LOCAL = threading.local()
_HOOK = {"installed": False}
_CODE_SUFFIXES = {".py", ".pyc", ".pyd", ".so", ".nbi", ".nbc", ".pth"}


def _audit(event: str, args) -> None:
    files = getattr(_LOCAL, "files", None)
    if files is not None and event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        files.add(os.path.abspath(os.fsdecode(args[0])))


@contextmanager
def recording() -> Iterator[set[str]]:
    """Within the block, the set of files this thread opens (absolute paths). pint's unit
    registry is built first: the flight and ascent loaders ask for it on first use, and its
    start-up reads (pint's own cache, the system files its imports probe) are not inputs."""
    from taos.units import _registry

    _registry()
    if not _HOOK["installed"]:
        sys.addaudithook(_audit)
        _HOOK["installed"] = True
    _LOCAL.files = files = set()
    try:
        yield files
    finally:
        _LOCAL.files = None


def _is_input(path: str) -> bool:
    p = Path(path)
    if p.suffix in _CODE_SUFFIXES or "__pycache__" in p.parts or not p.is_file():
        return False
    import taos
    from taos.units import cache_folder
    own = Path(taos.__file__).resolve().parent
    rp = p.resolve()
    if cache_folder().resolve() in rp.parents:
        return False  # taos's own caches (the units table, read by the first model load of a process)
    if own in rp.parents:
        return True  # shipped data of an installed taos
    return not any(Path(pre).resolve() in rp.parents for pre in {sys.prefix, sys.base_prefix})


def digest(files: set[str], settings: str) -> tuple[str, list[dict]]:
    """(SHA-256 of the input files' contents and ``settings``, [{file, sha256}] sorted by path)."""
    table = []
    for f in sorted({os.path.abspath(f) for f in files if _is_input(f)}):
        table.append({"file": f, "sha256": hashlib.sha256(Path(f).read_bytes()).hexdigest()})
    h = hashlib.sha256(settings.encode())
    for s in sorted(t["sha256"] for t in table):
        h.update(s.encode())
    return h.hexdigest(), table
