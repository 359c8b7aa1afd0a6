"""The TVC as a block in someone else's simulation: a step-by-step co-simulation API and an
FMI 2.0 co-simulation FMU built from it.

* :class:`TvcBlock` (``reset()``, ``step(dt, pitch_command_rad, yaw_command_rad)`` ->
  :class:`BlockOutputs`): one engine's nonlinear TVC, both axes, computing exactly what
  ``taos simulate`` computes (the same compiled kernels, stepped in chunks;
  :mod:`taos.cosim._block`);
* :func:`build_fmu`: the block as an FMI 2.0 co-simulation FMU through ``pythonfmu``
  (``taos fmu``; :mod:`taos.cosim._fmu`). Such an FMU runs the block in a Python with ``taos``
  importable on the importing machine;
* the standalone FMU (``taos fmu --standalone``; :mod:`taos.cosim._standalone`): the planar
  model in C emitted from the kernels' own Python source (:mod:`taos.cosim._ccode`), no Python
  at run time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from taos import lazy_api

if TYPE_CHECKING:
    from ._block import BlockOutputs, TvcBlock
    from ._fmu import FmuBuild, build_fmu
    from ._options import HOLDS

_WHERE = {"TvcBlock": "._block", "BlockOutputs": "._block", "HOLDS": "._options",
          "build_fmu": "._fmu", "FmuBuild": "._fmu"}

__all__ = sorted(_WHERE)

__getattr__, __dir__ = lazy_api(__name__, _WHERE, globals())
