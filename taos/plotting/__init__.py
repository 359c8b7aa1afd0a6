"""Plots (matplotlib): thin functions over result objects; analysis never draws.

Submodules: :mod:`._common` (saving, engineering units). Import plot functions from their
submodules, e.g. ``from taos.plotting import bode``.
"""

from ._common import save

__all__ = ["save"]
