"""A normal (not editable) install runs anywhere.

The wheel is built from the source tree (``pip wheel --no-deps``), installed with
``pip install --no-deps --target`` into a temporary folder (the dependencies come from the
running interpreter's environment), and the shipped commands are run from another working
directory with only that folder on ``PYTHONPATH``: ``taos info rs25_hotfire`` (a shipped model
named without a path) and ``python -m taos greenrun rs25_hotfire --out DIR`` (the report).

Building the wheel fetches setuptools and wheel into pip's isolated build environment (network);
the fresh install compiles its numba kernels on first use (about a minute of CPU). The whole
module is marked slow (``make check`` skips it; ``make test`` runs it).
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
