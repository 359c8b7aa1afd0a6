"""Provenance: the version an output records is taos's own. ``git_revision`` is taken only from
taos's own source checkout; installed or copied inside another project's git repository, taos
must not record that project's commit as its revision."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import taos
from taos.results import base_provenance, git_revision, own_checkout, package_version

PACKAGE = Path(taos.__file__).resolve().parent

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def _git(folder: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(folder), "-c", "user.name=t", "-c", "user.email=t@example.org",
                           *args], check=True, capture_output=True, text=True).stdout.strip()


def _repo(folder: Path, project_name: str) -> str:
    """A git repository at ``folder`` whose pyproject names ``project_name``; its HEAD commit."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "pyproject.toml").write_text(f'[project]\nname = "{project_name}"\nversion = "9.9.9"\n')
    _git(folder, "init", "-q")
    _git(folder, "add", "-A")
    _git(folder, "commit", "-q", "-m", "foreign")
    return _git(folder, "rev-parse", "HEAD")


def _copy_package(dest: Path) -> Path:
    shutil.copytree(PACKAGE, dest / "taos", ignore=shutil.ignore_patterns("__pycache__"))
    return dest / "taos"


def test_own_checkout_records_its_commit(tmp_path):
    root = tmp_path / "taos-src"
    root.mkdir()
    _copy_package(root)
    head = _repo(root, "taos-tvc")
    assert own_checkout(root / "taos") == root.resolve()
    assert git_revision(root / "taos") == head


def test_package_inside_another_projects_repository_records_no_commit(tmp_path):
    proj = tmp_path / "their_project"
    proj.mkdir()
    pkg = _copy_package(proj)
    foreign = _repo(proj, "their-project")
    assert own_checkout(pkg) is None
    assert git_revision(pkg) == ""
    # a taos source tree (its own pyproject) unpacked inside the other repository: still not
    # taos's checkout (the git top level is the other project's)
    outer = tmp_path / "outer"
    src = outer / "vendor" / "taos-src"
    src.mkdir(parents=True)
    (src / "pyproject.toml").write_text('[project]\nname = "taos-tvc"\n')
    pkg2 = _copy_package(src)
    _repo(outer, "outer")
    assert own_checkout(pkg2) is None
    assert git_revision(pkg2) == ""
    # end to end: the copied package, imported in a fresh interpreter, writes no foreign commit
    env = {**os.environ, "PYTHONPATH": str(proj)}
    out = subprocess.run([sys.executable, "-c", "import json, taos, taos.results as r; "
                          "print(json.dumps([taos.__file__, r.base_provenance()]))"],
                         cwd=proj, env=env, check=True, capture_output=True, text=True).stdout
    where, prov = json.loads(out)
    assert Path(where).resolve().parent == pkg.resolve()
    assert prov["git_revision"] == ""
    assert foreign not in out
    assert prov["package_version"] == package_version()


def test_version_is_taos_own():
    assert package_version() == taos.__version__
    assert base_provenance()["package_version"] == taos.__version__
