"""The result of a 3-D fit (:func:`taos.identify.fit3d.fit_taos`): values, standard errors,
identifiability, adequacy, the fitted responses, JSON, text and the fitted model file.

Statistics (Gauss-Newton, first order in the noise): with J the Jacobian of the normalised
residuals r in x = ln(p / p_start), cov_x = s^2 (J^T J)^-1, s^2 = 2 cost / (m - n) (or 1 with
``absolute_sigma``), se(p_i) = p_i sqrt(cov_x[i, i]) [SI], correlations cov_x[i, j] /
(se_x,i se_x,j). Identified: se_x,i <= ``max_rel_se`` and |corr| <= ``max_corr`` with every
other parameter, and J^T J of reciprocal condition above 1e-12.
"""

from __future__ import annotations

from taos.units import N_PER_M_PER_LBF_PER_IN

import datetime as _dt
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from taos.errors import InputError
from taos.identify.params3d import Param3d, to_eng, variant_values

RCOND_MIN = 1e-12


@dataclass(frozen=True, eq=False)
class Fit3dResult:
    """A fit of the 3-D TAOS model: ``values`` [SI] of ``names`` (model-file keys in
    ``params``), ``taos`` the fitted :class:`~taos.taos3d.TaosModel` (a variant of
    ``initial`` through the loader), ``model`` its planar base."""

    taos: object
    initial: object
    params: tuple[Param3d, ...]
    values: np.ndarray
    start_values: np.ndarray
    std_errors: np.ndarray
    correlation: np.ndarray
    cost: float
    n_residuals: int
    sigma2: float
    data: tuple
    fitted: tuple
    lower_si: np.ndarray
    upper_si: np.ndarray
    bound_basis: tuple[str, ...]
    unidentified: tuple[str, ...] = ()
    unidentified_reason: str = ""
    global_search: dict | None = None
    runs: int = 0
    failed_runs: int = 0
    nfev: int = 0
    wall_s: float = 0.0
    absolute_sigma: bool = False
    solver: dict = field(default_factory=dict)
    sources: tuple[str, ...] = ()

    # -- construction ------------------------------------------------------------------
    @classmethod
    def build(cls, tm0, params, p0, x, r, J, lo_si, hi_si, basis, replays, ev, gs, *, absolute_sigma, refuse,
              max_rel_se, max_corr, wall_s, nfev, fd_step, local_starts=1):
        from taos.errors import SimulationUnstable
        from taos.identify.params3d import REPLAY_DT_S, Unidentifiable

        n, m = len(params), r.size
        cost = 0.5 * float(r @ r)
        sigma2 = 1.0 if absolute_sigma else 2 * cost / max(1, m - n)
        JtJ = J.T @ J
        ev_max = float(np.max(np.linalg.eigvalsh(JtJ))) if n else 0.0
        ev_min = float(np.min(np.linalg.eigvalsh(JtJ))) if n else 0.0
        rcond = ev_min / ev_max if ev_max > 0 else 0.0
        cov = sigma2 * np.linalg.pinv(JtJ)
        se_x = np.sqrt(np.clip(np.diag(cov), 0, None))
        d = np.where(se_x > 0, se_x, 1.0)
        corr = cov / np.outer(d, d)
        values = p0 * np.exp(x)
        names = [p.name for p in params]
        why = []
        cn = np.linalg.norm(J, axis=0)
        for i, nm in enumerate(names):
            if not cn[i] > 1e-6 * max(float(cn.max()), 1e-300):
                why.append(f"{nm}: the record does not see it (no residual changes)")
            elif se_x[i] > max_rel_se:
                why.append(f"{nm}: relative standard error {100 * se_x[i]:.3g} % (> {100 * max_rel_se:g} %)")
            for j in range(i):
                if abs(corr[i, j]) > max_corr:
                    why.append(f"{nm} and {names[j]}: correlation {corr[i, j]:+.5f}")
        if n and rcond < RCOND_MIN and not why:   # the parameters along the null direction
            w, V = np.linalg.eigh(JtJ)
            null = [names[i] for i in np.flatnonzero(np.abs(V[:, 0]) > 0.3)]
            why.append(f"{' and '.join(null)}: J^T J nearly singular along them (reciprocal condition {rcond:.2g})")
        unid = tuple(nm for nm in names if any(w.split(":")[0] == nm or nm in w.split(":")[0].split(" and ")
                                               for w in why))
        if not unid and why:
            unid = tuple(names)
        reason = "; ".join(why)
        srcs = tuple(rp.data.source for rp in replays)

        def result():
            """The fit at ``values``: the fitted model and its responses at the records' points."""
            from taos.taos3d import with_values
            tm_fit = with_values(tm0, variant_values(tm0, params, values))
            fitted = tuple(resp for rp in replays for resp in rp.simulate(tm_fit))
            data = tuple(resp for rp in replays for resp in rp.responses)
            return cls(taos=tm_fit, initial=tm0, params=tuple(params), values=values, start_values=p0,
                       std_errors=values * se_x, correlation=corr, cost=cost, n_residuals=m, sigma2=sigma2, data=data,
                       fitted=fitted, lower_si=lo_si, upper_si=hi_si, bound_basis=tuple(basis), unidentified=unid,
                       unidentified_reason=reason, global_search=gs, runs=ev.runs, failed_runs=ev.failures, nfev=nfev,
                       wall_s=wall_s, absolute_sigma=absolute_sigma, sources=srcs,
                       solver={"engine": "taos", "replay_dt_max_s": REPLAY_DT_S, "local": "scipy least_squares trf",
                               "jacobian": f"forward differences in ln p, step {fd_step:g}, runs on threads",
                               "rcond_JtJ": rcond, "max_rel_se": max_rel_se, "max_corr": max_corr,
                               "local_starts": int(local_starts),
                               "integrator": "rk4, trapezoidal bearing torque + BDF2 bearing substeps"})

        if refuse and why:   # refused, with the fit itself for whoever asks (Unidentifiable.result)
            err = Unidentifiable(", ".join(srcs)[:120], "--free",
                                 "parameters the record identifies (drop or hold the others, or add records)",
                                 got=reason[:400])
            try:
                err.result = result()
            except (InputError, SimulationUnstable):   # the refusal stands without it
                pass
            raise err
        return result()

    # -- derived -----------------------------------------------------------------------
    @property
    def model(self):
        """The fitted planar base (:class:`~taos.model.TvcModel`)."""
        return self.taos.base

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    @property
    def identifiable(self) -> bool:
        return not self.unidentified

    @property
    def dof(self) -> int:
        return max(1, self.n_residuals - len(self.params))

    @property
    def at_bound(self) -> tuple[str, ...]:
        from taos.identify.adequacy import parameters_at_bound
        return parameters_at_bound(self.names, self.values, self.lower_si, self.upper_si)

    def adequacy(self, **kwargs):
        """The model-adequacy verdict (:mod:`taos.identify.adequacy`)."""
        from taos.identify.adequacy import assess
        return assess(self.cost, self.n_residuals, len(self.params), self.at_bound, **kwargs)

    def model_values(self) -> dict:
        """The fitted model-file keys and values [SI] (for :func:`taos.taos3d.with_values`)."""
        return variant_values(self.initial, self.params, self.values)

    def line_stiffness_N_per_m(self) -> float:
        """The fitted model's actuator-line stiffness [N/m] (outside the FEM gimbal)."""
        return float(self.taos.line_load_stiffness_N_per_m)

    # -- output ------------------------------------------------------------------------
    def to_dict(self) -> dict:
        from taos.results import model_provenance
        from taos.units import DIMENSIONS

        from taos.identify.adequacy import normal_quantile, student_t_quantile
        q = normal_quantile(0.975) if self.absolute_sigma else student_t_quantile(0.975, self.dof)
        atb = self.at_bound
        pars = {}
        for i, p in enumerate(self.params):
            v, se = float(self.values[i]), float(self.std_errors[i])
            pars[p.name] = {"key": p.key, "value_si": v, "std_error_si": se, "start_si": float(self.start_values[i]),
                            "si_unit": DIMENSIONS[p.kind][1], "unit": p.unit or "1", "value": to_eng(p, v),
                            "std_error": abs(to_eng(p, v + se) - to_eng(p, v)), "ci95_si": [v - q * se, v + q * se],
                            "bounds_si": [float(self.lower_si[i]), float(self.upper_si[i])],
                            "bounds_basis": self.bound_basis[i], "at_bound": p.name in atb,
                            "identified": p.name not in self.unidentified}
        return {"engine": "taos", "parameters": pars, "correlation": self.correlation.tolist(),
                "adequacy": self.adequacy().to_dict(), "identifiable": self.identifiable,
                "unidentified": list(self.unidentified), "unidentified_reason": self.unidentified_reason,
                "cost": self.cost, "n_residuals": self.n_residuals, "dof": self.dof,
                "residual_rms": math.sqrt(2 * self.cost / max(1, self.n_residuals)),
                "line_load_stiffness_N_per_m": self.line_stiffness_N_per_m(),
                "line_load_stiffness_yaw_N_per_m": float(self.taos.line_load_stiffnesses_N_per_m[1]),
                "stiffness_source": self.taos.stiffness_source, "friction_model": self.model.friction.name,
                "global_stage": None if self.global_search is None else
                {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.global_search.items()},
                "runs_3d": self.runs, "failed_runs_3d": self.failed_runs, "local_evaluations": self.nfev,
                "wall_s": self.wall_s, "solver": self.solver, "model_provenance": model_provenance(self.model),
                "data": [{"source": d.source, "axis": d.axis, "method": d.method, "points": len(d),
                          "condition": d.condition} for d in self.data]}

    def table(self) -> str:
        lines = [f"{'parameter':24s} {'start':>14s} {'fitted':>14s} {'std error':>12s} {'bounds':>25s}  unit"]
        atb = self.at_bound
        for i, p in enumerate(self.params):
            v = self.values[i]
            se = abs(to_eng(p, v + self.std_errors[i]) - to_eng(p, v))
            b = f"[{to_eng(p, self.lower_si[i]):.4g}, {to_eng(p, self.upper_si[i]):.4g}]"
            flag = ("  AT BOUND" if p.name in atb else "") + ("  NOT IDENTIFIED" if p.name in self.unidentified else "")
            lines.append(f"{p.name:24s} {to_eng(p, self.start_values[i]):14.6g} {to_eng(p, v):14.6g} {se:12.3g} "
                         f"{b:>25s}  {p.unit or '-'}{flag}")
        lines.append(f"line stiffness (outside the FEM gimbal {Path(self.taos.stiffness_source).name}) "
                     f"{self.line_stiffness_N_per_m() / N_PER_M_PER_LBF_PER_IN:.6g} lbf/in")
        g = self.global_search
        if g:
            lines.append(f"global first stage: {' x '.join(map(str, g['grid']))} grid over {', '.join(g['parameters'])}"
                         f" within the physical bounds ({g['cells']} 3-D replays, {g['wall_s']:.1f} s)")
        lines.append(f"residual rms {math.sqrt(2 * self.cost / max(1, self.n_residuals)):.3g} (sigma units), "
                     f"{self.n_residuals} residuals, {self.runs} 3-D replays, {self.wall_s:.1f} s")
        if self.unidentified:
            lines.append("NOT IDENTIFIED by the record: " + self.unidentified_reason)
        lines.append(self.adequacy().message())
        return "\n".join(lines)

    def write_model(self, path, data_label: str = "") -> None:
        """Write the fitted model file (:func:`fitted_model_text3d`), atomically, after checking
        that it loads back to the fitted values."""
        from taos.model import load_model
        from taos.results import atomic_write

        text = fitted_model_text3d(self, data_label)

        def write(tmp: Path):
            tmp.write_text(text)
            back = load_model(tmp)
            from taos.taos3d import taos_model
            tb = taos_model(back)
            for i, p in enumerate(self.params):
                got = p.get(tb)
                if not math.isclose(got, self.values[i], rel_tol=1e-5):
                    raise RuntimeError(f"written {p.name} reads back as {got}, not {self.values[i]}")
        atomic_write(path, write)


def _law_inline(law) -> dict:
    """The law's every parameter as model-file values with units (a fitted law written out)."""
    import dataclasses

    from taos.units import DIMENSIONS
    out = {}
    for f in dataclasses.fields(law):
        key, kind = f.metadata.get("key"), f.metadata.get("kind")
        if not key:
            continue
        v = float(getattr(law, f.name))
        out[key] = float(f"{v:.9g}") if kind == "dimensionless" else f"{v:.9g} {DIMENSIONS[kind][1]}"
    return out


def fitted_model_text3d(result: Fit3dResult, data_label: str = "") -> str:
    """The model file of ``result.initial`` with the fitted keys set (tomlkit: other lines and
    comments kept). A fitted friction parameter other than the level writes the fitted law
    inline (a shared parameter set's keys may not be repeated in a model file: the fitted
    bearing is no longer that set's hardware)."""
    import tomlkit

    from taos.model import resolve_parameter_set
    from taos.results import toml_set
    from taos.variants import file_value

    base = result.initial.base
    src = base.source
    try:
        doc = tomlkit.parse(Path(src).read_text())
    except OSError as e:
        raise InputError(src, "(file)", "the model file the fit started from", got=e.strerror) from None
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    label = data_label or ", ".join(result.sources)
    se = {p.key: (to_eng(p, result.values[i]), abs(to_eng(p, result.values[i] + result.std_errors[i])
                                                   - to_eng(p, result.values[i])), p.unit)
          for i, p in enumerate(result.params)}
    vals = result.model_values()
    law_free = any(p.friction and p.name not in ("coulomb_torque", "friction_coefficient") for p in result.params)
    if law_free:
        ftab = doc["friction"]
        if "parameter_set" in ftab:
            del ftab["parameter_set"]
        for k in list(ftab.keys()):
            if k != "model":
                del ftab[k]
        for k, v in _law_inline(result.model.friction).items():
            ftab[k] = v
        ftab.add(tomlkit.comment(f"the fitted law written inline by taos fit --engine taos ({stamp})"))
        vals = {k: v for k, v in vals.items() if not k.startswith("friction.")}
    else:
        for section in ("actuator", "friction"):
            ref = doc.get(section, {}).get("parameter_set")
            if ref:
                toml_set(doc, section, "parameter_set", resolve_parameter_set(str(ref), Path(src)).as_posix(),
                         f"the shared set of {Path(src).name}")
        if "friction.coulomb_torque" in vals and "static_torque" in doc.get("friction", {}) \
                and "friction.static_torque" not in vals:   # the level moves the law's held static torque
            vals["friction.static_torque"] = float(result.model.friction.static_torque_Nm)
    ref = doc.get("gimbal", {}).get("stiffness_file")
    if ref:
        from taos.shipped import resolve_reference
        toml_set(doc, "gimbal", "stiffness_file",
                 str(resolve_reference(str(ref), src, field="gimbal.stiffness_file", kind="model",
                                       what="a gimbal stiffness file")), f"the FEM gimbal of {Path(src).name}")
    for key, v in vals.items():
        section, _, k = key.partition(".")
        fv = file_value(key, v)
        if isinstance(fv, float):
            fv = float(f"{fv:.9g}")
        elif isinstance(fv, str) and " " in fv:
            num, unit = fv.split(" ", 1)
            fv = f"{float(num):.9g} {unit}"
        note = f"# set by taos fit --engine taos ({label}, {stamp})"
        if key in se:
            v_e, s_e, unit = se[key]
            note = f"# fitted by taos fit --engine taos ({label}, {stamp}): {v_e:.6g} +- {s_e:.3g} {unit} (1-sigma)"
        try:
            toml_set(doc, section, k, fv, note)
        except KeyError:
            raise InputError(src, f"[{section}]", "the section of a fitted value", got="no such section") from None
    if "name" in doc:
        toml_set(doc, "", "name", f"{base.name} (3-D fit)")
    head = f"# Model fitted by taos fit --engine taos on {stamp} to {label}; values marked '# fitted' were estimated.\n"
    return head + tomlkit.dumps(doc)
