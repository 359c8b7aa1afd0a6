"""The figures a parameter sweep reports per point (``taos sweep --metric``).

Each metric is one number (or a yes/no) of a TVC model variant, computed by the same functions
``taos info`` and the Green Run report use; only the families a sweep asks for are computed:

* ``linear`` - :func:`taos.report.merit.frequency_merit` on the swept axis, from the exact linear
  response: the load resonance w_L / 2 pi = sqrt((K_L R^2 + K_n) / J) / 2 pi (seed paper eq. 1,
  :meth:`taos.model.TvcModel.load_resonance_hz`), the piston notch
  (:func:`taos.planar.simplex.load_resonance_from_notch`), the command -> engine -3 dB bandwidth,
  -90 deg frequency and peaking (dB above the low-frequency gain) and the breakaway deflection
  T_c / (K_L R^2);
* ``servo`` - :func:`taos.report.servo.servo_figures`: position-loop gain and phase margins with
  the model's load and in the laboratory (rigid load), the laboratory peaking and bandwidth, the
  load mode's frequency and damping ratio;
* ``lco`` - the describing-function LCO prediction of the flight loop (``taos lco``'s
  :func:`taos.flight.lco.analyse_lco`, time domain off; needs ``--flight``): the verdict, the
  cycle's command and engine amplitudes and frequency, the margin left where there is none,
  and the loop margins with the TVC at the map's largest amplitude;
* ``lco_time`` - the verdict as ``taos lco`` gives it: the same prediction, then the flight loop
  flown in the time domain (300 s from a 0.2 deg attitude offset, the oscillation measured over
  the last 120 s, :func:`taos.flight.lco.simulate_flight` and
  :func:`taos.flight.lco.measure_oscillation`), which decides; its amplitude and
  frequency. About 1.5 s of one core a point beyond the prediction.

A figure that does not exist for a variant (no -3 dB crossing below 50 Hz, no gain crossover,
no cycle) is NaN; the sweep's JSON writes it as null. Units are in the names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Metric:
    """One sweep metric: its family (what has to be computed for it), and its meaning."""

    name: str
    family: str
    meaning: str
    flag: bool = False


_ROWS = (
    ("load_resonance_hz", "linear", "load resonance sqrt((K_L R^2 + K_n)/J)/2 pi of the swept axis [Hz]"),
    ("notch_hz", "linear", "command -> piston notch frequency [Hz]"),
    ("engine_bandwidth_hz", "linear", "command -> engine -3 dB bandwidth, linear [Hz]"),
    ("engine_phase_90_hz", "linear", "command -> engine -90 deg frequency, linear [Hz]"),
    ("engine_peaking_db", "linear", "command -> engine peak above the low-frequency gain, linear [dB]"),
    ("engine_peak_freq_hz", "linear", "frequency of that peak [Hz]"),
    ("breakaway_deflection_deg", "linear", "load-path deflection friction holds, T_c/(K_L R^2) [deg]"),
    ("gain_margin_db", "servo", "position-loop gain margin with the model's load [dB]"),
    ("phase_margin_deg", "servo", "position-loop phase margin with the model's load [deg]"),
    ("crossover_hz", "servo", "position-loop gain crossover with the model's load [Hz]"),
    ("lab_gain_margin_db", "servo", "position-loop gain margin, laboratory (rigid load) [dB]"),
    ("lab_phase_margin_deg", "servo", "position-loop phase margin, laboratory [deg]"),
    ("lab_peaking_db", "servo", "laboratory command -> engine peaking [dB]"),
    ("lab_bandwidth_hz", "servo", "laboratory command -> engine -3 dB bandwidth [Hz]"),
    ("load_mode_hz", "servo", "least-damped oscillatory pole below 40 Hz [Hz]"),
    ("load_mode_damping", "servo", "its damping ratio [-]"),
    ("lco_amplitude_deg", "lco", "predicted limit cycle: command amplitude [deg] (NaN: none)"),
    ("lco_engine_amplitude_deg", "lco", "predicted limit cycle: engine amplitude [deg]"),
    ("lco_frequency_hz", "lco", "predicted limit cycle: frequency [Hz]"),
    ("lco_margin_db", "lco", "margin left to a limit cycle where none is predicted [dB] (0 with one)"),
    ("flight_phase_margin_deg", "lco", "flight loop with the TVC at the map's largest amplitude: phase margin [deg]"),
    ("flight_low_gain_margin_db", "lco", "the same loop: low-frequency gain margin [dB]"),
    ("flight_high_gain_margin_db", "lco", "the same loop: high-frequency gain margin [dB]"),
    ("lco_confirmed_engine_amplitude_deg", "lco_time", "limit cycle flown in the time domain: engine amplitude [deg]"),
    ("lco_confirmed_frequency_hz", "lco_time", "limit cycle flown in the time domain: frequency [Hz]"),
)
#: every metric by name
METRICS: dict[str, Metric] = {r[0]: Metric(*r) for r in _ROWS}
METRICS["lco"] = Metric("lco", "lco", "limit cycle predicted (yes/no)", flag=True)
METRICS["lco_confirmed"] = Metric("lco_confirmed", "lco_time",
                                  "limit cycle in the time domain, taos lco's verdict (yes/no)", flag=True)
FAMILIES = ("linear", "servo", "lco", "lco_time")


@dataclass(frozen=True, eq=False)
class LcoSettings:
    """What the ``lco`` family needs: the parsed flight file and the describing-function grid
    (None: ``taos lco``'s defaults) with the avionics of the analysis."""

    flight: object
    avionics: str = "bounding"
    amplitudes_rad: tuple[float, ...] | None = None
    freq_hz: tuple[float, ...] | None = None


def _f(x) -> float:
    return math.nan if x is None or not math.isfinite(x) else float(x)


def _linear(model, axis: str) -> dict[str, float]:
    from taos.report.merit import frequency_merit

    fm = frequency_merit(model, axis)
    e = fm.engine
    return {"load_resonance_hz": model.load_resonance_hz(axis), "notch_hz": _f(fm.notch_hz),
            "engine_bandwidth_hz": _f(e.bandwidth_3db_hz), "engine_phase_90_hz": _f(e.phase_90_hz),
            "engine_peaking_db": _f(e.peak_gain_db), "engine_peak_freq_hz": _f(e.peak_freq_hz),
            "breakaway_deflection_deg": math.degrees(model.breakaway_deflection_rad())}


def _servo(model, axis: str) -> dict[str, float]:
    from taos.report.servo import servo_figures

    s = servo_figures(model, axis)
    return {"gain_margin_db": _f(s.loop.gain_margin_db), "phase_margin_deg": _f(s.loop.phase_margin_deg),
            "crossover_hz": _f(s.loop.crossover_hz), "lab_gain_margin_db": _f(s.lab_loop.gain_margin_db),
            "lab_phase_margin_deg": _f(s.lab_loop.phase_margin_deg), "lab_peaking_db": _f(s.lab_peaking_db),
            "lab_bandwidth_hz": _f(s.lab_bandwidth_hz), "load_mode_hz": _f(s.load_mode_hz),
            "load_mode_damping": _f(s.load_mode_damping)}


def _lco(model, lco: LcoSettings, time_domain: bool) -> dict[str, float]:
    from taos.flight.lco import analyse_lco

    rep = analyse_lco(lco.flight, model, amplitudes_rad=lco.amplitudes_rad, freq_hz=lco.freq_hz,
                      avionics=lco.avionics, time_domain=time_domain)
    d = rep.to_dict()
    big = d["margins_at_largest_amplitude"]
    pred = rep.prediction.to_dict()
    out = {"lco": float(bool(pred["lco"])), "lco_amplitude_deg": _f(pred["amplitude_deg"]),
           "lco_engine_amplitude_deg": _f(pred["engine_amplitude_deg"]), "lco_frequency_hz": _f(pred["frequency_hz"]),
           "lco_margin_db": 0.0 if pred["lco"] else _f(rep.prediction.margin_db),
           "flight_phase_margin_deg": _f(big.get("phase_margin_deg")),
           "flight_low_gain_margin_db": _f(big.get("low_gain_margin_db")),
           "flight_high_gain_margin_db": _f(big.get("high_gain_margin_db"))}
    if time_domain:
        td = d["time_domain"]
        out |= {"lco_confirmed": float(bool(d["verdict"]["lco"])),
                "lco_confirmed_engine_amplitude_deg": _f(td["engine_amplitude_deg"]),
                "lco_confirmed_frequency_hz": _f(td["frequency_hz"])}
    return out


def evaluate(model, names: tuple[str, ...], axis: str, lco: LcoSettings | None) -> dict[str, float]:
    """The metrics ``names`` of ``model`` on ``axis`` (flags as 0.0 / 1.0), computing only the
    families they belong to."""
    fams = {METRICS[n].family for n in names}
    out: dict[str, float] = {}
    if "linear" in fams:
        out |= _linear(model, axis)
    if "servo" in fams:
        out |= _servo(model, axis)
    if fams & {"lco", "lco_time"}:
        if lco is None:
            raise ValueError("the lco metrics need a flight file")
        out |= _lco(model, lco, time_domain="lco_time" in fams)
    return {n: out[n] for n in names}


def unstable_reason(model, axis: str) -> str:
    """Why the linear block of ``model`` on ``axis`` is unstable ("" when it is stable): its
    least-damped right-half-plane pole (:func:`taos.planar.envelope.unstable_modes`)."""
    from taos.planar.envelope import unstable_modes

    modes = unstable_modes(model, (axis,))
    if not modes:
        return ""
    _, f, z = min(modes, key=lambda m: m[2])
    return f"linear model unstable: {axis} mode at {f:.4g} Hz with damping ratio {z:.3g}"


#: rough cost of one point per family [s] on one core (sizes the engine's batches only)
FAMILY_COST_S = {"linear": 0.02, "servo": 0.08, "lco": 5.0, "lco_time": 1.5}


def run_cost_s(names: tuple[str, ...], lco: LcoSettings | None) -> float:
    fams = {METRICS[n].family for n in names}
    cost = sum(FAMILY_COST_S[f] for f in fams) + (FAMILY_COST_S["lco"] if fams == {"lco_time"} else 0.0)
    if fams & {"lco", "lco_time"} and lco is not None and lco.amplitudes_rad is not None and lco.freq_hz is not None:
        cost += FAMILY_COST_S["lco"] * (len(lco.amplitudes_rad) * len(lco.freq_hz) / 110.0 - 1.0)
    return float(np.clip(cost, 1e-3, 1e3))
