"""Named linear state-space systems and their exact frequency responses.

x' = A x + B u,  y = C x + D u, with named states, inputs and outputs so that models are
assembled from pieces (actuator, load path, engine, vehicle) by name rather than by index.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg


@dataclass(frozen=True, eq=False)
class StateSpace:
    """A continuous-time LTI system with named signals (SI units in the names)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    def __post_init__(self):
        n, m, p = len(self.states), len(self.inputs), len(self.outputs)
        for name, M, shape in (("A", self.A, (n, n)), ("B", self.B, (n, m)),
                               ("C", self.C, (p, n)), ("D", self.D, (p, m))):
            if M.shape != shape:
                raise ValueError(f"{name} has shape {M.shape}, expected {shape}")

    def input_index(self, name: str) -> int:
        return self.inputs.index(name)

    def output_index(self, name: str) -> int:
        return self.outputs.index(name)

    def state_index(self, name: str) -> int:
        return self.states.index(name)

    def poles(self) -> np.ndarray:
        """Eigenvalues of A [1/s]."""
        return np.linalg.eigvals(self.A)

    def freqresp(self, freq_hz, inputs: str | list[str] | None = None,
                 outputs: str | list[str] | None = None) -> np.ndarray:
        """Exact frequency response H(j w) = C (j w I - A)^-1 B + D.

        Returns an array of shape (n_freq, n_out, n_in) for the selected signals (all by
        default); a single name selects a single signal and drops that axis. Uses a Hessenberg
        reduction of the balanced A (Laub 1981).
        """
        f = np.atleast_1d(np.asarray(freq_hz, float))
        ii = self._sel(inputs, self.inputs)
        oo = self._sel(outputs, self.outputs)
        B = self.B[:, ii]
        C = self.C[oo, :]
        D = self.D[np.ix_(oo, ii)]
        # diagonal balancing (states mix Pa and m), then Hessenberg form
        Ab, (sc, _perm) = scipy.linalg.matrix_balance(self.A, permute=False, separate=True)
        H, Q = scipy.linalg.hessenberg(Ab, calc_q=True)
        Bq = Q.T @ (B / sc[:, None])
        Cq = (C * sc[None, :]) @ Q
        n = self.A.shape[0]
        out = np.empty((f.size, len(oo), len(ii)), complex)
        eye = np.eye(n)
        for k, fk in enumerate(f):
            s = 2j * np.pi * fk
            out[k] = Cq @ scipy.linalg.solve(s * eye - H, Bq) + D
        if isinstance(outputs, str):
            out = out[:, 0, :]
        if isinstance(inputs, str):
            out = out[..., 0]
        return out

    @staticmethod
    def _sel(sel, names) -> list[int]:
        if sel is None:
            return list(range(len(names)))
        if isinstance(sel, str):
            return [names.index(sel)]
        return [names.index(s) for s in sel]


def gain_db(h) -> np.ndarray:
    """20 log10 |h| [dB]."""
    return 20.0 * np.log10(np.abs(h))


def phase_deg(h, unwrap: bool = True) -> np.ndarray:
    """Phase of h [deg], unwrapped along the first axis by default."""
    ph = np.angle(h)
    if unwrap:
        ph = np.unwrap(ph, axis=0)
    return np.degrees(ph)
