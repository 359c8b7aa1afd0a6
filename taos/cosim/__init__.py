"""The TVC as a block in someone else's simulation: a step-by-step co-simulation API and an
FMI 2.0 co-simulation FMU built from it.

* :class:`TvcBlock` (``reset()``, ``step(dt, pitch_command_rad, yaw_command_rad)`` ->
  :class:`BlockOutputs`): one engine's nonlinear TVC, both axes, computing exactly what
  ``taos simulate`` computes (the same compiled kernels, stepped in chunks;
  :mod:`taos.cosim._block`);
* the standalone FMU (``taos fmu``, the default): in C emitted from the kernels' own Python
  source (:mod:`taos.cosim._ccode`), no Python at run time; the planar model
  (:mod:`taos.cosim._standalone`, tunable parameters) or the 3-D model
  (:mod:`taos.cosim._standalone3d`, ``--engine taos``);
* :func:`build_fmu`: the block as an FMI 2.0 co-simulation FMU through ``pythonfmu``
  (``taos fmu --python``; :mod:`taos.cosim._fmu`). Such an FMU runs the block in a Python with
  ``taos`` importable on the importing machine and lacks host behaviours the standalone one
  has (:data:`taos.cli.fmu.PYTHON_LACKS`).
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
