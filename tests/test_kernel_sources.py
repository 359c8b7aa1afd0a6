"""The Makefile's KERNEL_SOURCES stays true (issue 28 item 5): every file whose code numba compiles
is in ``taos.cli.warmup.kernel_sources()`` (a change to it drops the kernel cache), checked
against the kernels actually loaded, not against the rule that made the list; and the warm-up's
shares compile every step once, whole groups each."""

from __future__ import annotations

import ast
import functools
import importlib
import re
import sys
import types
from pathlib import Path

import pytest

from taos.cli import warmup

ROOT = Path(__file__).resolve().parents[1]
TAOS = ROOT / "taos"
MASV = ROOT / "masv"
PKGS = ("taos", "masv")
NUMBA_IMPORT = re.compile(r"^\s*(import numba(\.\w+)*(\s+as\s+\w+)?\s*(#.*)?$|from numba(\.\w+)* import )", re.M)


@pytest.fixture(scope="module")
def sources() -> set[Path]:
    return {p.resolve() for p in warmup.kernel_sources()}


def _py_files():
    return [p for d in (TAOS, MASV) for p in d.rglob("*.py") if "__pycache__" not in p.parts]


def test_every_module_importing_numba_is_a_kernel_source(sources):
    importing = {p.resolve() for p in _py_files() if NUMBA_IMPORT.search(p.read_text(encoding="utf-8"))}
    assert importing, "no module imports numba?"
    assert importing <= sources, sorted(str(p.relative_to(ROOT)) for p in importing - sources)


def test_the_report_and_the_cli_are_not_kernel_sources(sources):
    """The point of the list: editing the report or the command line keeps the kernel cache."""
    for rel in ("taos/report/html.py", "taos/cli/__init__.py", "taos/viewer/__init__.py"):
        assert (ROOT / rel).resolve() not in sources, rel


@functools.cache
def _top_level_names(path: Path) -> frozenset[str]:
    """The names a module file assigns or defines at top level (each file parsed once)."""
    names = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
            node, (ast.AnnAssign, ast.AugAssign)) else []
        for t in targets:
            names |= {n.id for n in ast.walk(t) if isinstance(n, ast.Name)}
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
    return frozenset(names)


def _code_names(code: types.CodeType) -> set[str]:
    out = set(code.co_names)
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            out |= _code_names(c)
    return out


def _loaded_kernels():
    """Every numba kernel (dispatcher or C callback) in a loaded taos or masv module: py_func."""
    from numba.core.ccallback import CFunc
    from numba.core.dispatcher import Dispatcher

    from taos.friction.registry import load_all

    for rel in ("planar.dynamics", "planar._expstep", "planar._expplan", "planar.steady", "planar.saturation",
                "planar._avionics_kernels", "flight.lco_confirm", "taos3d.dynamics", "taos3d._bearing",
                "friction._kernels", "friction._vector"):
        importlib.import_module(f"taos.{rel}")
    importlib.import_module("masv._kernel")
    load_all()
    seen = set()
    for name, mod in list(sys.modules.items()):
        if not name.startswith(("taos.", "masv.")) or mod is None:
            continue
        for obj in vars(mod).values():
            fn = obj.py_func if isinstance(obj, Dispatcher) else obj._pyfunc if isinstance(obj, CFunc) else None
            if fn is not None and id(fn) not in seen:
                seen.add(id(fn))
                yield fn


def _file_of(obj) -> Path | None:
    from numba.core.ccallback import CFunc
    from numba.core.dispatcher import Dispatcher

    if isinstance(obj, types.ModuleType):
        f = getattr(obj, "__file__", None)
    elif isinstance(obj, Dispatcher):
        f = obj.py_func.__code__.co_filename
    elif isinstance(obj, CFunc):
        f = obj._pyfunc.__code__.co_filename
    elif isinstance(obj, types.FunctionType):
        f = obj.__code__.co_filename
    else:
        return None
    return Path(f).resolve() if f else None


def _definers(name: str, value) -> set[Path]:
    """The loaded taos and masv modules that assign ``name`` at top level to this very ``value``."""
    out = set()
    for mname, mod in list(sys.modules.items()):
        f = getattr(mod, "__file__", None)
        if mname.startswith(PKGS) and f and getattr(mod, name, object()) is value and name in _top_level_names(
                Path(f)):
            out.add(Path(f).resolve())
    return out


def test_every_loaded_kernel_and_what_it_reads_is_a_kernel_source(sources):
    """Each kernel's own file, every module, kernel and function its code names (``_dy.f``,
    ``K.lugre_zdot``), and the file defining every constant it reads (packed-slot indices, flags)."""
    kernels = list(_loaded_kernels())
    assert len(kernels) > 30
    for fn in kernels:
        own = Path(fn.__code__.co_filename).resolve()
        assert own in sources, (fn.__qualname__, own)
        g = fn.__globals__
        names = _code_names(fn.__code__)
        values = [(n, g[n]) for n in names if n in g]
        values += [(a, getattr(v, a)) for _, v in values if isinstance(v, types.ModuleType)
                   and v.__name__.startswith(PKGS) for a in names if hasattr(v, a)]
        for n, v in values:
            if isinstance(v, types.ModuleType) and not v.__name__.startswith(PKGS):
                continue
            f = _file_of(v)
            if f is not None:
                if f.is_relative_to(TAOS) or f.is_relative_to(MASV):
                    assert f in sources, (fn.__qualname__, n, f)
            elif isinstance(v, (int, float, tuple, frozenset, set, str)) and n not in _top_level_names(own):
                found = _definers(n, v)
                assert not found or found & sources, (fn.__qualname__, n, found)


def test_the_warm_up_shares_compile_every_step_once_in_whole_groups():
    for n in (1, 2, 3):
        shares = warmup.shares(n)
        steps = [s for share in shares for s in share]
        assert sorted(s.name for s in steps) == sorted(s.name for s in warmup.STEPS)
        groups = [{s.group for s in share} for share in shares]
        assert all(not (a & b) for i, a in enumerate(groups) for b in groups[i + 1:])
    costs = [sum(s.cost_s for s in share) for share in warmup.shares(2)]
    assert max(costs) < 0.6 * sum(costs)
