"""Ambient and hot fire fitted with the 3-D TAOS model, each with its own FEM gimbal pair
(issue 39.2; the paper's Figure 11 and its K_L adjusted to 115,000 / 205,000 lbf/in).

Each condition's record is fitted (:func:`taos.identify.fit3d.fit_taos`) from its own model
file, whose ``[gimbal] stiffness_file`` names that condition's FEM halves (``rs25_ambient``:
``gimbal_hanging.npz``, ``rs25_hotfire``: ``gimbal_thrust.npz``). The fitted total load
stiffness K_L of each condition is split by the loader into the FEM gimbal in series with the
actuator line, K_line (:mod:`taos.taos3d.calibrate`). Reported:

* the total shift Delta K_L = K_L,B - K_L,A with se = sqrt(se_A^2 + se_B^2) (independent records);
* the shift the FEM does not explain, Delta K_line = K_line,B - K_line,A: were the FEM
  gimbal's change between the conditions the whole story, the line outside it would be the
  same in both. se(K_line) = (dK_line / dK_L) se(K_L) (delta method, the derivative by a
  relative step of 1e-3 through the loader), combined as above.

Analysis only: :func:`taos.plotting.compare.plot_compare3d` draws Figure 11's analogue.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.units import N_PER_M_PER_LBF_PER_IN as LBF_IN  # N/m per lbf/in


def line_stiffness_slope(result) -> float:
    """dK_line / dK_L [-] of a fitted 3-D model (a central difference through the loader)."""
    from taos.taos3d import with_values
    K = result.model.structure.load_stiffness_N_per_m
    lo = with_values(result.taos, {"structure.load_stiffness": K * (1 - 1e-3)}).line_load_stiffness_N_per_m
    hi = with_values(result.taos, {"structure.load_stiffness": K * (1 + 1e-3)}).line_load_stiffness_N_per_m
    return float((hi - lo) / (2e-3 * K))


@dataclass(frozen=True, eq=False)
class Comparison3d:
    """Two conditions fitted with the 3-D model (module docstring); SI."""

    labels: tuple[str, str]
    fits: tuple
    total_N_per_m: tuple[float, float]
    total_se_N_per_m: tuple[float, float]
    line_N_per_m: tuple[float, float]
    line_se_N_per_m: tuple[float, float]

    @property
    def shift_total(self) -> tuple[float, float]:
        return (self.total_N_per_m[1] - self.total_N_per_m[0], math.hypot(*self.total_se_N_per_m))

    @property
    def shift_line(self) -> tuple[float, float]:
        """(Delta K_line, its se) [N/m]: the load-stiffness shift the FEM does not explain."""
        return (self.line_N_per_m[1] - self.line_N_per_m[0], math.hypot(*self.line_se_N_per_m))

    def to_dict(self) -> dict:
        st, sl = self.shift_total, self.shift_line
        return {"engine": "taos", "labels": list(self.labels),
                "conditions": [{"label": lab, "stiffness_file": f.taos.stiffness_source,
                                "load_stiffness_lbf_in": self.total_N_per_m[i] / LBF_IN,
                                "load_stiffness_se_lbf_in": self.total_se_N_per_m[i] / LBF_IN,
                                "line_load_stiffness_lbf_in": self.line_N_per_m[i] / LBF_IN,
                                "line_load_stiffness_se_lbf_in": self.line_se_N_per_m[i] / LBF_IN,
                                "fit": f.to_dict()} for i, (lab, f) in enumerate(zip(self.labels, self.fits))],
                "load_stiffness_shift_lbf_in": st[0] / LBF_IN, "load_stiffness_shift_se_lbf_in": st[1] / LBF_IN,
                "unexplained_by_fem_shift_lbf_in": sl[0] / LBF_IN,
                "unexplained_by_fem_shift_se_lbf_in": sl[1] / LBF_IN}

    def table(self) -> str:
        lines = [f"{'condition':12s} {'FEM gimbal':22s} {'K_L total [lbf/in]':>24s} {'K_line [lbf/in]':>24s}  fit"]
        from pathlib import Path
        for i, (lab, f) in enumerate(zip(self.labels, self.fits)):
            flag = f.adequacy().verdict + ("" if f.identifiable else ", NOT IDENTIFIED: " + ",".join(f.unidentified))
            lines.append(f"{lab:12s} {Path(f.taos.stiffness_source).name:22s} "
                         f"{self.total_N_per_m[i] / LBF_IN:12.6g} +- {self.total_se_N_per_m[i] / LBF_IN:<8.3g} "
                         f"{self.line_N_per_m[i] / LBF_IN:12.6g} +- {self.line_se_N_per_m[i] / LBF_IN:<8.3g}  {flag}")
        st, sl = self.shift_total, self.shift_line
        lines.append(f"K_L shift {self.labels[0]} -> {self.labels[1]}: {st[0] / LBF_IN:+.6g} +- {st[1] / LBF_IN:.3g} "
                     f"lbf/in (total); not explained by the FEM gimbal pair (line stiffness shift): "
                     f"{sl[0] / LBF_IN:+.6g} +- {sl[1] / LBF_IN:.3g} lbf/in")
        for lab, f in zip(self.labels, self.fits):
            for i, p in enumerate(f.params):
                if p.name != "load_stiffness":
                    from taos.identify.params3d import to_eng
                    lines.append(f"{lab}: {p.name} {to_eng(p, f.values[i]):.6g} +- "
                                 f"{abs(to_eng(p, f.values[i] + f.std_errors[i]) - to_eng(p, f.values[i])):.3g} "
                                 f"{p.unit or '-'}")
        return "\n".join(lines)


def same_taos_model(a, b) -> bool:
    """True when 3-D models ``a`` and ``b`` have the same content: the planar base's SHA-256
    (its files, overrides and changes made in code), the gimbal parameters, the stiffness source
    and the line-stiffness fingerprint (both halves' matrices, the geometry, the engine)."""
    from taos.taos3d.model import line_stiffness_basis

    return (a is b) or (a.base.sha256 == b.base.sha256 and a.gimbal == b.gimbal
                        and a.stiffness_source == b.stiffness_source
                        and line_stiffness_basis(a) == line_stiffness_basis(b))


def same_records(a, b) -> bool:
    """True when two lists of :class:`~taos.identify.data.TestData` hold equal records (every
    field; arrays element by element)."""
    import dataclasses

    def eq(u, v):
        if isinstance(u, np.ndarray) or isinstance(v, np.ndarray):
            return (isinstance(u, np.ndarray) and isinstance(v, np.ndarray) and u.shape == v.shape
                    and u.dtype == v.dtype and bool(np.array_equal(u, v)))
        try:
            return type(u) is type(v) and bool(u == v)
        except (TypeError, ValueError):   # e.g. arrays inside the metadata: not known equal
            return False

    return len(a) == len(b) and all(
        x is y or (type(x) is type(y) and all(eq(getattr(x, f.name), getattr(y, f.name))
                                              for f in dataclasses.fields(x)))
        for x, y in zip(a, b))


def compare_taos(models, records, free, labels=("ambient", "hot fire"), **fit_kwargs) -> Comparison3d:
    """Fit ``records[i]`` (a list of :class:`~taos.identify.data.TestData`) with ``models[i]``
    (each with its own ``[gimbal] stiffness_file``), ``free[i]`` the free names (a list per
    condition); ``load_stiffness`` must be free in both (the quantity compared). A condition equal
    to an earlier one (:func:`same_taos_model`, :func:`same_records`, the same free names) reuses
    its fit instead of repeating it (the fit is deterministic: the same numbers)."""
    from taos.errors import InputError
    from taos.identify.fit3d import fit_taos
    from taos.taos3d import TaosModel, taos_model

    fits, done = [], []
    for m, recs, fr in zip(models, records, free):
        if "load_stiffness" not in fr:
            raise InputError("command line", "--free", "load_stiffness among the free parameters (the compared "
                             "quantity)", got=",".join(fr))
        tm = m if isinstance(m, TaosModel) else taos_model(m)
        # a condition identical to one already fitted (the same model content, records and free
        # names: e.g. a record compared with itself) has that fit: fit_taos is deterministic
        same = next((f for (tm2, recs2, fr2), f in zip(done, fits)
                     if list(fr2) == list(fr) and same_taos_model(tm2, tm) and same_records(recs2, recs)), None)
        fits.append(same if same is not None else fit_taos(tm, recs, fr, **{"refuse": False, **fit_kwargs}))
        done.append((tm, recs, fr))
    tot, tse, line, lse = [], [], [], []
    for f in fits:
        k = f.names.index("load_stiffness")
        tot.append(float(f.values[k]))
        tse.append(float(f.std_errors[k]))
        line.append(f.line_stiffness_N_per_m())
        lse.append(abs(line_stiffness_slope(f)) * float(f.std_errors[k]))
    return Comparison3d(tuple(labels), tuple(fits), tuple(tot), tuple(tse), tuple(line), tuple(lse))


def comparison3d_curves(cmp: Comparison3d) -> list[dict]:
    """Per condition and axis: frequency [Hz], data and fitted piston x_p/(R theta_c) and engine
    gains [dB] and phases [deg] (continuous, the fit's branch), for the plot."""
    out = []
    for lab, f in zip(cmp.labels, cmp.fits):
        R = f.model.actuator.moment_arm_m
        for d, m in zip(f.data, f.fitted):
            order = np.argsort(d.freq_hz)
            row = {"label": lab, "axis": d.axis, "freq_hz": d.freq_hz[order]}
            for key, hd, hm in (("piston", d.piston_m_per_rad / R, m.piston_m_per_rad / R),
                                ("engine", d.engine, m.engine)):
                if hd is None or hm is None:
                    continue
                hd, hm = hd[order], hm[order]
                pm = np.degrees(np.unwrap(np.angle(hm)))
                pd = pm + np.degrees(np.angle(hd / hm))
                row[key] = {"data_db": 20 * np.log10(np.abs(hd)), "fit_db": 20 * np.log10(np.abs(hm)),
                            "data_deg": pd, "fit_deg": pm}
            out.append(row)
    return out
