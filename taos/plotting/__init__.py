"""Plots (matplotlib; Plotly for the pages: :mod:`.interactive`) and the flight sign-off page
(:mod:`.signoff_page`): thin functions over result objects; analysis never draws.

Submodules: :mod:`._common` (saving, engineering units). Import plot functions from their
submodules, e.g. ``from taos.plotting import bode``.
"""

from ._common import save

__all__ = ["save"]
