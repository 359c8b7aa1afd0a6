"""The fit's global first stage: a grid over the load stiffness and the friction level.

The least-squares cost of a TVC record need not be convex in K_L and T_c: the piston notch
is sharp (the load mode's damping ratio is near 0.005) and a friction level tens of times off
(the ambient model's 2,185 in-lbf against a hot-fire record's ~100,000) changes which points
the friction holds. IPOPT (:mod:`taos.identify.fit`) converges fast from near the answer, so a
cheap global look first picks where it starts (on the records tried so far IPOPT also reached
the optimum from the start values once the bounds were physical, :mod:`taos.identify.physbounds`;
the grid is the safeguard, and the start values stay among IPOPT's starts).

:func:`grid_search` evaluates the describing-function surrogate of the fit
(:mod:`taos.identify.surrogate`, same equations, same residuals) on a log grid spanning the
physical bounds (:mod:`taos.identify.physbounds`) of the free ``load_stiffness`` and
``coulomb_torque`` (either or both), the other free parameters held at their start, in
numpy instead of CasADi:

* the linear responses G_xc, G_xT, G_wc, G_wT of :func:`taos.planar.simplex.simplex_state_space`
  at each K_L of the grid (one batched complex solve per K_L and axis);
* the friction law's fit describing function N(X, w) (its registry entry's
  ``fit_describing_function``) tabulated once per point on a log grid of engine-angle
  amplitudes X. Every torque-like parameter scales with T_c when the level moves
  (:func:`taos.identify.surrogate.apply_values`), and every law is homogeneous of degree one
  in them (:meth:`taos.friction.FrictionLaw.scaled`), so N(X, w; T_c) = (T_c / T_ref) N(X, w; T_ref):
  one table serves every friction level;
* the loop equation ln(w X / A) + ln|1 - G_wT N(X)| - ln|G_wc C| = 0 of the surrogate, solved
  on the X table (first sign change, interpolated in ln X; no change: the engine is held at
  the smallest X, or slides at the largest), then the responses and the log-complex
  residuals of :class:`taos.identify.fit.FitProblem`.

The grid's local minima (8-neighbourhood), best first, are the starts IPOPT refines; the
grid costs 0.3-2.5 s (benchmarks/bench_fit.py), a few per cent of a fit.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from taos.identify.surrogate import apply_values, avionics_df

GRID_NAMES = ("load_stiffness", "coulomb_torque")
N_STIFFNESS = 64
N_TORQUE = 40
N_AMPLITUDE = 240


@dataclass(frozen=True, eq=False)
class GridSearch:
    """Result of :func:`grid_search`: the grid axes [SI] (length 1 for a name not free), the
    cost 0.5 sum r^2 on it, and the candidate starts (scaled vectors s = p / p_start of the
    problem's free parameters), best first."""

    stiffness_N_per_m: np.ndarray
    torque_Nm: np.ndarray
    cost: np.ndarray
    candidates: tuple[np.ndarray, ...]
    candidate_costs: tuple[float, ...]
    wall_s: float

    def to_dict(self) -> dict:
        return {"grid": [int(self.stiffness_N_per_m.size), int(self.torque_Nm.size)],
                "load_stiffness_range_si": [float(self.stiffness_N_per_m[0]), float(self.stiffness_N_per_m[-1])],
                "coulomb_torque_range_si": [float(self.torque_Nm[0]), float(self.torque_Nm[-1])],
                "candidates": len(self.candidates), "best_grid_cost": float(np.min(self.cost)),
                "wall_s": self.wall_s}


def _df_table(model, family: str, w: np.ndarray, X: np.ndarray) -> np.ndarray:
    """(points, amplitudes) complex rate-form describing function [N m s/rad] of the model's
    law at its own level."""
    if family == "none":
        return np.zeros((w.size, X.size), complex)
    law, entry = model.friction, model.friction.entry
    out = np.empty((w.size, X.size), complex)
    for k, wk in enumerate(w):
        for j, x in enumerate(X):
            re, im = entry.fit_describing_function(law, float(x), float(wk))
            out[k, j] = complex(float(re), float(im))
    return out


def _linear(model, axes, f):
    """(Gxc, Gxt, Gwc, Gwt) at the points, complex arrays."""
    from taos.planar.simplex import simplex_state_space

    G = np.empty((4, f.size), complex)
    for ax in np.unique(axes):
        idx = np.flatnonzero(axes == ax)
        H = simplex_state_space(model, str(ax)).freqresp(f[idx], ["command_rad", "friction_torque_Nm"],
                                                          ["x_p_m", "omega_rad_s"])
        G[0, idx], G[1, idx] = H[:, 0, 0], H[:, 0, 1]
        G[2, idx], G[3, idx] = H[:, 1, 0], H[:, 1, 1]
    return G


def _log_residual_cost(h, d, wgt):
    """sum over points of (wgt ln|h/d|)^2 + (wgt arg(h/d))^2 along the last axis."""
    q = h / d
    return np.sum((wgt * np.log(np.abs(q))) ** 2 + (wgt * np.angle(q)) ** 2, axis=-1)


def grid_search(prob, hx, he, wx, we, *, n_stiffness: int = N_STIFFNESS, n_torque: int = N_TORQUE,
                keep: int = 3) -> GridSearch | None:
    """Grid of the surrogate's cost over the free ``load_stiffness`` and ``coulomb_torque`` of a
    :class:`taos.identify.fit.FitProblem` ``prob`` (module docstring) against the data
    (hx [m/rad], he, weights wx, we: the problem's point layout). ``None`` when neither is free."""
    t0 = time.perf_counter()
    names = list(prob.free)
    idx = {n: names.index(n) for n in GRID_NAMES if n in names}
    if not idx:
        return None
    lo, hi = prob.lbx[:len(names)] * prob.p_ref, prob.ubx[:len(names)] * prob.p_ref

    def axis(name, n):
        if name not in idx:
            return None
        i = idx[name]
        return np.geomspace(lo[i], hi[i], n)

    Kg, Tg = axis("load_stiffness", n_stiffness), axis("coulomb_torque", n_torque)
    base = prob.model
    axes, f, A = prob.axes, prob.freq_hz, prob.amp_rad
    w = 2 * math.pi * f
    Aeff = np.where(np.isfinite(A), A, 1e-2)
    C = np.array([avionics_df(base, a) if math.isfinite(a) else 1.0 + 0j for a in A])
    fam = prob.sur.family
    t_ref = base.friction.coulomb_torque_Nm if fam != "none" else 1.0
    lam = (Tg / t_ref) if Tg is not None else np.ones(1)
    X = np.geomspace(1e-8, 1.0, N_AMPLITUDE)
    Nref = _df_table(base, fam, w, X)                          # (m, nX)
    lnX = np.log(X)
    Ks = Kg if Kg is not None else np.array([base.structure.load_stiffness_N_per_m])
    cost = np.empty((Ks.size, lam.size))
    for a, K in enumerate(Ks):
        mk = apply_values(base, ["load_stiffness"], [float(K)]) if Kg is not None else base
        Gxc, Gxt, Gwc, Gwt = _linear(mk, axes, f)
        N = lam[:, None, None] * Nref[None]                    # (nT, m, nX)
        g = (np.log(w[None, :, None] * X[None, None, :] / Aeff[None, :, None])
             + np.log(np.abs(1 - Gwt[None, :, None] * N)) - np.log(np.abs(Gwc * C))[None, :, None])
        pos = g >= 0
        j = np.argmax(pos, axis=-1)                            # first amplitude where the loop closes
        j = np.where(pos.any(axis=-1), j, X.size - 1)
        j0 = np.clip(j - 1, 0, X.size - 1)
        g0 = np.take_along_axis(g, j0[..., None], -1)[..., 0]
        g1 = np.take_along_axis(g, j[..., None], -1)[..., 0]
        frac = np.where((j > 0) & (g1 != g0), np.clip(-g0 / np.where(g1 != g0, g1 - g0, 1.0), 0, 1), 0.0)
        lx = np.where(j > 0, lnX[j0] + frac * (lnX[j] - lnX[j0]), lnX[0])
        fx = (lx - lnX[0]) / (lnX[1] - lnX[0])
        i0 = np.clip(np.floor(fx).astype(int), 0, X.size - 2)
        t = (fx - i0)[..., None]
        Nx = (np.take_along_axis(N, i0[..., None], -1) * (1 - t)
              + np.take_along_axis(N, (i0 + 1)[..., None], -1) * t)[..., 0]   # (nT, m)
        Om = Gwc * C / (1 - Gwt * Nx)
        Hx = Gxc * C + Gxt * Nx * Om
        He = Om / (1j * w)
        cost[a] = 0.5 * (_log_residual_cost(Hx, hx, wx) + _log_residual_cost(He, he, we))
    cands, ccost = _local_minima(cost, keep)
    starts = []
    along = _torque_like_free(base, names) if Tg is not None else []
    for a, b in cands:
        s = np.ones(len(names))
        if Kg is not None:
            s[idx["load_stiffness"]] = Kg[a] / prob.p_ref[idx["load_stiffness"]]
        if Tg is not None:
            s[idx["coulomb_torque"]] = Tg[b] / prob.p_ref[idx["coulomb_torque"]]
            s[along] = lam[b]      # free torque-like parameters start scaled with the level, as the grid had them
        starts.append(s)
    return GridSearch(Ks, Tg if Tg is not None else np.array([t_ref]), cost, tuple(starts), tuple(ccost),
                      time.perf_counter() - t0)


def _torque_like_free(model, names) -> list[int]:
    """Indices of the free friction parameters (other than the level) that are torque-like
    (scale with the normal load): the grid moved them with T_c."""
    import dataclasses

    from taos.identify.surrogate import PARAMETERS

    keys = {f.metadata.get("key") for f in dataclasses.fields(model.friction) if f.metadata.get("torque_like")}
    return [i for i, n in enumerate(names) if n != "coulomb_torque" and PARAMETERS[n].section == "friction"
            and PARAMETERS[n].toml_key in keys]


def _local_minima(cost: np.ndarray, keep: int) -> tuple[list[tuple[int, int]], list[float]]:
    """Up to ``keep`` grid cells lower than their 8 neighbours (ties: the first), best first."""
    c = np.where(np.isfinite(cost), cost, np.inf)
    pad = np.pad(c, 1, constant_values=np.inf)
    nb = np.min([pad[1 + di:1 + di + c.shape[0], 1 + dj:1 + dj + c.shape[1]]
                 for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0)], axis=0)
    mins = np.argwhere((c <= nb) & np.isfinite(c))
    order = np.argsort(c[mins[:, 0], mins[:, 1]])[:max(1, keep)]
    out = [(int(mins[k, 0]), int(mins[k, 1])) for k in order]
    if not out:
        out = [tuple(int(v) for v in np.unravel_index(np.argmin(c), c.shape))]
    return out, [float(c[a, b]) for a, b in out]
