"""Why flight friction exceeded the Green Run's: the seed paper's three explanations (sec. 5)
quantified on the shipped models, each as a Green Run condition against the flight condition.

1. **Cross-axis dither**: on the stand both axes were exercised together, so the other axis'
   motion dithered the bearing; in quiescent flight it is absent. Modelled as the modified LuGre
   vibration level V_d = the cross-axis engine rate amplitude (a sine of amplitude a at f:
   W = 2 pi f a) against V_d = 0 (:func:`taos.flight.friction_env.vibration_velocity`).
2. **Vibration environment**: the test stand's vibration against flight's, each a flat lateral
   acceleration PSD at the nozzle mapped to V_d (:mod:`taos.flight.friction_env`).
3. **Thrust**: sea-level thrust on the stand (Green Run 109 %, 1,860 kN) against vacuum thrust
   in flight (2,279 kN): T_c = mu N r_b (:func:`taos.flight.friction_env.at_thrust`).

Each condition is the flight model (``rs25_flight``, the flight load path) with only that
difference, and is measured by the low-frequency engine gain |theta / theta_c| [dB] of a sine
dwell (:func:`taos.planar.freqresp.sine_dwell_points`, friction against the servo's stiffness)
and by the flight loop's LCO margin [dB] (:func:`taos.flight.lco.analyse_lco`, prediction only,
a coarse describing-function grid; None when an LCO is predicted). The change of each explanation
is flight minus Green Run. The vibration levels and the dither amplitude are [notional]
(:data:`DEFAULT_ENVIRONMENT`): the paper states the explanations, not these numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

#: [notional] environment levels of the study (SI unless named): the cross-axis dither on the
#: stand (engine amplitude [rad] at [Hz]), the lateral acceleration PSDs at the nozzle [g^2/Hz]
#: over the band [Hz], the nozzle's distance from the gimbal [m] (RS-25 nozzle exit ~3 m below
#: the gimbal), the stand's and flight's thrust [N] ([public], the model files')
DEFAULT_ENVIRONMENT = {"dither_amplitude_rad": math.radians(0.05), "dither_freq_hz": 1.0,
                       "stand_psd_g2_per_hz": 0.02, "flight_psd_g2_per_hz": 0.002, "band_hz": (20.0, 2000.0),
                       "nozzle_arm_m": 3.0, "stand_thrust_N": 1.86e6, "flight_thrust_N": 2.279e6}


@dataclass(frozen=True)
class Explanation:
    """One explanation: its name, the Green Run and flight conditions (labels), the low-frequency
    engine gain [dB], the LCO margin [dB] (None: LCO predicted; the harmonic-balance margin is 0
    then) and the predicted stable cycle's engine amplitude [deg] (None: no LCO) in each, and the
    changes flight minus Green Run."""

    name: str
    green_run: str
    flight: str
    gain_db: tuple[float, float]
    margin_db: tuple[float | None, float | None]
    lco: tuple[bool, bool]
    engine_amplitude_deg: tuple[float | None, float | None] = (None, None)

    @property
    def gain_change_db(self) -> float:
        return self.gain_db[1] - self.gain_db[0]

    @property
    def margin_change_db(self) -> float | None:
        a, b = self.margin_db
        return None if a is None or b is None else b - a

    def to_dict(self) -> dict:
        return {"name": self.name, "green_run": self.green_run, "flight": self.flight,
                "gain_db": list(self.gain_db), "gain_change_db": self.gain_change_db,
                "margin_db": list(self.margin_db), "margin_change_db": self.margin_change_db,
                "lco": list(self.lco), "lco_engine_amplitude_deg": list(self.engine_amplitude_deg)}


@dataclass(frozen=True)
class FrictionExplanations:
    """The three explanations (:class:`Explanation`) with the dwell point (command amplitude [rad],
    frequency [Hz]), the axis and the environment used; ``provenance`` of the base model."""

    explanations: tuple[Explanation, ...]
    dwell_amplitude_rad: float
    dwell_freq_hz: float
    axis: str
    environment: dict
    provenance: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"explanations": [e.to_dict() for e in self.explanations],
                "dwell": {"amplitude_deg": math.degrees(self.dwell_amplitude_rad), "freq_hz": self.dwell_freq_hz},
                "axis": self.axis, "environment": {k: list(v) if isinstance(v, tuple) else v
                                                   for k, v in self.environment.items()},
                "provenance": self.provenance}


#: the coarse describing-function grid of the margins (as examples/plot_lco_verdict.py)
GRID = {"amplitudes_rad": [math.radians(a) for a in (0.03, 0.1, 0.3)], "freq_hz": [0.05, 0.08, 0.12, 0.18, 0.27, 0.4]}


def friction_explanations(flight, model, *, axis: str = "yaw", environment: dict | None = None,
                          dwell_amplitude_rad: float = math.radians(0.05), dwell_freq_hz: float = 0.15,
                          grid: dict | None = None) -> FrictionExplanations:
    """The study (module docstring) for ``flight`` (:class:`taos.flight.vehicle.FlightModel`) and
    the flight TVC ``model`` (law switched to ``modified-lugre``, whose V_d = 0 is LuGre)."""
    from taos.flight.friction_env import at_thrust, vibration_velocity, with_vibration
    from taos.flight.lco import analyse_lco, flown_model
    from taos.planar.freqresp import sine_dwell_points
    from taos.results import model_provenance

    env = dict(DEFAULT_ENVIRONMENT | (environment or {}))
    grid = grid or GRID
    base = with_vibration(model, 0.0)

    def measure(m):
        d = sine_dwell_points(flown_model(m, "bounding"), [dwell_amplitude_rad], [dwell_freq_hz], axis)
        rep = analyse_lco(flight, m, axis=axis, time_domain=False, **grid)
        cyc = rep.prediction.stable_cycle
        mg = rep.prediction.margin_db
        return (20 * math.log10(abs(complex(d.engine[0]))), (None if cyc or not math.isfinite(mg) else mg),
                cyc is not None, None if cyc is None else math.degrees(cyc.engine_amplitude_rad))

    def explanation(name, gr_label, fl_label, gr_model, fl_model):
        a, b = measure(gr_model), measure(fl_model)
        return Explanation(name, gr_label, fl_label, (a[0], b[0]), (a[1], b[1]), (a[2], b[2]), (a[3], b[3]))

    w = 2 * math.pi * env["dither_freq_hz"] * env["dither_amplitude_rad"]
    vd = {k: vibration_velocity(psd_g2_per_hz=env[f"{k}_psd_g2_per_hz"], band_hz=tuple(env["band_hz"]),
                                arm_m=env["nozzle_arm_m"]) for k in ("stand", "flight")}
    out = (
        explanation("cross-axis dither", f"dither present: V_d = {math.degrees(w):.3f} deg/s",
                    "absent: V_d = 0", with_vibration(base, w), base),
        explanation("vibration environment", f"test stand: V_d = {math.degrees(vd['stand']):.3f} deg/s",
                    f"flight: V_d = {math.degrees(vd['flight']):.3f} deg/s",
                    with_vibration(base, vd["stand"]), with_vibration(base, vd["flight"])),
        explanation("thrust", f"sea level {env['stand_thrust_N'] / 1e3:.0f} kN",
                    f"flight {env['flight_thrust_N'] / 1e3:.0f} kN",
                    at_thrust(base, env["stand_thrust_N"]), at_thrust(base, env["flight_thrust_N"])),
    )
    return FrictionExplanations(out, dwell_amplitude_rad, dwell_freq_hz, axis, env, model_provenance(base))
