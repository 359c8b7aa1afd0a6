"""Analytic run kinds: a pure function of the factors run through the campaign engine, and the
engine on any design (the entry point a parameter sweep uses).

:class:`Ishigami` is the test function of T. Ishigami and T. Homma (Proc. ISUMA 1990, 398-403),
``y = sin x1 + a sin^2 x2 + b x3^4 sin x1`` with x_i ~ U(-pi, pi), whose Sobol' indices are known
in closed form (A. Saltelli et al., Global Sensitivity Analysis: The Primer, Wiley 2008, sec.
4.9): with ``V1 = (1 + b pi^4/5)^2 / 2``, ``V2 = a^2/8``, ``V13 = b^2 pi^8 (1/18 - 1/50)``
and ``V = V1 + V2 + V13``: ``S1 = (V1/V, V2/V, 0)``, ``ST = ((V1 + V13)/V, V2/V, V13/V)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from taos.montecarlo import engine, store
from taos.montecarlo.engine import Design, Part, RunKind


@dataclass(frozen=True)
class Ishigami:
    """The Ishigami function as a run kind (scalar output ``y``, no trace)."""

    a: float = 7.0
    b: float = 0.1
    scalars: tuple[str, ...] = ("y",)
    flags: tuple[str, ...] = ()
    run_cost_s: float = 1e-6

    @property
    def inputs_sha256(self) -> str:
        import hashlib
        return hashlib.sha256(f"ishigami a={self.a!r} b={self.b!r}".encode()).hexdigest()

    @property
    def trace_t_s(self) -> np.ndarray:
        return np.zeros(0)

    def run_batch(self, names, factors: np.ndarray, seeds: np.ndarray) -> dict:
        x1, x2, x3 = (factors[:, names.index(k)] for k in ("x1", "x2", "x3"))
        y = np.sin(x1) + self.a * np.sin(x2) ** 2 + self.b * x3 ** 4 * np.sin(x1)
        n = len(seeds)
        return {"status": np.full(n, store.STATUS["ok"], np.int8), "error": [""] * n, "y": y,
                "trace": np.zeros((n, 0))}

    def analytic_indices(self) -> dict:
        """{"S1": (3,), "ST": (3,)} in closed form (module docstring)."""
        a, b, pi = self.a, self.b, math.pi
        v1, v2, v13 = 0.5 * (1 + b * pi ** 4 / 5) ** 2, a * a / 8, b * b * pi ** 8 * (1 / 18 - 1 / 50)
        v = v1 + v2 + v13
        return {"S1": np.array([v1 / v, v2 / v, 0.0]), "ST": np.array([(v1 + v13) / v, v2 / v, v13 / v])}

    @staticmethod
    def problem() -> dict:
        return {"num_vars": 3, "names": ["x1", "x2", "x3"], "bounds": [[-math.pi, math.pi]] * 3,
                "dists": ["unif"] * 3}


def run_design(kind: RunKind, design: Design, path: str | Path, *, workers: int = 2, scheduler: str | None = None,
               batch: int | None = None, resume: bool = False, progress: bool = False):
    """Run ``design`` with ``kind`` on the engine into the store ``path`` (a new one, or the
    one a previous call began when ``resume``); returns the store as a lazy xarray Dataset."""
    path = Path(path)
    with engine.connected(workers, scheduler) as client:
        n_workers = len(client.scheduler_info().get("workers", {})) if client is not None else 1
        b = batch or engine.batch_size(design.n, kind.run_cost_s, n_workers)
        if not (resume and store.status(path) is not None):
            store.create(path, labels=np.arange(design.n), names=design.names, factors=design.factors,
                         seeds=design.seeds, scalars=kind.scalars, flags=kind.flags, trace_t_s=kind.trace_t_s,
                         batch=b, attrs={"inputs_sha256": kind.inputs_sha256})
        else:
            b = int(store.open_store(path)["status"].encoding["chunks"][0])
        engine.execute(path, kind, [Part(None, design)], b, client, progress=progress)
    return store.open_store(path)
