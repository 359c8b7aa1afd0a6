"""Where the shipped data lives: the model files, profiles, meshes and FEM matrices.

The repository keeps them at the top level (``models/`` and ``fem_data/``); a wheel carries the
same folders as package data (``taos/shipped/models`` and ``taos/shipped/fem_data``, declared
in ``pyproject.toml``), read through :mod:`importlib.resources`. A source checkout (editable
install) reads the top-level folders directly.

A shipped file can be named without a path: ``rs25_hotfire`` is ``models/rs25_hotfire.toml``,
``greenrun_two_axis`` (as a profile) is ``models/profiles/greenrun_two_axis.toml``.
"""

from __future__ import annotations

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
    reader then reports it as missing)."""
    p = Path(path)
    if p.exists() or p.suffix or len(p.parts) != 1:
        return p
    cand = models_dir() / KIND_FOLDERS[kind] / f"{p.name}.toml"
    return cand if cand.is_file() else p
