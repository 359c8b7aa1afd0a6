"""Package list for setuptools (everything else is in pyproject.toml).

The shipped data folders models/ and fem_data/ stay at the top level of the repository and are
mapped into the wheel as the packages taos.shipped.models and taos.shipped.fem_data (see
pyproject.toml [tool.setuptools.package-dir]); find_packages cannot see mapped folders, hence
this file.
"""

from setuptools import find_packages, setup

setup(packages=find_packages(include=["taos", "taos.*", "masv", "masv.*"])
      + ["taos.shipped.models", "taos.shipped.fem_data"])
