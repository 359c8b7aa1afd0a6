"""Result files: written atomically, never over a file the program did not write, with provenance.

The rule (docs/reference/outputs.md, "What an output may replace"):

* An output never replaces an input of the run (the same file, or a link to it: compared by
  device and inode), ``--force`` or not.
* An output never replaces a device, FIFO, socket or folder; ``/dev/null`` is taken as the user
  means it: the output is made and thrown away.
* An existing regular file (or symbolic link) is replaced only when this program wrote it: every
  folder it writes in holds its mark ``.taos-output.json`` listing the files it wrote there
  (under an exclusive lock of the folder, so concurrent runs see each other's files). Any other
  file is refused (exit 2) before any work unless the user says ``--force``.
* :func:`atomic_write` writes one file through a temporary file beside it
  (``.NAME.PID.TOKEN.taos.tmp``, TOKEN 128 random bits) renamed into place; the mark lists the
  temporary before it is made, so the temporaries of a killed run (SIGKILL) are removed by the
  next run writing in that folder (:func:`clean_stale_temps`) and nothing else ever is.
* :func:`write_output_folder` fills an output folder with the program's own files only, all
  complete or none replaced; foreign files are left alone.
* :func:`base_provenance` (package version, git revision) and :func:`file_sha256` complete the
  provenance that every output carries.

An output place that cannot be written (a folder where a file is expected or the reverse, no
permission, a name too long) is bad input: :class:`~taos.errors.InputError`, exit 2.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import math
import os
import re
import secrets
import shutil
import stat
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Mapping

if TYPE_CHECKING:  # h5py is imported where a file is written (start-up of the CLI)
    import h5py

from .errors import _FORCE, InputError, stat_key, check_not_input, note_input, output_policy  # noqa: F401

MARK = ".taos-output.json"
MAX_MARK_BYTES = 16 * 2 ** 20
_TMP_RE = re.compile(r"^\..+\.(\d+)\.[0-9a-f]{32}\.taos\.tmp$")  # .NAME.PID.TOKEN.taos.tmp


def package_version() -> str:
    """taos's own version: the installed distribution's (``taos-tvc``) metadata, else
    ``taos.__version__`` (a source tree on the path, not installed)."""
    from importlib import metadata

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
    """SHA-256 of a file's bytes (hex), or '' when it cannot be read. A regular file's hash is
    remembered under its :func:`stat_key` (model variants hash the same files again and again)."""
    from .errors import stored

    kept = stored(path)
    if kept is not None:
        return kept[1]
    key = stat_key(path)
    if key is None:
        return _file_sha256(path)
    sys.audit("open", str(path), "rb", os.O_RDONLY)   # read, as far as anyone recording inputs can tell
    return _cached_sha256(key)


@functools.lru_cache(maxsize=256)
def _cached_sha256(key: tuple) -> str:
    return _file_sha256(key[0])


def _file_sha256(path: str | Path) -> str:
    h = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return ""
    return h.hexdigest()


def model_provenance(model: object) -> dict:
    """What every output says of the model that produced it: ``model_file``, ``model_name``,
    ``model_sha256`` (the variant's own hash), and for a modified model also
    ``model_file_sha256`` (the files' combined hash) and ``model_overrides`` (key -> value as a
    model file holds it; ``code.*`` for changes made in code with
    :meth:`~taos.model.TvcModel.replace`; :mod:`taos.variants`). A 3-D model is described by its
    planar base."""
    m = getattr(model, "base", model)
    out = {"model_file": str(m.source), "model_name": m.name, "model_sha256": m.sha256}
    if getattr(m, "overrides", ()):
        out["model_file_sha256"] = m.base_sha256
        out["model_overrides"] = {k: v if isinstance(v, (str, int, float, bool, list)) else repr(v)
                                  for k, v in m.overrides}
    return out


def output_provenance(models=(), inputs=()) -> dict:
    """Provenance block of a JSON output: package version, git revision, and the path and
    SHA-256 of each model (``TvcModel``: ``model_sha256`` the combined hash of the model file and
    the shared files it names, ``model_inputs`` each one's path and hash) and input file
    (``(kind, path)``)."""
    out = base_provenance()
    for i, m in enumerate(models):
        sfx = "" if len(models) == 1 else f"_{i + 1}"
        out.update({f"{k}{sfx}": v for k, v in model_provenance(m).items() if k != "model_name"})
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


# -- output safety: the folder mark, the replace policy, temporaries -------------------------

_NAME_MAX = 255


def _read_mark_doc(folder: Path) -> dict:
    """The folder's mark (``{"written_by": "taos", "files": [...], "pending": [...]}``); an empty
    one when there is none; InputError when a file of that name is not this program's mark."""
    p = folder / MARK
    if not os.path.lexists(p):
        return {"written_by": "taos", "files": [], "pending": []}
    try:
        if not stat.S_ISREG(os.lstat(p).st_mode) or os.path.getsize(p) > MAX_MARK_BYTES:
            raise ValueError
        d = json.loads(p.read_text(encoding="utf-8"))
        if not isinstance(d, dict) or not isinstance(d.get("files"), list) or d.get("written_by", "taos") != "taos":
            raise ValueError
        return {"written_by": "taos", "files": [str(x) for x in d.get("files", [])],
                "pending": [str(x) for x in d.get("pending", [])]}
    except (OSError, ValueError, TypeError, AttributeError):
        raise InputError(str(p), "(output)", f"this program's own mark {MARK} (it keeps its list of "
                         "written files there)", got="a file it did not write") from None


def _read_mark(folder: Path) -> set[str]:
    try:
        return set(_read_mark_doc(folder)["files"])
    except InputError:
        return set()


@contextmanager
def _locked_mark(folder: Path):
    """The folder's mark, read and rewritten under an exclusive lock of the folder (concurrent
    writers of one folder each see the other's files)."""
    import fcntl

    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        mark = _read_mark_doc(folder)
        before = json.dumps(mark, sort_keys=True)
        yield mark
        if json.dumps(mark, sort_keys=True) != before:
            mark["files"], mark["pending"] = sorted(set(mark["files"])), sorted(set(mark["pending"]))
            (folder / MARK).write_text(json.dumps(mark, indent=1) + "\n", encoding="utf-8")
    finally:
        os.close(fd)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def _clean_pending(folder: Path, mark: dict) -> list[Path]:
    removed = []
    for name in list(mark["pending"]):
        m = _TMP_RE.match(name)
        if m is None or (int(m.group(1)) != os.getpid() and _pid_alive(int(m.group(1)))):
            continue
        if int(m.group(1)) == os.getpid():
            continue
        p = folder / name
        try:
            if os.path.lexists(p):
                shutil.rmtree(p) if p.is_dir() and not p.is_symlink() else p.unlink()
                removed.append(p)
        except OSError:
            continue
        mark["pending"].remove(name)
    return removed


def clean_stale_temps(folder: str | Path) -> list[Path]:
    """Remove the temporaries of killed runs in ``folder``: only those this program listed in
    the folder's mark before creating them, and only when their process is gone."""
    folder = Path(folder)
    if not (folder / MARK).is_file():
        return []
    try:
        with _locked_mark(folder) as mark:
            return _clean_pending(folder, mark)
    except (OSError, InputError):
        return []


def _output_error(path, e: OSError, field: str = "(output)"):
    return InputError(str(path), field, "a place this program can write", got=e.strerror or str(e))


def _is_dev_null(path: Path) -> bool:
    try:
        return os.path.samefile(path, os.devnull)
    except OSError:
        return False


def check_output_file(path: str | Path, field: str = "(output)", suffixes: tuple[str, ...] = (),
                      inputs=()) -> Path:
    """Refuse, before any work, an output file place that cannot take this program's output:
    a name ending in none of ``suffixes``; a name too long for the file system; an existing
    folder, device, FIFO or socket (``/dev/null`` is allowed: the output is discarded); a path
    under a regular file; one of ``inputs`` or an input read so far; an existing file (or
    symbolic link) that this program did not write (its folder's mark does not list it),
    unless ``--force``."""
    p = Path(path)
    if _is_dev_null(p):   # the user plainly means: make it and throw it away
        return p
    if suffixes and p.suffix.lower() not in suffixes:
        raise InputError(str(path), field, "a file name ending in " + " or ".join(suffixes), got=repr(p.suffix))
    if len(str(p)) > 4000 or any(len(os.fsencode(part)) > _NAME_MAX - 60 for part in p.parts):
        raise InputError(str(path)[:80] + "...", field, f"a file name of at most {_NAME_MAX - 60} bytes "
                         "per folder level", got=f"{max(len(os.fsencode(x)) for x in p.parts)} bytes")
    try:
        st = os.lstat(p)
    except (FileNotFoundError, NotADirectoryError):
        st = None
    except OSError as e:
        raise _output_error(path, e, field) from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise InputError(str(path), field, "a file name (not a folder)", got="an existing folder")
        if not (stat.S_ISREG(st.st_mode) or stat.S_ISLNK(st.st_mode)):
            raise InputError(str(path), field, "a regular file place (or /dev/null)",
                             got="a device, FIFO or socket (never replaced)")
        check_not_input(p, field, inputs)
        if p.name not in _read_mark(p.parent) and not _FORCE.get():
            raise InputError(str(path), field, "a new file, or one this program wrote (it never replaces a "
                             "file it did not write; --force replaces it)", got="an existing file it did not write")
    parent = p.parent
    for q in [parent, *parent.parents]:
        if q.exists():
            if not q.is_dir():
                raise InputError(str(path), field, "a path inside folders", got=f"{q} is a regular file")
            break
    return p


def _tmp_name(path: Path) -> Path:
    return path.parent / f".{path.name[:80]}.{os.getpid()}.{secrets.token_hex(16)}.taos.tmp"


def _mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _discard(write: Callable[[Path], None], name: str) -> None:
    """``/dev/null`` as output: make the output in a private folder and throw it away."""
    with tempfile.TemporaryDirectory(prefix="taos-devnull-") as d:
        write(Path(d) / name)


def atomic_write(path: str | Path, write: Callable[[Path], None], field: str = "(output)") -> None:
    """Call ``write(tmp)`` on a temporary path beside ``path`` and rename it into place only
    if it succeeds, so a failed or interrupted run leaves the previous file and no partial one.

    The place is checked by :func:`check_output_file` (never an input, a device or a file this
    program did not write); the file's folder mark lists the temporary before it is made (so
    that only this program's own temporaries are ever cleaned) and the file once written."""
    path = check_output_file(path, field)
    if _is_dev_null(path):
        return _discard(write, "output" + path.suffix)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with _locked_mark(path.parent) as mark:
            _clean_pending(path.parent, mark)
            tmp = _tmp_name(path)
            mark["pending"].append(tmp.name)
    except OSError as e:
        raise _output_error(path, e, field) from None
    try:
        try:
            write(tmp)
            os.chmod(tmp, _mode())  # the usual mode (h5py and mkstemp differ)
            with _locked_mark(path.parent) as mark:
                check_output_file(path, field)  # again: another writer may have come in between
                os.replace(tmp, path)
                mark["files"].append(path.name)
                mark["pending"].remove(tmp.name)
        except OSError as e:
            raise _output_error(path, e, field) from None
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        with contextlib.suppress(OSError, InputError, ValueError), _locked_mark(path.parent) as mark:
            mark["pending"].remove(tmp.name)
        raise


def check_output_folder(out: str | Path, names, field: str = "--out") -> Path:
    """Refuse, before any work, an output folder that is a regular file, sits under one, or
    holds a file of one of ``names`` that this program did not write (``--force`` lets it
    replace a foreign regular file), or a device, FIFO, socket or folder in place of one."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(str(out), field, "an output folder (or a new name)", got="an existing regular file")
    check_output_file(out / "x", field)
    if out.is_dir():
        owned = _read_mark_doc(out)["files"]
        for name in names:
            p = out / name
            if p.is_dir() and not p.is_symlink():
                raise InputError(str(p), field, "a file place", got="an existing folder")
            if os.path.lexists(p) and name not in owned:
                check_output_file(p, field)
            elif os.path.lexists(p):
                check_not_input(p, field)
        if not os.access(out, os.W_OK | os.X_OK):
            raise InputError(str(out), field, "a folder this program can write", got="no permission")
    return out


def write_output_folder(out: str | Path, files: Mapping[str, Callable[[Path], None]],
                        field: str = "--out") -> Path:
    """Write ``files`` (name -> ``write(tmp_path)``) into folder ``out``.

    Refuses (InputError, before writing anything) what :func:`check_output_folder` refuses.
    Every output is first written to a temporary file in ``out`` (listed in the mark first);
    only when all are complete are they renamed into place (the previous result stays whole
    until then). Foreign files are never touched."""
    out = check_output_folder(out, list(files), field)
    try:
        out.mkdir(parents=True, exist_ok=True)
        with _locked_mark(out) as mark:
            _clean_pending(out, mark)
            tmps = {name: _tmp_name(out / name) for name in files}
            mark["pending"] += [t.name for t in tmps.values()]
    except OSError as e:
        raise _output_error(out, e, field) from None
    mode = _mode()
    try:
        try:
            for name, write in files.items():
                write(tmps[name])
                os.chmod(tmps[name], mode)
            with _locked_mark(out) as mark:
                check_output_folder(out, list(files), field)
                for name, tmp in tmps.items():
                    os.replace(tmp, out / name)
                    mark["pending"].remove(tmp.name)
                mark["files"] += list(files)
        except OSError as e:
            raise _output_error(out, e, field) from None
    except BaseException:
        for tmp in tmps.values():
            if os.path.lexists(tmp):
                os.unlink(tmp)
        with contextlib.suppress(OSError, InputError, ValueError), _locked_mark(out) as mark:
            mark["pending"] = [n for n in mark["pending"] if n not in {t.name for t in tmps.values()}]
        raise
    return out


def _first_non_finite(obj, where: str = "") -> str | None:
    """Dotted key of the first NaN or infinite number in a JSON payload, or None."""
    if isinstance(obj, float):
        return where or "(value)" if not math.isfinite(obj) else None
    if isinstance(obj, Mapping):
        items = ((f"{where}.{k}" if where else str(k), v) for k, v in obj.items())
    elif isinstance(obj, (list, tuple)):
        items = ((f"{where}[{i}]", v) for i, v in enumerate(obj))
    else:
        return None
    for w, v in items:
        hit = _first_non_finite(v, w)
        if hit is not None:
            return hit
    return None


def write_json(path: str, payload: dict) -> None:
    """JSON to ``path`` ('-' is standard output), atomically for files. A NaN or infinite
    value is refused (InputError naming its key: the inputs led to a non-finite figure) and
    nothing is written."""
    try:
        text = json.dumps(payload, indent=2, allow_nan=False)
    except ValueError:
        key = _first_non_finite(payload) or "(value)"
        raise InputError(str(path), key, "finite numbers in the output (the inputs led to a NaN or "
                         "infinite figure; nothing was written)", got="a non-finite value") from None
    if path == "-":
        print(text)
        return
    atomic_write(path, lambda p: p.write_text(text + "\n"), field="--json")


def write_provenance(h5: h5py.File, provenance: dict) -> None:
    """Store provenance as attributes of the root group (JSON for nested values). HDF5 text is
    UTF-8: a file name whose bytes are not (read under ``LANG=C``, held as surrogate escapes)
    is stored with those bytes written as ``\\xNN``."""
    for k, v in provenance.items():
        v = v if isinstance(v, (str, int, float)) else json.dumps(v, sort_keys=True)
        h5.attrs[k] = v.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace") if isinstance(v, str) else v


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


#: options that name an output place (file or folder); every other path argument is an input
OUTPUT_OPTIONS = ("json", "out", "plot", "html", "df_out", "out_model", "plot_df", "plot_time", "plot_map")
#: options that name an output file (``--out`` is a file or a folder, checked by its command)
_OUTPUT_FILE_OPTIONS = {"json": (), "html": (".html", ".htm"), "df_out": (), "out_model": (),
                        "plot": (".png", ".svg"), "plot_df": (".png", ".svg"), "plot_time": (".png", ".svg"),
                        "plot_map": (".png", ".svg")}


from taos.argpaths import check_environment, input_paths as _input_paths, same_place as _same_place  # noqa: E402


def check_arguments(args) -> None:
    """Checks every ``taos`` command shares, before any work (:func:`taos.errors.run_cli`'s
    ``check``): a seed is a 32-bit unsigned whole number; an output option is not empty, is not
    one of the inputs (nor a link to one) and names a place :func:`check_output_file` accepts;
    the environment as :func:`taos.argpaths.check_environment` says."""
    check_environment()
    seed = getattr(args, "seed", None)
    if isinstance(seed, int) and not 0 <= seed < 2 ** 32:
        raise InputError("command line", "--seed", "a whole number from 0 to 4294967295", got=str(seed))
    inputs = _input_paths(args, OUTPUT_OPTIONS)
    named = []   # (option, value) of every output named so far: no two outputs are one file
    for k in OUTPUT_OPTIONS:
        v = getattr(args, k, None)
        if v is None or v == "-":
            continue
        opt = "--" + k.replace("_", "-")
        if not isinstance(v, str) or not v.strip():
            raise InputError("command line", opt, "a file or folder name", got=repr(v))
        check_not_input(v, opt, inputs)
        for o, w in named:
            if _same_place(v, w):
                raise InputError("command line", opt, f"a place of its own (not the {o} output's)", got=repr(v))
        named.append((opt, v))
        if k in _OUTPUT_FILE_OPTIONS:
            check_output_file(v, opt, _OUTPUT_FILE_OPTIONS[k])
