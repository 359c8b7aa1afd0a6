"""The LCO verdict over one or two parameters: where the soft-LCO / stiff-none result flips.

The paper's flight result (sec. 3.2, figs. 7-8) sits on a margin of about a dB: the friction's
small-amplitude gain loss against the flight loop's low-frequency gain margin. This module runs
the describing-function prediction (:func:`taos.flight.lco.analyse_lco`, time domain off) over a
grid of one or two parameters and returns, per grid point, the LCO verdict, its command and
engine amplitudes, frequency, and the remaining margin when there is none.

Sweepable parameters (:data:`SWEEPABLE`, name -> where it lives, unit kind):

* ``bristle_stiffness``, ``coulomb_torque`` : the TVC model's friction law
* ``load_stiffness`` : the TVC model's load path
* ``integral_gain``, ``attitude_gain``, ``rate_gain`` : the flight loop's FCS; the map also
  reports the loop's own low-frequency gain margin (without the TVC) for each value, the
  quantity the calibration actually sets (models/flight/core_stage.toml).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from taos.errors import InputError
from taos.flight.lco import analyse_lco, describing_function_map_for
from taos.flight.vehicle import FlightModel, loop_freqresp, margins
from taos.model import TvcModel
from taos.units import to_si

#: name -> (part, field, unit kind, unit shown)
SWEEPABLE = {
    "bristle_stiffness": ("friction", "bristle_stiffness_Nm_per_rad", "rotational_stiffness", "N*m/rad"),
    "coulomb_torque": ("friction", "coulomb_torque_Nm", "torque", "N*m"),
    "load_stiffness": ("structure", "load_stiffness_N_per_m", "stiffness", "N/m"),
    "integral_gain": ("fcs", "integral_gain_per_s", "rate", "1/s"),
    "attitude_gain": ("fcs", "attitude_gain", "dimensionless", "1"),
    "rate_gain": ("fcs", "rate_gain_s", "time", "s"),
}


@dataclass(frozen=True)
class SweepAxis:
    """One swept parameter: its name (:data:`SWEEPABLE`) and values in SI."""

    name: str
    values: tuple[float, ...]

    @property
    def unit(self) -> str:
        return SWEEPABLE[self.name][3]


def parse_sweep(text: str) -> SweepAxis:
    """``NAME=V1,V2,...`` (values in SI, or each with its unit: ``1.3e7 N*m/rad``) -> SweepAxis.
    Raises :class:`InputError` naming ``--sweep`` on bad input."""
    name, sep, rest = text.partition("=")
    name = name.strip()
    if not sep or name not in SWEEPABLE:
        raise InputError("command line", "--sweep", "NAME=V1,V2,... with NAME one of " + ", ".join(SWEEPABLE),
                         got=repr(text))
    kind = SWEEPABLE[name][2]
    vals = []
    for v in rest.split(","):
        v = v.strip()
        try:
            vals.append(float(v))
        except ValueError:
            vals.append(to_si(v, kind, source="command line", field=f"--sweep {name}", positive=True))
    if len(vals) < 1 or not all(math.isfinite(v) and v > 0 for v in vals):
        raise InputError("command line", "--sweep", f"positive values for {name}", got=repr(rest))
    return SweepAxis(name, tuple(vals))


def apply_value(flight: FlightModel, model: TvcModel, name: str, value: float) -> tuple[FlightModel, TvcModel]:
    """The flight loop and TVC model with parameter ``name`` set to ``value`` [SI]."""
    part, fld, _, _ = SWEEPABLE[name]
    if part == "fcs":
        return dataclasses.replace(flight, fcs=dataclasses.replace(flight.fcs, **{fld: value})), model
    obj = getattr(model, part)
    if not hasattr(obj, fld):
        raise InputError(model.source, f"friction.{name}", f"a friction law with {name} (the model's is "
                         f"{model.friction.name})", got="a law without it")
    return flight, model.replace(**{part: dataclasses.replace(obj, **{fld: value})})


def loop_low_gain_margin_db(flight: FlightModel) -> float | None:
    """Low-frequency gain margin [dB] of the flight loop without the TVC."""
    f = np.logspace(-3, 1, 3000)
    return margins(f, loop_freqresp(flight, f)).low_gain_margin_db


@dataclass(frozen=True, eq=False)
class LcoMap:
    """Verdict grid: arrays shaped (n_1,) or (n_1, n_2) over the swept values. ``margin_db`` is
    the remaining margin where there is no cycle (0 where there is); amplitudes and frequency
    are NaN where there is no cycle."""

    axes: tuple[SweepAxis, ...]
    lco: np.ndarray
    amplitude_deg: np.ndarray
    engine_amplitude_deg: np.ndarray
    frequency_hz: np.ndarray
    margin_db: np.ndarray
    friction_model: str
    loop_low_gain_margin_db: dict = field(default_factory=dict)

    def flips(self) -> list[dict]:
        """Neighbouring grid points whose verdicts differ (where the verdict flips)."""
        out = []
        shape = self.lco.shape
        for idx in np.ndindex(shape):
            for d in range(len(shape)):
                j = list(idx)
                j[d] += 1
                if j[d] < shape[d] and self.lco[idx] != self.lco[tuple(j)]:
                    out.append({"axis": self.axes[d].name,
                                "between": [self.axes[d].values[idx[d]], self.axes[d].values[j[d]]],
                                "at": {a.name: a.values[i] for k, (a, i) in enumerate(zip(self.axes, idx)) if k != d}})
        return out

    def to_dict(self) -> dict:
        nan = lambda a: [None if not np.isfinite(x) else float(x) for x in np.ravel(a)]  # noqa: E731
        shape = list(self.lco.shape)

        def grid(a):
            return np.array(nan(a), dtype=object).reshape(shape).tolist()
        return {"parameters": [a.name for a in self.axes], "units": [a.unit for a in self.axes],
                "values": [list(a.values) for a in self.axes], "friction_model": self.friction_model,
                "lco": self.lco.tolist(), "amplitude_deg": grid(self.amplitude_deg),
                "engine_amplitude_deg": grid(self.engine_amplitude_deg), "frequency_hz": grid(self.frequency_hz),
                "margin_db": grid(self.margin_db), "loop_low_gain_margin_db": self.loop_low_gain_margin_db,
                "flips": self.flips()}


def lco_map(flight: FlightModel, model: TvcModel, axes, *, amplitudes_rad=None, freq_hz=None,
            avionics: str = "bounding") -> LcoMap:
    """Describing-function LCO prediction over the grid of ``axes`` (one or two
    :class:`SweepAxis`); other settings as :func:`taos.flight.lco.analyse_lco`."""
    axes = tuple(axes)
    if not 1 <= len(axes) <= 2:
        raise InputError("command line", "--sweep", "one or two parameters", got=str(len(axes)))
    shape = tuple(len(a.values) for a in axes)
    lco = np.zeros(shape, bool)
    amp, eamp, fr, mg = (np.full(shape, np.nan) for _ in range(4))
    lgm = {}
    maps = {}   # the describing function depends on the TVC only: one map per TVC variant
    for idx in np.ndindex(shape):
        fl, m = flight, model
        tvc_key = []
        for a, i in zip(axes, idx):
            fl, m = apply_value(fl, m, a.name, a.values[i])
            if SWEEPABLE[a.name][0] == "fcs":
                lgm[f"{a.name}={a.values[i]:.6g}"] = loop_low_gain_margin_db(fl)
            else:
                tvc_key.append((a.name, a.values[i]))
        key = tuple(tvc_key)
        if key not in maps:
            maps[key] = describing_function_map_for(m, fl.axis, amplitudes_rad=amplitudes_rad, freq_hz=freq_hz,
                                                    avionics=avionics)
        d = analyse_lco(fl, m, amplitudes_rad=amplitudes_rad, freq_hz=freq_hz, avionics=avionics,
                        time_domain=False, df=maps[key]).to_dict()
        lco[idx] = bool(d["lco"])
        if d["lco"]:
            amp[idx], eamp[idx], fr[idx], mg[idx] = (d["amplitude_deg"], d["engine_amplitude_deg"],
                                                     d["frequency_hz"], 0.0)
        elif d["margin_db"] is not None:
            mg[idx] = d["margin_db"]
    return LcoMap(axes, lco, amp, eamp, fr, mg, model.friction.name, lgm)
