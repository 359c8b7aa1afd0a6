"""The zero bristle-state rate of the memoryless laws (``none`` and both Coulomb laws), a cached
C callback with the registry's ``ZDOT3_SIG`` (see :mod:`._builtin`)."""

from __future__ import annotations

from ._builtin import kernel


@kernel("ZDOT3_SIG")
def zero_zdot3(w0, w1, z0, z1, p):
    return 0.0, 0.0
