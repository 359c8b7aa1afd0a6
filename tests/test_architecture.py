"""The package layers do not look back.

Every module of ``taos`` and ``masv`` is parsed with :mod:`ast` (imports inside functions and
in ``if TYPE_CHECKING:`` blocks included: a type-only import cycle is still a cycle, and the
modules it ties cannot be read or moved apart), the module import graph is built, and the rules
below are checked:

* no import cycles (a strongly connected component of more than one module, or a self-import);
* nothing below the command line imports it: only ``taos.cli.*`` and ``masv.cli`` (itself a
  command line) may import ``taos.cli``.

The public API is checked from a fresh interpreter: ``import taos`` lists ``__all__`` and every
name in it resolves; ``python -m taos --help`` works.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("taos", "masv")



def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


MODULES = _modules()


def _imported(tree: ast.AST, module: str, is_package: bool) -> set[str]:
    """Every module name imported anywhere in ``tree`` (relative imports resolved)."""
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".")
                if not is_package:
                    base = base[:-1]
                base = base[: len(base) - (node.level - 1)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            # ``from pkg import sub`` imports the submodule pkg.sub when there is one, else a
            # name defined in pkg (resolved against the module list in import_graph)
            found.update(f"{prefix}.{alias.name}" if f"{prefix}.{alias.name}" in MODULES
                         else prefix for alias in node.names)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def import_graph() -> dict[str, set[str]]:
    """module -> the project modules it imports (edges to modules that exist only)."""
    modules = MODULES
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(), filename=str(path))
        targets = _imported(tree, name, path.name == "__init__.py")
        edges = set()
        for target in targets:
            # importing a.b.c runs a/__init__ and a.b/__init__ too, but those package
            # initialisers are the lazy API tables; the edge that matters is the module named
            if target in modules and target != name:
                edges.add(target)
        graph[name] = edges
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of size > 1 (Tarjan, iterative-safe for this size)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def strong(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return out


def test_graph_sees_function_level_imports():
    tree = ast.parse("def f():\n    from taos.cli import main\n")
    assert "taos.cli" in _imported(tree, "taos.x", False)
    tree = ast.parse("from ..plotting import fit\n")
    assert "taos.plotting.fit" in _imported(tree, "taos.identify.compare", False)
    tree = ast.parse("from taos import load_model\n")
    assert _imported(tree, "taos.x", False) == {"taos"}
    tree = ast.parse("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .registry import E\n")
    assert "taos.friction.registry" in _imported(tree, "taos.friction._laws", False)


def test_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_import_cycles():
    cycles = _cycles(import_graph())
    assert not cycles, "import cycles: " + "; ".join(" <-> ".join(c) for c in cycles)


def _is_cli(module: str) -> bool:
    return module == "taos.cli" or module.startswith("taos.cli.") or module in (
        "masv.cli", "taos.__main__")


def test_nothing_below_the_cli_imports_it():
    offenders = sorted(f"{m} imports {t}" for m, targets in import_graph().items()
                       if not _is_cli(m) for t in targets if _is_cli(t))
    assert not offenders, "; ".join(offenders)


#: the layers of taos/__init__.py's docstring, bottom (1) to top; masv sits on taos
LAYERS = {
    "taos.units": 1, "taos.errors": 1, "taos.results": 1, "taos.shipped": 1, "taos.bounds": 1, "taos.argpaths": 1,
    "taos.harmonics": 1, "taos.descfcn": 1,
    "taos.cosim._ccode": 1, "taos.cosim._ccode_func": 1, "taos.cosim._ccode_stmt": 1,
    "taos.friction": 2, "taos.linear": 2, "taos.stability": 2, "taos.model": 2,
    "taos.model_keys": 2, "taos.variants": 2,
    "taos.planar.actuator": 2, "taos.planar.avionics": 2, "taos.planar._avionics_kernels": 2,
    "taos.planar._avionics_slots": 2,
    "taos.planar.saturation": 2, "taos.planar._limits_pack": 2,
    "taos.planar": 3, "taos.taos3d": 3, "taos.fem": 3, "taos.profiles": 3, "taos.engine_geometry": 3,
    "taos.flight": 4, "taos.identify": 4, "taos.report": 4, "taos.montecarlo": 4,
    "taos.interop": 4, "taos.cosim": 4,
    "taos.plotting": 5, "taos.viewer": 5, "taos.report.analysis": 5, "taos.report.html": 5,
    "taos.cli": 6, "taos.__main__": 6,
    "masv.structure": 7, "masv.config": 7, "masv.system": 7, "masv.synthetic": 7,
    "masv.fe_import": 7, "masv._op2": 7, "masv.provenance": 7, "masv.coupled": 7, "masv._kernel": 7,
    "masv.analysis": 8, "masv.timedomain": 8, "masv": 8, "masv.plotting": 9, "masv.cli": 10,
    # the kernel warm-up (`make test`, `make demo`) compiles both packages' kernels, masv's too:
    # a build tool over everything, imported by nothing
    "taos.cli.warmup": 11,
}


def _layer(module: str) -> int | None:
    keys = [k for k in LAYERS if module == k or module.startswith(k + ".")]
    return LAYERS[max(keys, key=len)] if keys else None


def test_every_module_has_a_layer():
    assert not [m for m in MODULES if m != "taos" and _layer(m) is None]


def test_no_module_imports_a_layer_above_it():
    """Physics and analysis return result objects; plotting draws them; the CLI sits on top."""
    offenders = sorted(f"{m} (layer {_layer(m)}) imports {t} (layer {_layer(t)})"
                       for m, targets in import_graph().items() if m != "taos"
                       for t in targets if t != "taos" and _layer(t) > _layer(m))
    assert not offenders, "; ".join(offenders)


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)


def test_public_api_lists_and_resolves():
    proc = _run("-c", "import taos; print(taos.__all__); "
                      "[getattr(taos, n) for n in taos.__all__]")
    assert proc.returncode == 0, proc.stderr
    listed = proc.stdout
    for name in ("load_model", "simulate", "linear_freqresp", "sine_dwell_freqresp",
                 "describing_function_map", "analyse_lco", "fit_frequency_response",
                 "compare_models", "write_html"):
        assert name in listed


def test_python_m_taos_help():
    proc = _run("-m", "taos", "--help")
    assert proc.returncode == 0, proc.stderr
    assert "greenrun" in proc.stdout


def test_the_top_level_keeps_to_the_shared_foundations():
    """The engines live in their packages (taos.planar beside taos.taos3d); directly under taos/
    stay the shared foundations, at most 16 files (__init__ and __main__ included; the model
    files' key table and their variants, taos.model_keys and taos.variants, made it 16)."""
    top = sorted(p.name for p in (ROOT / "taos").glob("*.py"))
    assert len(top) <= 16, top
    assert (ROOT / "taos" / "planar" / "__init__.py").exists() and (ROOT / "taos" / "taos3d" / "__init__.py").exists()
    for engine_module in ("simplex", "simulate", "freqresp", "steady", "actuator", "avionics"):
        assert not (ROOT / "taos" / f"{engine_module}.py").exists(), engine_module
