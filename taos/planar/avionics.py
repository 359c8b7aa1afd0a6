"""TVC command avionics: flight-software quantisation and servo-amplifier crossover gain.

Command path (seed paper section 2.3)::

    FCS command theta_c [rad] -> quantise (N bits over the full command range, truncation
    toward zero or rounding to nearest) -> crossover-distortion gain g(|c|) -> c_out

* Quantisation: LSB = range / 2**N (12 bits over 21 deg gives 0.00513 deg). Truncation
  (``int()`` toward zero, as flown on Artemis I) loses gain sharply for amplitudes below
  about two LSB; rounding (the planned Block 1B fix) removes that loss.
* Crossover distortion: the TAC servo amplifier's vendor curve, a static gain of the
  instantaneous command magnitude, linearly interpolated in a table (|c| [rad], gain [-]);
  the default has a valley of 0.95 (-0.45 dB... -1.1 dB with the paper's bounding) in the
  low-amplitude region tending to 1.0 at large commands.

Both maps are numba kernels over a packed parameter vector (:mod:`taos.planar._avionics_kernels`,
the single definition) so the time-domain integrator applies them in the loop (closed
flight loop) or to a whole command array (open loop).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from taos.descfcn import Nonlinearity

from ._avionics_slots import AV_BITS, AV_LSB, AV_NTAB, AV_ROUND, AV_TABLE


@dataclass(frozen=True)
class Avionics(Nonlinearity):
    """Command avionics parameters (SI); a static nonlinearity (:class:`taos.descfcn.Nonlinearity`,
    no analytic describing function: :func:`taos.descfcn.static_describing_function`).

    Parameters
    ----------
    quantization_bits : int
        Flight-software command word length; 0 disables quantisation.
    command_range_rad : float
        Full command range quantised by the word [rad] (e.g. 21 deg for +-10.5 deg).
    rounding : bool
        True: round to nearest LSB; False: truncate toward zero (as flown).
    gain_table_rad : tuple[float, ...]
        Command magnitudes [rad] of the crossover gain table, increasing; empty for unity gain.
    gain_table : tuple[float, ...]
        Gains [-] at those magnitudes (held constant beyond the ends).
    """

    quantization_bits: int = 0
    command_range_rad: float = 0.0
    rounding: bool = False
    gain_table_rad: tuple[float, ...] = ()
    gain_table: tuple[float, ...] = ()

    @property
    def lsb_rad(self) -> float:
        """Least significant bit of the command word [rad] (0 when quantisation is off)."""
        if self.quantization_bits <= 0:
            return 0.0
        return self.command_range_rad / 2.0 ** self.quantization_bits

    def pack(self) -> np.ndarray:
        """The parameters packed for the compiled kernels (slots ``AV_*``, module layout)."""
        n = len(self.gain_table_rad)
        p = np.zeros(AV_TABLE + 2 * n)
        p[AV_BITS] = float(self.quantization_bits)
        p[AV_LSB] = self.lsb_rad
        p[AV_ROUND] = 1.0 if self.rounding else 0.0
        p[AV_NTAB] = float(n)
        p[AV_TABLE:AV_TABLE + n] = self.gain_table_rad
        p[AV_TABLE + n:AV_TABLE + 2 * n] = self.gain_table
        return p

    def __call__(self, command_rad):
        """Apply the command path to a command value or array [rad]."""
        from ._avionics_kernels import apply_array

        c = np.asarray(command_rad, float)
        out = apply_array(np.ascontiguousarray(c.ravel()), self.pack()).reshape(c.shape)
        return float(out) if out.ndim == 0 else out

    def ideal(self) -> "Avionics":
        """The same avionics with quantisation and crossover gain off (a unity path)."""
        return Avionics()


def __getattr__(name: str):
    """``apply`` and ``apply_array``: the compiled kernels (:mod:`taos.planar._avionics_kernels`),
    imported on first use so that loading a model does not import numba."""
    if name in ("apply", "apply_array"):
        from . import _avionics_kernels
        return getattr(_avionics_kernels, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
