"""Side-by-side comparison of two model conditions, e.g. ambient and hot fire (seed paper
sec. 2.2, figs. 2 and 11).

:func:`compare_models` tabulates every parameter of both models (SI, with K_L in lbf/in and
the friction torque in in*lbf as well) with the ratio B / A, and the derived figures that
tell the conditions apart: the load resonance w_L = sqrt((K_L R^2 + K_n) / J_n) / 2 pi
(paper eq. 1) per axis, the notch of the linear command -> piston response
(:func:`taos.planar.simplex.load_resonance_from_notch`), and the friction breakaway deflection
T_c / (K_L R^2). With test data (time-history files) each condition's responses are
estimated (:func:`taos.identify.estimation.estimate`) and the plots overlay them on the model curves:
the exact linear response and the time-domain sine dwell of the full model at the data's
command amplitudes.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from taos.model import TvcModel
from taos.units import from_si

if TYPE_CHECKING:
    from taos.identify.estimate import MeasuredResponse


@dataclass(frozen=True)
class Row:
    """One line of the comparison table (value_a/value_b in ``unit``; ratio b / a)."""

    group: str
    name: str
    unit: str
    value_a: float
    value_b: float
    text_a: str = ""      # a non-numeric entry (the friction law's name) instead of a value
    text_b: str = ""

    @property
    def ratio(self) -> float:
        return self.value_b / self.value_a if self.value_a not in (0.0,) and math.isfinite(self.value_a) else math.nan


@dataclass(frozen=True, eq=False)
class Comparison:
    """Two models, their table, and optional measured responses per condition."""

    labels: tuple[str, str]
    models: tuple[TvcModel, TvcModel]
    rows: tuple[Row, ...]
    data: tuple[tuple, tuple] = ((), ())
    meta: dict = field(default_factory=dict)

    def table(self) -> str:
        a, b = self.labels
        w = max(len(r.name) for r in self.rows) + 2
        lines = [f"{'':{w}s} {a:>16s} {b:>16s} {'ratio':>9s}  unit"]
        group = None
        for r in self.rows:
            if r.group != group:
                lines.append(f"[{r.group}]")
                group = r.group
            ratio = f"{r.ratio:9.4g}" if math.isfinite(r.ratio) else f"{'-':>9s}"
            cell = lambda v, t: f"{t:>16s}" if t else (f"{v:16.6g}" if math.isfinite(v) else f"{'-':>16s}")  # noqa: E731
            lines.append(f"{r.name:{w}s} {cell(r.value_a, r.text_a)} {cell(r.value_b, r.text_b)} {ratio}  {r.unit}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {"labels": list(self.labels),
                "models": [m.source for m in self.models],
                "rows": [{"group": r.group, "name": r.name, "unit": r.unit, "a": r.text_a or _num(r.value_a),
                          "b": r.text_b or _num(r.value_b),
                          "ratio": r.ratio if math.isfinite(r.ratio) else None} for r in self.rows],
                "data": [[d.to_dict() for d in ds] for ds in self.data], **self.meta}

    def value(self, name: str) -> tuple[float, float]:
        for r in self.rows:
            if r.name == name:
                return r.value_a, r.value_b
        raise KeyError(name)

def _num(v: float):
    return float(v) if math.isfinite(v) else None


def _unit_of(fieldname: str) -> str:
    for suf, u in (("_N_per_m", "N/m"), ("_Nm_per_rad", "N*m/rad"), ("_Nms_per_rad", "N*m*s/rad"),
                   ("_Ns_per_m", "N*s/m"), ("_kgm2", "kg*m**2"), ("_kg", "kg"), ("_m2", "m**2"), ("_m3", "m**3"),
                   ("_m_per_s_Pa", "m/(s*Pa)"), ("_m3_per_s_Pa", "m**3/(s*Pa)"), ("_Pa", "Pa"), ("_m_per_s", "m/s"), ("_per_s", "1/s"),
                   ("_hz", "Hz"), ("_rad_s", "rad/s"), ("_Nm", "N*m"), ("_N", "N"), ("_rad", "rad"), ("_s", "s"),
                   ("_m", "m")):
        if fieldname.endswith(suf):
            return u
    return "-"


def _numeric_fields(obj) -> dict:
    out = {}
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, bool):
            out[f.name] = float(v)
        elif isinstance(v, (int, float)):
            out[f.name] = float(v)
    return out


def compare_models(model_a: TvcModel, model_b: TvcModel, data_a: Sequence[MeasuredResponse] = (),
                   data_b: Sequence[MeasuredResponse] = (),
                   labels: tuple[str, str] | None = None) -> Comparison:
    """The comparison table of two models (module docstring); ``data_a``/``data_b`` are
    lists of :class:`~taos.identify.estimation.MeasuredResponse` shown on the plots."""
    from taos.bounds import check_instance
    from taos.errors import InputError
    from taos.identify.estimation import MeasuredResponse
    from taos.planar.simplex import load_resonance_from_notch

    for name, m in (("model_a", model_a), ("model_b", model_b)):
        check_instance(m, name, TvcModel, "a TvcModel (taos.load_model)")
    for name, d in (("data_a", data_a), ("data_b", data_b)):
        if not isinstance(d, (list, tuple)) or not all(isinstance(r, MeasuredResponse) for r in d):
            raise InputError("argument", name, "a list of MeasuredResponse (taos.estimate)", got=repr(d)[:40])
    if labels is not None and not (isinstance(labels, (list, tuple)) and len(labels) == 2
                                   and all(isinstance(x, str) for x in labels)):
        raise InputError("argument", "labels", "None or two texts", got=repr(labels)[:40])

    labels = labels or (model_a.name, model_b.name)
    rows: list[Row] = []
    for part in ("engine", "actuator", "structure"):
        fa, fb = _numeric_fields(getattr(model_a, part)), _numeric_fields(getattr(model_b, part))
        for k in fa:
            rows.append(Row(part, k, _unit_of(k), fa[k], fb.get(k, math.nan)))
    rows.append(Row("friction", "model", "-", math.nan, math.nan, model_a.friction.name, model_b.friction.name))
    fa, fb = _numeric_fields(model_a.friction), _numeric_fields(model_b.friction)
    for k in list(fa) + [k for k in fb if k not in fa]:
        rows.append(Row("friction", k, _unit_of(k), fa.get(k, math.nan), fb.get(k, math.nan)))
    av_a, av_b = model_a.avionics, model_b.avionics
    rows.append(Row("avionics", "quantization_bits", "-", av_a.quantization_bits, av_b.quantization_bits))
    rows.append(Row("avionics", "lsb_deg", "deg", math.degrees(av_a.lsb_rad), math.degrees(av_b.lsb_rad)))
    rows.append(Row("avionics", "min_crossover_gain", "-", min(av_a.gain_table or (1.0,)),
                    min(av_b.gain_table or (1.0,))))
    eng = "engineering units"
    rows.append(Row(eng, "load_stiffness", "lbf/in", from_si(model_a.structure.load_stiffness_N_per_m, "N/m", "lbf/in"),
                    from_si(model_b.structure.load_stiffness_N_per_m, "N/m", "lbf/in")))
    rows.append(Row(eng, "coulomb_torque", "in*lbf", from_si(model_a.friction.coulomb_torque_Nm, "N*m", "in*lbf"),
                    from_si(model_b.friction.coulomb_torque_Nm, "N*m", "in*lbf")))
    der = "derived"
    for ax in ("pitch", "yaw"):
        rows.append(Row(der, f"load_resonance_{ax}_hz", "Hz", model_a.load_resonance_hz(ax), model_b.load_resonance_hz(ax)))
        rows.append(Row(der, f"notch_frequency_{ax}_hz", "Hz", load_resonance_from_notch(model_a, ax),
                        load_resonance_from_notch(model_b, ax)))
    rows.append(Row(der, "breakaway_deflection_deg", "deg", math.degrees(model_a.breakaway_deflection_rad()),
                    math.degrees(model_b.breakaway_deflection_rad())))
    return Comparison(tuple(labels), (model_a, model_b), tuple(rows), (tuple(data_a), tuple(data_b)))


def model_curves(model: TvcModel, axis: str, amplitudes_rad, f_lo: float = 0.3, f_hi: float = 20.0, n: int = 24):
    """(dense linear FrequencyResponse, [sine-dwell FrequencyResponse per amplitude]) for plots."""
    from taos.planar.freqresp import linear_freqresp, sine_dwell_freqresp

    f = np.geomspace(f_lo, f_hi, 300)
    lin = linear_freqresp(model, f, axis)
    fd = np.geomspace(f_lo, f_hi, n)
    amps = sorted({float(a) for a in np.round(np.asarray(amplitudes_rad, float), 7) if math.isfinite(a) and a > 0})
    dwell = [sine_dwell_freqresp(model, fd, a, axis) for a in amps]
    return lin, dwell


@dataclass(frozen=True, eq=False)
class ConditionCurves:
    """What the comparison plots draw for one condition and axis: the model's exact linear
    response and its sine dwells at the data's command amplitudes (FrequencyResponse objects),
    the piston notch [Hz] (:func:`taos.planar.simplex.load_resonance_from_notch`), the measured
    responses on this axis, and the moment arm R [m] and load stiffness K_L [N/m]."""

    label: str
    axis: str
    linear: object
    dwell: tuple
    notch_hz: float
    data: tuple
    moment_arm_m: float
    load_stiffness_N_per_m: float


def comparison_curves(cmp: Comparison, axis: str = "pitch") -> tuple[ConditionCurves, ConditionCurves]:
    """The model curves of both conditions of ``cmp`` on ``axis`` (computed here, drawn by
    :mod:`taos.plotting.fit`)."""
    out = []
    notches = cmp.value(f"notch_frequency_{axis}_hz")
    for label, model, data, notch in zip(cmp.labels, cmp.models, cmp.data, notches):
        on_axis = tuple(d for d in data if d.axis == axis)
        lin, dwell = model_curves(model, axis, [a for d in on_axis for a in d.amplitude_rad])
        out.append(ConditionCurves(label, axis, lin, tuple(dwell), notch, on_axis,
                                   model.actuator.moment_arm_m, model.structure.load_stiffness_N_per_m))
    return out[0], out[1]
