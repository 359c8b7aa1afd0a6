"""One meaning per public name.

* No package of ``taos`` or ``masv`` exports a name (its ``__all__``, its lazy ``_API`` table or
  a top-level name bound in its ``__init__``) equal to one of its submodules: ``pkg.x`` must not
  be a function or a module depending on what was imported first.
* The package docstring example of ``taos/__init__.py`` runs in a fresh interpreter whichever
  order the modules are imported in: ``taos.simulate`` and ``taos.margins`` stay the functions
  after ``import taos.planar.simulate`` and ``import taos.stability``.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("taos", "masv")


def _packages() -> list[Path]:
    return sorted(p.parent for pkg in PACKAGES for p in (ROOT / pkg).rglob("__init__.py"))


def _submodules(pkg: Path) -> set[str]:
    return ({p.stem for p in pkg.glob("*.py") if p.stem != "__init__"}
            | {p.name for p in pkg.iterdir() if (p / "__init__.py").is_file()})


def _literal_names(node: ast.AST) -> set[str]:
    """The strings of a list/tuple/dict-keys literal (``sorted(_API) + [...]`` pieces included)."""
    out: set[str] = set()
    for n in ast.walk(node):
        if isinstance(n, ast.Constant) and isinstance(n.value, str):
            out.add(n.value)
    return out


def public_names(init: Path) -> set[str]:
    """Names ``init`` exports: ``__all__`` entries, ``_API`` keys and the public top-level
    names it binds (``from . import sub``, which binds the submodule itself, excepted)."""
    tree = ast.parse(init.read_text(), filename=str(init))
    names: set[str] = set()
    for node in tree.body:
        if isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            ids = {t.id for t in targets if isinstance(t, ast.Name)}
            if "__all__" in ids and node.value is not None:
                names |= _literal_names(node.value)
            elif "_API" in ids and isinstance(node.value, ast.Dict):
                names |= {k.value for k in node.value.keys if isinstance(k, ast.Constant)}
            names |= ids
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level == 1 and node.module is None:
                continue  # ``from . import sub``: the submodule itself
            names |= {a.asname or a.name for a in node.names}
        elif isinstance(node, ast.Import):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
    return {n for n in names if not n.startswith("_")}


def test_public_names_finder_sees_all_api_and_bound_names(tmp_path):
    init = tmp_path / "__init__.py"
    init.write_text("from .a import b, c as d\nfrom . import e\n_API = {'f': 'x.y'}\n"
                    "__all__ = sorted(_API) + ['g']\ndef h(): pass\nclass K: pass\nk = 1\n_p = 2\n")
    assert public_names(init) == {"b", "d", "f", "g", "h", "K", "k"}


@pytest.mark.parametrize("pkg", _packages(), ids=lambda p: ".".join(p.relative_to(ROOT).parts))
def test_no_public_name_is_also_a_submodule(pkg):
    clash = sorted(public_names(pkg / "__init__.py") & _submodules(pkg))
    assert not clash, f"{'.'.join(pkg.relative_to(ROOT).parts)}: public name and submodule: {clash}"


EXAMPLE = """
import taos
m = taos.load_model('rs25_hotfire')
taos.linear_freqresp(m, [0.5, 5.0])
th = taos.simulate(m, taos.load_profile('step_pitch'))
assert isinstance(th, taos.TimeHistory), type(th)
fl = taos.load_flight('core_stage')
f = [0.01 * 1.05 ** k for k in range(120)]
mg = taos.margins(f, taos.flight.vehicle.loop_freqresp(fl, f))
assert callable(taos.simulate) and callable(taos.margins)
print(type(th).__name__, type(mg).__name__)
"""

FIRST = {
    "function first": "",
    "submodules first": "import taos.planar.simulate\nimport taos.stability\n",
    "submodules after the package": "import taos\nimport taos.planar.simulate\nimport taos.stability\n",
}


@pytest.mark.parametrize("first", FIRST, ids=list(FIRST))
def test_package_docstring_example_runs_whichever_is_imported_first(first):
    proc = subprocess.run([sys.executable, "-c", FIRST[first] + EXAMPLE], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.split() == ["TimeHistory", "Margins"]
