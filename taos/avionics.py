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

Both maps are numba kernels over a packed parameter vector so the time-domain integrator
applies them in the loop (closed flight loop) or to a whole command array (open loop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

# packed layout: [bits, lsb_rad, rounding(0/1), n_table, amp_0..amp_{n-1}, gain_0..gain_{n-1}]


@dataclass(frozen=True)
class Avionics:
    """Command avionics parameters (SI).

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
        n = len(self.gain_table_rad)
        return np.array([float(self.quantization_bits), self.lsb_rad, 1.0 if self.rounding else 0.0,
                         float(n), *self.gain_table_rad, *self.gain_table], dtype=float)

    def __call__(self, command_rad):
        """Apply the command path to a command value or array [rad]."""
        c = np.asarray(command_rad, float)
        out = apply_array(np.ascontiguousarray(c.ravel()), self.pack()).reshape(c.shape)
        return float(out) if out.ndim == 0 else out

    def ideal(self) -> "Avionics":
        """The same avionics with quantisation and crossover gain off (a unity path)."""
        return Avionics()


@njit(cache=True)
def apply(c, p):
    """Command path for one value ``c`` [rad] with packed parameters ``p``."""
    lsb = p[1]
    if lsb > 0.0:
        q = c / lsb
        if p[2] > 0.5:
            q = math.floor(q + 0.5)
        else:
            q = float(int(q))  # truncation toward zero
        c = q * lsb
    n = int(p[3])
    if n == 0:
        return c
    a = abs(c)
    ia = 4          # amplitudes p[4 : 4+n], gains p[4+n : 4+2n]
    ig = 4 + n
    if a <= p[ia]:
        g = p[ig]
    elif a >= p[ia + n - 1]:
        g = p[ig + n - 1]
    else:
        i = 0
        while p[ia + i + 1] < a:
            i += 1
        w = (a - p[ia + i]) / (p[ia + i + 1] - p[ia + i])
        g = p[ig + i] + w * (p[ig + i + 1] - p[ig + i])
    return g * c


@njit(cache=True)
def apply_array(c, p):
    out = np.empty_like(c)
    for i in range(c.shape[0]):
        out[i] = apply(c[i], p)
    return out
