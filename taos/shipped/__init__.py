"""Where the shipped data lives: the model files, profiles, meshes and FEM matrices.

The repository keeps them at the top level (``models/`` and ``fem_data/``); a wheel carries the
same folders as package data (``taos/shipped/models`` and ``taos/shipped/fem_data``, declared
in ``pyproject.toml``), read through :mod:`importlib.resources`. A source checkout (editable
install) reads the top-level folders directly.

A shipped file can be named without a path: ``rs25_hotfire`` is ``models/rs25_hotfire.toml``,
``greenrun_two_axis`` (as a profile) is ``models/profiles/greenrun_two_axis.toml``.
"""

from __future__ import annotations

import os
from functools import cache
from importlib import resources
from pathlib import Path

#: sub-folder of models/ for each kind of input file
KIND_FOLDERS = {"model": "", "profile": "profiles", "flight": "flight", "masv": "masv",
                "campaign": "montecarlo", "data": "data", "spec": "specs"}


def _package_dir(name: str) -> Path | None:
    """The package-data folder ``taos/shipped/<name>`` of an installed wheel, or None.

    Resolved from this regular package: ``taos.shipped.<name>`` has no ``__init__.py`` (a
    namespace package), and ``importlib.resources.files`` of a namespace package is a
    MultiplexedPath, whose str() is not a folder path."""
    p = Path(str(resources.files(__name__) / name))
    return p if p.is_dir() else None


@cache
def _root(name: str) -> Path:
    here = Path(__file__).resolve().parents[2] / name  # source checkout: <repo>/models, <repo>/fem_data
    if here.is_dir():
        return here
    p = _package_dir(name)
    if p is None:
        raise FileNotFoundError(f"shipped data folder {name!r} not found beside the package or in it")
    return p


def models_dir() -> Path:
    """The shipped ``models/`` folder."""
    return _root("models")


def fem_data_dir() -> Path:
    """The shipped ``fem_data/`` folder."""
    return _root("fem_data")


def shipped_names(kind: str = "model") -> list[str]:
    """Names (file stems) of the shipped files of one kind (:data:`KIND_FOLDERS`)."""
    folder = models_dir() / KIND_FOLDERS[kind]
    return sorted(p.stem for p in folder.glob("*.toml"))


def resolve(path: str | Path, kind: str = "model") -> Path:
    """``path`` itself when it exists (or has a folder part or a suffix); otherwise the shipped
    file of that name and kind when there is one; otherwise ``path`` unchanged (the caller's
    reader then reports it as missing). Anything but a path (text or ``os.PathLike``) is
    :class:`~taos.errors.InputError`, as a bad path on the command line is."""
    from taos.errors import InputError

    if isinstance(path, bool) or not isinstance(path, (str, os.PathLike)) or path in ("", b""):
        raise InputError(repr(path)[:40], "(file)", f"a {kind} file: a path (text or a pathlib.Path) or a "
                         "shipped name", got="an empty path" if isinstance(path, str) else type(path).__name__)
    if isinstance(path, str) and "\x00" in path:
        raise InputError(repr(path)[:40], "(file)", f"a {kind} file path", got="a path with a NUL character")
    p = Path(path)
    if p.exists() or p.suffix or len(p.parts) != 1:
        return p
    cand = models_dir() / KIND_FOLDERS[kind] / f"{p.name}.toml"
    return cand if cand.is_file() else p


@cache
def _resolved(p: Path) -> Path:
    return p.resolve()


def _resolved_roots() -> tuple[Path, ...]:
    """The shipped data folders (models/, fem_data/), each resolved once a process (the folders
    come from :func:`_root` at every call: a test may replace it)."""
    roots = []
    for name in ("models", "fem_data"):
        try:
            roots.append(_resolved(_root(name)))
        except FileNotFoundError:
            pass
    return tuple(roots)


def _within_shipped(p: Path) -> bool:
    """Whether ``p`` lies in the shipped data (the models/ or fem_data/ folder)."""
    return any(p == r or r in p.parents for r in _resolved_roots())


def reference_places(ref: str, referring_file: str | Path, kind: str = "model") -> tuple[Path, Path | None]:
    """The two places :func:`resolve_reference` looks for ``ref`` named inside ``referring_file``
    (a file of ``kind``, :data:`KIND_FOLDERS`): beside the referring file, then the same path
    from that kind's shipped folder (None when ``ref`` is absolute or leads out of the shipped
    data); neither resolved."""
    r = Path(ref)
    here = Path(referring_file).parent / r     # an absolute ref: r itself
    if r.is_absolute():
        return here, None
    shipped = models_dir() / KIND_FOLDERS[kind] / r
    return here, (shipped if _within_shipped(shipped.resolve()) else None)


def resolve_reference(ref, referring_file: str | Path, *, field: str, what: str = "a file",
                      kind: str = "model") -> Path:
    """The one rule for a file named inside another file (parameter sets, stiffness files,
    flight, ascent and TVC model files, modal files, MASV references).

    ``ref`` is a path written relative to the referring file. It is looked for

    1. relative to the folder of ``referring_file`` (an absolute ``ref``: as given, nowhere else);
    2. else as the same relative path from the shipped folder of the referring file's ``kind``
       (``models/`` for a model file, ``models/flight/`` for a flight or ascent file, ...: the
       place a shipped file of that kind lives), so a shipped file copied alone to another
       folder still finds the shipped files it names (``../fem_data/gimbal_thrust.npz`` from
       ``models/`` is the shipped ``fem_data/gimbal_thrust.npz``, in a checkout and in a wheel).

    Something at the first place wins, whatever it is (its reader then checks it). Returns the
    resolved absolute path; raises :class:`~taos.errors.InputError` (one line naming the
    referring file, the ``field`` and the places looked) when it is in neither place."""
    from taos.errors import InputError

    if not isinstance(ref, str) or not ref:
        raise InputError(str(referring_file), field, f"a path to {what}", got=repr(ref)[:60])
    here, shipped = reference_places(ref, referring_file, kind)
    from taos.errors import stored

    for place in (here, shipped):
        if place is not None and (os.path.lexists(place) or stored(place.resolve()) is not None):
            return place.resolve()
    here = here.resolve()
    where = f"{here}" if shipped is None else f"{here} (beside the file) or {shipped.resolve()} (shipped)"
    raise InputError(str(referring_file), field, f"{what} at {where}", got=f"no such file {ref!r}")
