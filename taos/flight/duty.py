"""The TVC hydraulic duty cycle of a flight (seed paper sec. 5: the LCO's impact on the hydraulic
duty cycle): flow, power, piston travel and reversals from an ascent run's actuator states.

From the actuator (:mod:`taos.planar.actuator`, Merritt 1967 ch. 5-6; A piston area [m^2], P_s
supply pressure [Pa], K_c flow-pressure coefficient, C_l leakage [m^3/(s Pa)], V_t trapped volume,
beta bulk modulus) and the recorded piston rate v_p [m/s], load pressure P_L [Pa] and valve
no-load flow over area q [m/s]:

    Q_v = A q - K_c P_L                     valve (load) flow [m^3/s]; the supply delivers |Q_v|
    Q_p = A v_p                             flow displaced by the piston [m^3/s]
    continuity:  Q_v - C_l P_L - Q_p = (V_t / 4 beta) P_L'

    supply power        P_s |Q_v|           [W] (a critical-centre four-way valve draws |Q_v| at P_s)
    load power          |P_L Q_p|           [W] (delivered to the load)
    piston travel       int |v_p| dt        [m]
    reversals           changes of travel direction by more than ``deadband_m`` (hysteresis), per second

Limits, from the model (``[actuator] rated_flow`` and ``pump_capacity`` [m^3/s], optional keys of
the actuator's parameter set; 0: no limit) unless given: the servovalve's rated flow Q_r bounds one
actuator's peak |Q_v|; the pump capacity Q_pump is the supply of one engine (both its actuators), so
the mean of the summed |Q_v| of the axes flown is read against it (an accumulator covers the peaks),
and the hydraulic power available is P_s Q_pump [W]. :func:`duty_summary` gives both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DutyCycle:
    """Duty-cycle summary of one axis over [start, end] [s] (SI; module docstring): peak and mean
    |Q_v| [m^3/s], mean supply and load power [W], piston travel [m], reversals and their rate
    [1/s], the limits and the peak fractions of them (None without a limit)."""

    axis: str
    start_s: float
    end_s: float
    peak_flow_m3_s: float
    mean_flow_m3_s: float
    supply_volume_m3: float
    mean_supply_power_W: float
    peak_supply_power_W: float
    mean_load_power_W: float
    piston_travel_m: float
    #: int A |v_p| dt [m^3]: the volume the piston swept (= A x piston travel)
    piston_volume_m3: float
    reversals: int
    reversals_per_s: float
    flow_limit_m3_s: float = 0.0
    power_limit_W: float = 0.0

    def to_dict(self) -> dict:
        """JSON-ready: the fields and the peak fractions of the limits (None without a limit)."""
        d = dict(self.__dict__)
        d["peak_flow_fraction_of_limit"] = self.peak_flow_m3_s / self.flow_limit_m3_s if self.flow_limit_m3_s else None
        d["peak_power_fraction_of_limit"] = (self.peak_supply_power_W / self.power_limit_W
                                             if self.power_limit_W else None)
        return d


def reversals(x: np.ndarray, deadband: float) -> int:
    """Changes of direction of ``x`` by more than ``deadband`` (a hysteresis counter)."""
    n, ref, direction, x0 = 0, float(x[0]), 0, float(x[0])
    for v in map(float, x):
        if direction == 0:
            if abs(v - x0) > deadband:
                direction, ref = (1 if v > x0 else -1), v
        elif direction > 0:
            ref = max(ref, v)
            if v < ref - deadband:
                n, direction, ref = n + 1, -1, v
        else:
            ref = min(ref, v)
            if v > ref + deadband:
                n, direction, ref = n + 1, 1, v
    return int(n)


def _window(history, axis: str, start_s, end_s):
    t = history.t_s
    a = float(t[0]) if start_s is None else start_s
    b = float(t[-1]) if end_s is None else end_s
    sel = (t >= a) & (t <= b)
    if np.count_nonzero(sel) < 2:
        from taos.errors import InputError
        raise InputError("duty cycle", "start_s", f"a window of at least two records within "
                         f"[{float(t[0]):g}, {float(t[-1]):g}] s", got=f"[{a:g}, {b:g}] s")
    return sel


def valve_flow(history, model, axis: str, sel) -> np.ndarray:
    """|Q_v| = |A q - K_c P_L| [m^3/s] of ``axis`` at the records ``sel`` (module docstring)."""
    act = model.actuator
    return np.abs(act.piston_area_m2 * history.signal("valve_flow_m_s", axis)[sel]
                  - act.flow_pressure_coefficient_m3_per_s_Pa * history.signal("load_pressure_Pa", axis)[sel])


def duty_cycle(history, model, axis: str, start_s: float | None = None, end_s: float | None = None, *,
               deadband_m: float = 1e-5, flow_limit_m3_s: float | None = None,
               power_limit_W: float | None = None) -> DutyCycle:
    """The duty cycle (module docstring) of ``axis`` of an ascent run ``history``
    (:class:`taos.flight.ascent_sim.AscentHistory`) flown with the TVC ``model``, over [start, end]
    [s] (default the whole run); ``deadband_m`` [m] the reversal hysteresis; the limits default to
    the model's rated flow Q_r and P_s Q_pump (0: none)."""
    act = model.actuator
    flow_limit_m3_s = act.rated_flow_m3_per_s if flow_limit_m3_s is None else flow_limit_m3_s
    power_limit_W = act.supply_pressure_Pa * act.pump_capacity_m3_per_s if power_limit_W is None else power_limit_W
    sel = _window(history, axis, start_s, end_s)
    A = act.piston_area_m2
    v = history.signal("piston_rate_m_s", axis)[sel]
    P = history.signal("load_pressure_Pa", axis)[sel]
    x = history.signal("piston_m", axis)[sel]
    ts = history.t_s[sel]
    Qv = valve_flow(history, model, axis, sel)
    dur = float(ts[-1] - ts[0])
    vol = float(np.trapezoid(Qv, ts))
    n = reversals(x, deadband_m)
    travel = float(np.trapezoid(np.abs(v), ts))
    return DutyCycle(axis, float(ts[0]), float(ts[-1]), float(Qv.max()), vol / dur, vol,
                     act.supply_pressure_Pa * vol / dur, act.supply_pressure_Pa * float(Qv.max()),
                     float(np.trapezoid(np.abs(P * A * v), ts)) / dur, travel, A * travel, n,
                     n / dur if dur > 0 and math.isfinite(dur) else 0.0, flow_limit_m3_s, power_limit_W)


def duty_summary(history, model, start_s: float | None = None, end_s: float | None = None, *,
                 deadband_m: float = 1e-5) -> dict:
    """Every flown axis' :func:`duty_cycle` against the rated flow, and the engine's supply: the summed
    |Q_v| of the axes (one pump feeds both actuators of an engine) against the pump capacity Q_pump
    [m^3/s] (``mean_flow_fraction_of_pump``: mean over Q_pump; None without a capacity). JSON-ready."""
    axes = tuple(history.axes)
    per = {ax: duty_cycle(history, model, ax, start_s, end_s, deadband_m=deadband_m) for ax in axes}
    sel = _window(history, axes[0], start_s, end_s)
    total = sum(valve_flow(history, model, ax, sel) for ax in axes)
    ts = history.t_s[sel]
    dur = float(ts[-1] - ts[0])
    mean = float(np.trapezoid(total, ts)) / dur if dur > 0 else 0.0
    cap = model.actuator.pump_capacity_m3_per_s
    return {"axes": {ax: d.to_dict() for ax, d in per.items()},
            "engine": {"axes": list(axes), "peak_flow_m3_s": float(total.max()), "mean_flow_m3_s": mean,
                       "mean_supply_power_W": model.actuator.supply_pressure_Pa * mean,
                       "pump_capacity_m3_s": cap, "mean_flow_fraction_of_pump": mean / cap if cap else None,
                       "peak_flow_fraction_of_pump": float(total.max()) / cap if cap else None}}
