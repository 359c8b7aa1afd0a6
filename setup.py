"""Package list for setuptools (everything else is in pyproject.toml).

The shipped data folders models/ and fem_data/ stay at the top level of the repository and are
mapped into the wheel as the packages taos.shipped.models and taos.shipped.fem_data (see
pyproject.toml [tool.setuptools.package-dir]); find_packages cannot see mapped folders, hence
this file.
"""

from pathlib import Path

from setuptools import find_packages, setup

#: the data sub-folders of models/ (data, flight, masv, meshes, profiles, ...), declared so that
#: setuptools does not warn about them; their files come from the package-data patterns
MODEL_FOLDERS = sorted(p.name for p in (Path(__file__).parent / "models").iterdir()
                       if p.is_dir() and not p.name.startswith((".", "_")))

setup(packages=find_packages(include=["taos", "taos.*", "masv", "masv.*"])
      + ["taos.shipped.models", "taos.shipped.fem_data"]
      + [f"taos.shipped.models.{d}" for d in MODEL_FOLDERS])
