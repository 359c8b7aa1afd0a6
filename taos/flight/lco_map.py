"""The LCO verdict over one or two parameters: where the soft-LCO / stiff-none result flips.

The paper's flight result (sec. 3.2, figs. 7-8) sits on a margin of about a dB: the friction's
small-amplitude gain loss against the flight loop's low-frequency gain margin. This module runs
the describing-function prediction (:func:`taos.flight.lco.analyse_lco`) over a grid of one or
two parameters and returns, per grid point, the LCO verdict, its command and engine amplitudes,
frequency, and the remaining margin when there is none. With the time domain on, every point is
confirmed by a closed-loop run started on the predicted periodic solution
(:mod:`taos.flight.lco_confirm`; or from rest, as ``taos lco`` does) and the run decides, as in
:func:`taos.flight.lco.decision`.

Cost and parallelism: one describing-function map per TVC variant (a flight-loop gain sweep
reuses it; its dwells run in one parallel call), the confirmation runs of all points on a thread
pool (:func:`taos.flight.lco_confirm.confirm_many`): every result is the same bit for bit for any
thread count. :func:`map_points` analyses any list of points; it is the run function of the map
as a stored, resumable campaign (:mod:`taos.flight.lco_campaign`).

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
    # the model variant through the loader (taos.variants): the key's one meaning, as `taos sweep --set`
    return flight, model.with_values({f"{part}.{name}": float(value)})


def loop_low_gain_margin_db(flight: FlightModel) -> float | None:
    """Low-frequency gain margin [dB] of the flight loop without the TVC."""
    f = np.logspace(-3, 1, 3000)
    return margins(f, loop_freqresp(flight, f)).low_gain_margin_db


#: the time-domain confirmation's starts: on the describing function's periodic solution, or from rest
STARTS = ("predicted", "rest")
#: per-point outputs (:func:`map_points`): floats (NaN where there is none) and yes/no flags
POINT_SCALARS = ("amplitude_deg", "engine_amplitude_deg", "frequency_hz", "margin_db", "td_amplitude_deg",
                 "td_engine_amplitude_deg", "td_frequency_hz", "td_simulated_s", "td_outcome")
POINT_FLAGS = ("lco", "prediction_lco", "td_lco", "grid_may_miss_cycle")


@dataclass(frozen=True)
class MapSettings:
    """How every point of a verdict map is analysed: the describing-function grid (None: the
    defaults of :func:`taos.flight.lco.describing_function_map_for`) [rad], [Hz], the avionics,
    and the time-domain confirmation: whether it runs, its start (:data:`STARTS`), its longest
    duration and final window [s]."""

    amplitudes_rad: tuple[float, ...] | None = None
    freq_hz: tuple[float, ...] | None = None
    avionics: str = "bounding"
    time_domain: bool = False
    start: str = "predicted"
    duration_s: float = 300.0
    window_s: float = 120.0

    def __post_init__(self):
        if self.start not in STARTS:
            raise InputError("command line", "--td-start", " or ".join(STARTS), got=repr(self.start))


def _start_point(pred) -> tuple[float, float, str] | None:
    """(command amplitude [rad], frequency [Hz], what it is) of the confirmation's start on the
    prediction ``pred`` (:mod:`taos.flight.lco_confirm`); None: nothing to start from."""
    from taos.flight.lco_verdict import grows_beyond_map, low_frequency_crossing_hz, nearest_margin, \
        signed_low_gain_margin
    c = pred.stable_cycle
    if c is not None:
        return c.amplitude_rad, c.freq_hz, "predicted cycle"
    if pred.cycles:
        u = min(pred.cycles, key=lambda x: x.amplitude_rad)
        return u.amplitude_rad, u.freq_hz, "threshold (unstable) cycle"
    if grows_beyond_map(pred):
        a = float(pred.df.amplitude_rad[-1])
        f0 = low_frequency_crossing_hz(pred)
        f = signed_low_gain_margin(pred, a, f0)[1] if f0 is not None else None
        if f is not None:
            return a, f, "largest map amplitude (loop unstable there)"
    near = nearest_margin(pred)
    return None if near is None else (near.amplitude_rad, near.freq_hz, "nearest margin")


def map_points(flight: FlightModel, model: TvcModel, names, rows, settings: MapSettings, *,
               threads: int | None = None) -> dict:
    """Analyse the points ``rows`` (n, len(names)) [SI] of parameters ``names`` (:data:`SWEEPABLE`):
    one describing-function map per TVC variant, the prediction at every point and, with
    ``settings.time_domain``, the confirmation run of every point, all runs on ``threads``
    threads (default numba's; the result is the same bit for bit for any count). Returns
    {name: (n,) array} for :data:`POINT_SCALARS` and :data:`POINT_FLAGS`; ``td_outcome`` is the
    index in :data:`taos.flight.lco_confirm.OUTCOMES` (NaN without a confirmation); ``lco`` is
    the time domain's verdict when it ran, the prediction's otherwise."""
    from taos.flight.lco import flown_model, measure_oscillation, simulate_flight
    from taos.flight.lco_confirm import OUTCOMES, confirm_many, periodic_start
    from taos.flight.vehicle import flight_plant

    rows = np.asarray(rows, float).reshape(-1, len(names))
    n = rows.shape[0]
    out = {k: np.full(n, np.nan) for k in POINT_SCALARS}
    out.update({k: np.zeros(n, bool) for k in POINT_FLAGS})
    amps, freqs = settings.amplitudes_rad, settings.freq_hz
    maps, cases, jobs, rest = {}, [], [], []
    for i, row in enumerate(rows):
        fl, m = flight, model
        for name, v in zip(names, row):
            fl, m = apply_value(fl, m, name, float(v))
        key = m.sha256   # the TVC variant's content (its files and overrides), not the swept names
        if key not in maps:   # the describing function depends on the TVC only: one map per TVC variant
            maps[key] = describing_function_map_for(m, fl.axis, amplitudes_rad=amps, freq_hz=freqs,
                                                    avionics=settings.avionics)
        rep = analyse_lco(fl, m, amplitudes_rad=amps, freq_hz=freqs, avionics=settings.avionics,
                          time_domain=False, df=maps[key])
        pred = rep.prediction
        maps[key] = pred.df   # as extended where a cycle lay beyond it (taos.flight.lco.extend_to_cover)
        c = pred.stable_cycle
        out["prediction_lco"][i] = c is not None
        out["grid_may_miss_cycle"][i] = pred.grid_may_miss_cycle
        if c is not None:
            out["amplitude_deg"][i], out["engine_amplitude_deg"][i] = (math.degrees(c.amplitude_rad),
                                                                        math.degrees(c.engine_amplitude_rad))
            out["frequency_hz"][i], out["margin_db"][i] = c.freq_hz, 0.0
        elif math.isfinite(pred.margin_db) and not pred.grid_may_miss_cycle:   # no margin of the map's edge
            out["margin_db"][i] = pred.margin_db
        if not settings.time_domain:
            continue
        mf = flown_model(m, settings.avionics)
        sp = _start_point(pred) if settings.start == "predicted" else None
        if sp is None:
            rest.append((i, fl, mf))
        else:
            plant = flight_plant(fl, mf, fl.axis)
            jobs.append((plant, mf, periodic_start(plant, mf, maps[key], *sp)))
            cases.append(i)
    res = confirm_many(jobs, threads, duration_s=settings.duration_s, window_s=settings.window_s)
    for i, r in zip(cases, res):
        out["td_lco"][i] = r.lco
        out["td_outcome"][i] = OUTCOMES.index(r.outcome)
        out["td_amplitude_deg"][i] = math.degrees(r.amplitude_rad)
        out["td_simulated_s"][i] = r.simulated_s
        if r.lco:
            out["td_engine_amplitude_deg"][i] = math.degrees(r.engine_amplitude_rad)
            out["td_frequency_hz"][i] = r.freq_hz
    for i, fl, mf in rest:   # the from-rest run of taos lco (0.2 deg attitude error, the final window measured)
        h = simulate_flight(fl, mf, settings.duration_s)
        meas = measure_oscillation(h, settings.window_s)
        out["td_lco"][i] = meas.lco
        out["td_amplitude_deg"][i] = math.degrees(meas.amplitude_rad)
        out["td_simulated_s"][i] = settings.duration_s
        out["td_outcome"][i] = OUTCOMES.index("sustained" if meas.lco else "decays")
        if meas.lco:
            out["td_engine_amplitude_deg"][i] = math.degrees(meas.engine_amplitude_rad)
            out["td_frequency_hz"][i] = meas.freq_hz
    out["lco"][:] = out["td_lco"] if settings.time_domain else out["prediction_lco"]
    return out


@dataclass(frozen=True, eq=False)
class LcoMap:
    """Verdict grid: arrays shaped (n_1,) or (n_1, n_2) over the swept values. ``lco`` is the
    verdict (the time domain's when it ran, else the describing function's), ``prediction_lco``
    the describing function's; ``margin_db`` is the remaining margin where no cycle is predicted
    (0 where one is); amplitudes and frequency (prediction) are NaN where there is no cycle.
    ``td``: the confirmation's arrays (:data:`POINT_SCALARS` ``td_*`` and ``td_lco``), None when
    it did not run; ``td_start``: its start (:data:`STARTS`)."""

    axes: tuple[SweepAxis, ...]
    lco: np.ndarray
    amplitude_deg: np.ndarray
    engine_amplitude_deg: np.ndarray
    frequency_hz: np.ndarray
    margin_db: np.ndarray
    friction_model: str
    loop_low_gain_margin_db: dict = field(default_factory=dict)
    prediction_lco: np.ndarray | None = None
    td: dict | None = None
    td_start: str | None = None
    #: per point: a cycle may lie outside the describing-function map even after its bounded
    #: extension (:func:`taos.flight.lco.extend_to_cover`); the verdict there is the map's, not the loop's
    grid_may_miss_cycle: np.ndarray | None = None

    @classmethod
    def from_points(cls, axes, points: dict, friction_model: str, lgm: dict, settings: MapSettings) -> "LcoMap":
        """The map of the :func:`map_points` output ``points`` in grid order (C order over ``axes``)."""
        shape = tuple(len(a.values) for a in axes)
        g = {k: np.asarray(v).reshape(shape) for k, v in points.items()}
        td = ({k: g[k] for k in POINT_SCALARS + ("td_lco",) if k.startswith("td_")} if settings.time_domain
              else None)
        return cls(tuple(axes), g["lco"].astype(bool), g["amplitude_deg"], g["engine_amplitude_deg"],
                   g["frequency_hz"], g["margin_db"], friction_model, lgm, g["prediction_lco"].astype(bool), td,
                   settings.start if settings.time_domain else None,
                   g["grid_may_miss_cycle"].astype(bool) if "grid_may_miss_cycle" in g else None)

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
        from taos.flight.lco_confirm import OUTCOMES
        nan = lambda a: [None if not np.isfinite(x) else float(x) for x in np.ravel(a)]  # noqa: E731
        shape = list(self.lco.shape)

        def grid(a):
            return np.array(nan(a), dtype=object).reshape(shape).tolist()
        pl = self.lco if self.prediction_lco is None else self.prediction_lco
        d = {"parameters": [a.name for a in self.axes], "units": [a.unit for a in self.axes],
             "values": [list(a.values) for a in self.axes], "friction_model": self.friction_model,
             "lco": self.lco.tolist(), "decided_by": "describing function" if self.td is None else "time domain",
             "prediction_lco": pl.tolist(), "amplitude_deg": grid(self.amplitude_deg),
             "engine_amplitude_deg": grid(self.engine_amplitude_deg), "frequency_hz": grid(self.frequency_hz),
             "margin_db": grid(self.margin_db), "loop_low_gain_margin_db": self.loop_low_gain_margin_db,
             "flips": self.flips(), "time_domain": None,
             "grid_may_miss_cycle": (None if self.grid_may_miss_cycle is None
                                     else self.grid_may_miss_cycle.astype(bool).tolist())}
        if self.td is not None:
            oc = np.array([None if not np.isfinite(x) else OUTCOMES[int(x)] for x in np.ravel(self.td["td_outcome"])],
                          dtype=object).reshape(shape).tolist()
            d["time_domain"] = {"start": self.td_start, "lco": self.td["td_lco"].astype(bool).tolist(), "outcome": oc,
                                "amplitude_deg": grid(np.where(self.td["td_lco"], self.td["td_amplitude_deg"], np.nan)),
                                "final_amplitude_deg": grid(self.td["td_amplitude_deg"]),
                                "engine_amplitude_deg": grid(self.td["td_engine_amplitude_deg"]),
                                "frequency_hz": grid(self.td["td_frequency_hz"]),
                                "simulated_s": grid(self.td["td_simulated_s"]),
                                "agree": (self.td["td_lco"].astype(bool) == pl).tolist()}
        return d


def grid_rows(axes) -> np.ndarray:
    """The swept values of every grid point, (n_points, len(axes)) [SI], in C order over ``axes``."""
    shape = tuple(len(a.values) for a in axes)
    return np.array([[a.values[i] for a, i in zip(axes, idx)] for idx in np.ndindex(shape)], float)


def loop_margins_of(flight: FlightModel, axes) -> dict:
    """The flight loop's own low-frequency gain margin [dB] for each swept FCS value."""
    lgm = {}
    for a in axes:
        if SWEEPABLE[a.name][0] == "fcs":
            for v in a.values:
                lgm[f"{a.name}={v:.6g}"] = loop_low_gain_margin_db(apply_value(flight, None, a.name, v)[0])
    return lgm


def check_axes(axes) -> tuple:
    axes = tuple(axes)
    if not 1 <= len(axes) <= 2:
        raise InputError("command line", "--sweep", "one or two parameters", got=str(len(axes)))
    return axes


def lco_map(flight: FlightModel, model: TvcModel, axes, *, amplitudes_rad=None, freq_hz=None,
            avionics: str = "bounding", time_domain: bool = False, start: str = "predicted",
            duration_s: float = 300.0, window_s: float = 120.0, threads: int | None = None) -> LcoMap:
    """The LCO verdict over the grid of ``axes`` (one or two :class:`SweepAxis`), in this
    process on ``threads`` threads (:func:`map_points`); describing-function settings as
    :func:`taos.flight.lco.analyse_lco`; ``time_domain``: confirm every point by a run started
    as ``start`` says (:data:`STARTS`), at most ``duration_s`` [s] long."""
    axes = check_axes(axes)
    st = MapSettings(None if amplitudes_rad is None else tuple(map(float, amplitudes_rad)),
                     None if freq_hz is None else tuple(map(float, freq_hz)), avionics, time_domain, start,
                     duration_s, window_s)
    pts = map_points(flight, model, [a.name for a in axes], grid_rows(axes), st, threads=threads)
    return LcoMap.from_points(axes, pts, model.friction.name, loop_margins_of(flight, axes), st)
