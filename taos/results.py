"""Result files: written atomically, never over a file the program did not write, with provenance.

* :func:`atomic_write` writes one file through a temporary file beside it
  (``.NAME.PID.taos.tmp``) renamed into place; a failure or a signal leaves the previous file
  intact and removes the temporary file; one left by a killed run (SIGKILL) is removed by the
  next run writing in that folder (:func:`clean_stale_temps`).
* :func:`write_output_folder` fills an output folder with the program's own files only: it
  records them in ``.taos-output.json`` (its mark) and replaces a file only if the mark lists
  it; foreign files are left alone, and a foreign file in the way of an output is refused
  (exit 2) before anything is written.
* :func:`base_provenance` (package version, git revision) and :func:`file_sha256` complete the
  provenance that every output carries.

An output place that cannot be written (a folder where a file is expected or the reverse, no
permission) is bad input: :class:`~taos.errors.InputError`, exit 2.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import subprocess
from functools import cache
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Mapping

if TYPE_CHECKING:  # h5py is imported where a file is written (start-up of the CLI)
    import h5py

from .errors import InputError

MARK = ".taos-output.json"
_TMP_RE = re.compile(r"^\..+\.(\d+)\.taos\.tmp$")  # only this program's own temporaries


def package_version() -> str:
    """taos's own version: the installed distribution's (``taos-tvc``) metadata, else
    ``taos.__version__`` (a source tree on the path, not installed)."""
    try:
        return metadata.version("taos-tvc")
    except metadata.PackageNotFoundError:
        from . import __version__
        return __version__


def _git(folder: Path, *args: str) -> str | None:
    """stdout of ``git -C folder args`` (stripped), or None when git fails or is missing."""
    try:
        r = subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return r.stdout.strip() if r.returncode == 0 else None


def own_checkout(package_dir: Path) -> Path | None:
    """The root of taos's own git checkout when ``package_dir`` is its ``taos/`` folder, else None.

    taos's own checkout: ``package_dir`` is ``<root>/taos``, ``<root>/pyproject.toml`` names the
    project ``taos-tvc`` and ``<root>`` is the top level of a git work tree. Installed (or
    copied) inside another project's git repository, the package is not in its own checkout, and
    that project's commit is not taos's revision."""
    import tomllib
    root = package_dir.resolve().parent
    if package_dir.resolve().name != "taos":
        return None
    try:
        name = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]["name"]
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, KeyError, TypeError):
        return None
    if name != "taos-tvc":
        return None
    top = _git(root, "rev-parse", "--show-toplevel")
    return root if top and Path(top).resolve() == root else None


@cache
def git_revision(package_dir: Path | None = None) -> str:
    """``git describe --always --dirty`` of taos's own source checkout when the package runs
    from one (:func:`own_checkout`), else '' (an installed package: its version is
    :func:`package_version`). ``package_dir`` defaults to this package's folder."""
    root = own_checkout(Path(__file__).resolve().parent if package_dir is None else Path(package_dir))
    if root is None:
        return ""
    return _git(root, "describe", "--always", "--dirty", "--abbrev=40") or ""


def base_provenance() -> dict:
    """Package version and git revision (when the package runs from its own git checkout)."""
    return {"package_version": package_version(), "git_revision": git_revision()}


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (hex), or '' when it cannot be read."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return ""
    return h.hexdigest()


def output_provenance(models=(), inputs=()) -> dict:
    """Provenance block of a JSON output: package version, git revision, and the path and
    SHA-256 of each model (``TvcModel``: ``model_sha256`` the combined hash of the model file and
    the shared files it names, ``model_inputs`` each one's path and hash) and input file
    (``(kind, path)``)."""
    out = base_provenance()
    for i, m in enumerate(models):
        sfx = "" if len(models) == 1 else f"_{i + 1}"
        out[f"model_file{sfx}"] = str(m.source)
        out[f"model_sha256{sfx}"] = m.sha256
        if getattr(m, "input_files", None):   # per-file hashes behind the combined model_sha256
            out[f"model_inputs{sfx}"] = {r: {"file": f, "sha256": h} for r, (f, h) in m.input_files.items()}
    for i, (kind, path) in enumerate(inputs):
        sfx = "" if sum(k == kind for k, _ in inputs) == 1 else f"_{i + 1}"
        out[f"{kind}_file{sfx}"] = str(path)
        out[f"{kind}_sha256{sfx}"] = file_sha256(path)
    return out


def input_provenance(path, kind: str, prov: dict | None = None) -> dict:
    """``{kind}_file`` (resolved path) and ``{kind}_sha256`` of an input file, plus the SHA-256
    of the stiffness file named in ``prov['stiffness_source']`` (3-D runs) when it is a file."""
    from .shipped import resolve

    p = resolve(path, kind) if kind in ("model", "profile", "flight", "masv", "data") else Path(path)
    out = {f"{kind}_file": str(p), f"{kind}_sha256": file_sha256(p)}
    src = (prov or {}).get("stiffness_source")
    if src and "stiffness_sha256" not in (prov or {}) and Path(str(src)).is_file():
        out["stiffness_sha256"] = file_sha256(src)
    return out


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_stale_temps(folder: str | Path) -> list[Path]:
    """Remove temporary files and folders left in ``folder`` by killed runs (their process is
    gone); returns what was removed."""
    import shutil

    removed = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    for p in entries:
        m = _TMP_RE.match(p.name)
        if not m:
            continue
        pid = int(m.group(1))
        if _pid_alive(pid) and pid != os.getpid():
            continue
        if pid == os.getpid():
            continue
        try:
            shutil.rmtree(p) if p.is_dir() and not p.is_symlink() else p.unlink()
            removed.append(p)
        except OSError:
            pass
    return removed


def _output_error(path, e: OSError, field: str = "(output)"):
    return InputError(str(path), field, "a place this program can write", got=e.strerror or str(e))


def check_output_file(path: str | Path, field: str = "(output)", suffixes: tuple[str, ...] = ()) -> Path:
    """Refuse an output file place that is an existing folder or whose parent is not a folder
    (and, with ``suffixes``, a name not ending in one of them)."""
    p = Path(path)
    if suffixes and p.suffix.lower() not in suffixes:
        raise InputError(str(path), field, "a file name ending in " + " or ".join(suffixes), got=repr(p.suffix))
    if p.is_dir():
        raise InputError(str(path), field, "a file name (not a folder)", got="an existing folder")
    parent = p.parent
    for q in [parent, *parent.parents]:
        if q.exists():
            if not q.is_dir():
                raise InputError(str(path), field, "a path inside folders", got=f"{q} is a regular file")
            break
    return p


def _tmp_name(path: Path) -> Path:
    return path.parent / f".{path.name}.{os.getpid()}.taos.tmp"


def _mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> None:
    """Call ``write(tmp)`` on a temporary path beside ``path`` and rename it into place only
    if it succeeds, so a failed or interrupted run leaves the previous file and no partial one."""
    path = check_output_file(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise _output_error(path, e) from None
    clean_stale_temps(path.parent)
    tmp = _tmp_name(path)
    try:
        try:
            write(tmp)
            os.chmod(tmp, _mode())  # the usual mode (h5py and mkstemp differ)
            os.replace(tmp, path)
        except OSError as e:
            raise _output_error(path, e) from None
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise


def _read_mark(folder: Path) -> set[str]:
    try:
        return set(json.loads((folder / MARK).read_text()).get("files", []))
    except (OSError, ValueError, AttributeError):
        return set()


def check_output_folder(out: str | Path, names, field: str = "--out") -> Path:
    """Refuse, before any work, an output folder that is a regular file, sits under one, or
    holds a file of one of ``names`` that this program did not write."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(str(out), field, "an output folder (or a new name)", got="an existing regular file")
    check_output_file(out / "x", field)
    if out.is_dir():
        owned = _read_mark(out)
        for name in names:
            p = out / name
            if os.path.lexists(p) and name not in owned:
                raise InputError(str(p), field, "a folder whose files of that name this program wrote "
                                 "(it never replaces a file it did not write)", got="a file it did not write")
            if p.is_dir():
                raise InputError(str(p), field, "a file place", got="an existing folder")
        if not os.access(out, os.W_OK | os.X_OK):
            raise InputError(str(out), field, "a folder this program can write", got="no permission")
    return out


def write_output_folder(out: str | Path, files: Mapping[str, Callable[[Path], None]],
                        field: str = "--out") -> Path:
    """Write ``files`` (name -> ``write(tmp_path)``) into folder ``out``.

    Refuses (InputError, before writing anything) an ``out`` that is a regular file, and a
    file of the same name as an output that this program did not write. Every output is first
    written to a temporary file in ``out``; only when all are complete are they renamed into
    place (the previous result stays whole until then). Foreign files are never touched."""
    out = check_output_folder(out, list(files), field)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise _output_error(out, e, field) from None
    owned = _read_mark(out)
    clean_stale_temps(out)
    tmps: dict[str, Path] = {}
    mode = _mode()
    try:
        try:
            for name, write in files.items():
                tmps[name] = _tmp_name(out / name)
                write(tmps[name])
                os.chmod(tmps[name], mode)
            mark = _tmp_name(out / MARK)
            tmps[MARK] = mark
            mark.write_text(json.dumps({"written_by": "taos", "files": sorted(owned | set(files))}, indent=1) + "\n")
            for name, tmp in tmps.items():
                os.replace(tmp, out / name)
        except OSError as e:
            raise _output_error(out, e, field) from None
    except BaseException:
        for tmp in tmps.values():
            if os.path.lexists(tmp):
                os.unlink(tmp)
        raise
    return out


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
        h5.attrs[k] = v if isinstance(v, (str, int, float)) else json.dumps(v, sort_keys=True)


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
