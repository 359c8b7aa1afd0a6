"""A normal (not editable) install runs anywhere.

The wheel is built from the source tree (``pip wheel --no-deps``), installed with
``pip install --no-deps --target`` into a temporary folder (the dependencies come from the
running interpreter's environment), and the shipped commands are run from another working
directory with only that folder on ``PYTHONPATH``: ``taos info rs25_hotfire`` (a shipped model
named without a path) and ``python -m taos greenrun rs25_hotfire --out DIR`` (the report).

Building the wheel fetches setuptools and wheel into pip's isolated build environment (network).
The installed copy is given the source tree's numba kernel cache (:func:`_copy_kernel_cache`):
numba keys each cached kernel on the SHA-256 of its source file, the function's bytecode and
this machine's CPU, so it loads only what it would have compiled from the same text here, and
compiles the rest; a cold compile for the installed copy cost about 35 CPU-s of `make test` and
proved nothing the suite's kernel warm-up does not (benchmarks/RESULTS.md, "make test cost,
2026-12-02 (session 3)"). The whole module is marked slow (``make check`` skips it; ``make
test`` runs it).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

#: slow (make check skips these, make test runs them): wheel build (network) and install
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]


def _run(args, cwd, env=None, timeout=1800):
    return subprocess.run([str(a) for a in args], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=timeout)


def _copy_kernel_cache(site: Path) -> int:
    """Copy the source tree's numba cache files (``__pycache__/*.nbi``, ``*.nbc``) of ``taos``
    and ``masv`` to the same places in ``site``; returns how many source files they belong to.
    Each one's source file in ``site`` must be byte-identical to the tree's (the wheel ships the
    tree's kernels); numba checks that again itself (its index holds the source's SHA-256). A
    kernel that reads code of another file keeps the code it was compiled with, in the tree's
    cache as here (the Makefile drops and rebuilds the whole cache when a kernel file changes)."""
    sources = set()
    for pkg in ("taos", "masv"):
        for nb in sorted((ROOT / pkg).rglob("__pycache__/*.nb[ic]")):
            rel = nb.relative_to(ROOT)
            py = rel.parent.parent / (nb.name.split(".", 1)[0] + ".py")
            if not (ROOT / py).is_file():
                continue   # left by a module the tree no longer has
            assert (site / py).is_file() and (site / py).read_bytes() == (ROOT / py).read_bytes(), \
                f"the wheel's {py} is not the tree's"
            (site / rel.parent).mkdir(exist_ok=True)
            shutil.copyfile(nb, site / rel)
            sources.add(py)
    return len(sources)


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(site folder holding the installed wheel, environment that sees only it, a work folder)."""
    tmp = tmp_path_factory.mktemp("install")
    # build from a copy: pip builds in the source folder (build/, *.egg-info), which must not be
    # shared with another test session (make test runs two pytest processes) or left in the tree
    src = tmp / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "__pycache__",
                                                              "out", "docs", "tests", ".hypothesis", ".pytest_cache"))
    r = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", tmp / "dist", src], cwd=tmp)
    assert r.returncode == 0, r.stderr[-2000:]
    wheels = sorted((tmp / "dist").glob("taos_tvc-*.whl"))
    assert len(wheels) == 1
    names = zipfile.ZipFile(wheels[0]).namelist()
    assert "taos/shipped/models/rs25_hotfire.toml" in names
    assert "taos/shipped/models/profiles/greenrun_two_axis.toml" in names
    assert any(n.startswith("taos/shipped/fem_data/") and n.endswith(".npz") for n in names)
    assert not any(n.startswith("tests/") for n in names)
    assert "taos/py.typed" in names and "masv/py.typed" in names  # PEP 561: typed packages
    site = tmp / "site"
    # byte-compiled at install, as pip does by default (with --no-compile and the test
    # environment's PYTHONDONTWRITEBYTECODE, each command below compiled every taos module again)
    r = _run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", site, wheels[0]], cwd=tmp)
    assert r.returncode == 0, r.stderr[-2000:]
    _copy_kernel_cache(site)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONPATH"] = str(site)
    work = tmp / "elsewhere"
    work.mkdir()
    return site, env, work


def test_installed_package_is_the_wheel_not_the_source_tree(installed):
    site, env, work = installed
    r = _run([sys.executable, "-c", "import taos, masv; print(taos.__file__); print(masv.__file__)"], work, env)
    assert r.returncode == 0, r.stderr
    for line in r.stdout.split():
        assert Path(line).resolve().is_relative_to(site.resolve()), line


def test_info_names_a_shipped_model_without_a_path(installed):
    site, env, work = installed
    r = _run([sys.executable, "-m", "taos", "info", "rs25_hotfire", "--json", "-"], work, env)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert Path(d["model_file"]).resolve().is_relative_to(site.resolve())
    assert d["load_resonance_hz"] > 0


@pytest.mark.slow
def test_greenrun_report_from_the_installed_wheel(installed):
    site, env, work = installed
    out = work / "report"
    r = _run([sys.executable, "-m", "taos", "greenrun", "rs25_hotfire", "--out", out], work, env)
    assert r.returncode == 0, r.stderr[-3000:]
    html = out / "index.html"
    assert html.is_file() and html.stat().st_size > 10_000
    assert "Green Run two-axis vectoring" in html.read_text()
    summary = json.loads((out / "summary.json").read_text())
    assert Path(summary["model_file"]).resolve().is_relative_to(site.resolve())
