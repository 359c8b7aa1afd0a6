"""The public API is typed: every callable in ``taos.__all__`` annotates each parameter and its
return (classes: their constructor's parameters), and both packages ship ``py.typed`` (PEP 561)
so that type checkers read those annotations from an installed taos."""

from __future__ import annotations

import inspect
import tomllib
from pathlib import Path

import taos

ROOT = Path(__file__).resolve().parents[1]


def _missing(name: str, obj) -> list[str]:
    sig = inspect.signature(obj)
    out = [f"{name}({p.name})" for p in sig.parameters.values()
           if p.annotation is inspect.Parameter.empty and p.name not in ("self", "cls")]
    if not inspect.isclass(obj) and sig.return_annotation is inspect.Signature.empty:
        out.append(f"{name} -> (return)")
    return out


def test_every_public_callable_is_annotated():
    checked, missing = 0, []
    for name in taos.__all__:
        obj = getattr(taos, name)
        if not callable(obj):   # e.g. LAWS, the friction-law registry (a mapping)
            continue
        missing += _missing(name, obj)
        checked += 1
    assert checked >= 30
    assert not missing, "public names without annotations: " + ", ".join(missing)


def test_annotation_check_sees_a_missing_annotation():
    def f(a, b: int):  # noqa: ANN001, ANN202 - on purpose
        return a

    assert _missing("f", f) == ["f(a)", "f -> (return)"]


def test_py_typed_is_package_data():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    data = cfg["tool"]["setuptools"]["package-data"]
    for pkg in ("taos", "masv"):
        assert (ROOT / pkg / "py.typed").is_file()
        assert "py.typed" in data.get(pkg, [])
