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

Limits: ``flow_limit_m3_s`` (the supply / pump flow available to this actuator) and
``power_limit_W`` (0: no limit); the summary gives the peak and mean against them.
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
    reversals: int
    reversals_per_s: float
    flow_limit_m3_s: float = 0.0
    power_limit_W: float = 0.0

    def to_dict(self) -> dict:
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


def duty_cycle(history, model, axis: str, start_s: float | None = None, end_s: float | None = None, *,
               deadband_m: float = 1e-5, flow_limit_m3_s: float = 0.0, power_limit_W: float = 0.0) -> DutyCycle:
    """The duty cycle (module docstring) of ``axis`` of an ascent run ``history``
    (:class:`taos.flight.ascent_sim.AscentHistory`) flown with the TVC ``model``, over [start, end]
    [s] (default the whole run); ``deadband_m`` [m] the reversal hysteresis."""
    t = history.t_s
    a = float(t[0]) if start_s is None else start_s
    b = float(t[-1]) if end_s is None else end_s
    sel = (t >= a) & (t <= b)
    act = model.actuator
    A = act.piston_area_m2
    v = history.signal("piston_rate_m_s", axis)[sel]
    P = history.signal("load_pressure_Pa", axis)[sel]
    q = history.signal("valve_flow_m_s", axis)[sel]
    x = history.signal("piston_m", axis)[sel]
    ts = t[sel]
    Qv = np.abs(A * q - act.flow_pressure_coefficient_m3_per_s_Pa * P)
    dur = float(ts[-1] - ts[0])
    vol = float(np.trapezoid(Qv, ts))
    n = reversals(x, deadband_m)
    return DutyCycle(axis, float(ts[0]), float(ts[-1]), float(Qv.max()), vol / dur, vol,
                     act.supply_pressure_Pa * vol / dur, act.supply_pressure_Pa * float(Qv.max()),
                     float(np.trapezoid(np.abs(P * A * v), ts)) / dur, float(np.trapezoid(np.abs(v), ts)), n,
                     n / dur if dur > 0 and math.isfinite(dur) else 0.0, flow_limit_m3_s, power_limit_W)
